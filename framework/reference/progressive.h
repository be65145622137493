#pragma once
// Progressive per-pixel estimation (internal to rtlab_reference): batches of samples until the
// standard error of every channel is below its target or a sample cap, with running mean and
// co-moments [Welford 1962]. Pixels are independent, so the result does not depend on how TBB
// splits the image over threads.

#include "reference/integrators.h"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace rtlab::reference {

struct ProgressiveRule {
    int channels = 1;
    double targetStdErr = 0.0;
    double targetRelStdErr = 0.0;
    int batchSize = 1;
    int maxSamples = 1;
};

struct PixelEstimate {
    std::uint32_t samples = 0;
    bool converged = false;
    std::array<double, kMaxChannels> mean{};
    //! Covariance of the mean (sample covariance / n), row-major kMaxChannels x kMaxChannels.
    std::array<double, kMaxChannels * kMaxChannels> covariance{};

    double getStdErr(int channel) const;
};

struct ProgressiveOutput {
    std::vector<PixelEstimate> pixels; //!< row-major; untouched (samples 0) where inactive
    std::uint64_t rayCount = 0;
};

//! Evaluates sample `index` of pixel `pixel` into `value`; returns the rays it traced.
using SampleFunction =
    std::function<std::uint32_t(std::size_t pixel, std::uint32_t index, SampleValue& value)>;

//! Evaluates samples first .. first + count - 1 of pixel `pixel` into values[0 .. count - 1]
//! (each zeroed before the call); returns the rays it traced. A batch lets an estimator trace
//! its rays together (Embree ray streams).
using BatchSampleFunction = std::function<std::uint32_t(std::size_t pixel, std::uint32_t first,
                                                        std::uint32_t count, SampleValue* values)>;
//! Runs the rule on every pixel whose `active` flag is set, in parallel over tiles. The samples
//! are added to the running moments in index order, so batching changes no estimate.
ProgressiveOutput runProgressive(int width, int height, const std::vector<std::uint8_t>& active,
                                 const ProgressiveRule& rule, const BatchSampleFunction& sample);
//! The same, one sample per call.
ProgressiveOutput runProgressive(int width, int height, const std::vector<std::uint8_t>& active,
                                 const ProgressiveRule& rule, const SampleFunction& sample);

} // namespace rtlab::reference
