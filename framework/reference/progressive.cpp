#include "reference/progressive.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::reference {

namespace {

constexpr int kTileSize = 8;

//! Running mean and co-moment matrix of up to kMaxChannels channels [Welford 1962].
class RunningMoments {
public:
    explicit RunningMoments(int channels) : mChannels(channels) {}

    void add(const SampleValue& x)
    {
        ++mCount;
        std::array<double, kMaxChannels> before{};
        for (int c = 0; c < mChannels; ++c) {
            before[c] = x[c] - mMean[c];
            mMean[c] += before[c] / double(mCount);
        }
        for (int i = 0; i < mChannels; ++i) {
            const double after = x[i] - mMean[i];
            for (int j = 0; j < mChannels; ++j)
                mComoment[i * kMaxChannels + j] += before[j] * after;
        }
    }

    std::uint32_t count() const { return mCount; }

    //! Standard error of the mean of channel c, infinite below two samples.
    double getStdErr(int c) const
    {
        if (mCount < 2)
            return std::numeric_limits<double>::infinity();
        return std::sqrt(std::max(0.0, mComoment[c * kMaxChannels + c]) /
                         (double(mCount - 1) * double(mCount)));
    }

    bool meets(const ProgressiveRule& rule) const
    {
        for (int c = 0; c < mChannels; ++c)
            if (getStdErr(c) >
                std::max(rule.targetStdErr, rule.targetRelStdErr * std::abs(mMean[c])))
                return false;
        return true;
    }

    void store(PixelEstimate& out) const
    {
        out.samples = mCount;
        out.mean = mMean;
        const double scale = mCount >= 2 ? 1.0 / (double(mCount - 1) * double(mCount)) : 0.0;
        for (int i = 0; i < kMaxChannels * kMaxChannels; ++i)
            out.covariance[i] = mComoment[i] * scale;
    }

private:
    int mChannels;
    std::uint32_t mCount = 0;
    std::array<double, kMaxChannels> mMean{};
    std::array<double, kMaxChannels * kMaxChannels> mComoment{};
};

} // namespace

double PixelEstimate::getStdErr(int channel) const
{
    return std::sqrt(std::max(0.0, covariance[channel * kMaxChannels + channel]));
}

ProgressiveOutput runProgressive(int width, int height, const std::vector<std::uint8_t>& active,
                                 const ProgressiveRule& rule, const SampleFunction& sample)
{
    return runProgressive(width, height, active, rule,
                          [&](std::size_t pixel, std::uint32_t first, std::uint32_t count, SampleValue* values) {
                              std::uint32_t rays = 0;
                              for (std::uint32_t i = 0; i < count; ++i)
                                  rays += sample(pixel, first + i, values[i]);
                              return rays;
                          });
}

ProgressiveOutput runProgressive(int width, int height, const std::vector<std::uint8_t>& active,
                                 const ProgressiveRule& rule, const BatchSampleFunction& sample)
{
    ProgressiveOutput out;
    out.pixels.resize(std::size_t(width) * std::size_t(height));
    const int tilesX = (width + kTileSize - 1) / kTileSize;
    const int tilesY = (height + kTileSize - 1) / kTileSize;
    tbb::enumerable_thread_specific<std::uint64_t> rays(0);

    tbb::parallel_for(
        tbb::blocked_range<int>(0, tilesX * tilesY), [&](const tbb::blocked_range<int>& r) {
            std::uint64_t& localRays = rays.local();
            std::vector<SampleValue> values(std::size_t(std::max(1, rule.batchSize)));
            for (int tile = r.begin(); tile != r.end(); ++tile) {
                const int x0 = (tile % tilesX) * kTileSize;
                const int y0 = (tile / tilesX) * kTileSize;
                for (int y = y0; y < std::min(height, y0 + kTileSize); ++y) {
                    for (int x = x0; x < std::min(width, x0 + kTileSize); ++x) {
                        const std::size_t pixel =
                            std::size_t(y) * std::size_t(width) + std::size_t(x);
                        if (!active[pixel])
                            continue;
                        RunningMoments moments(rule.channels);
                        std::uint32_t n = 0;
                        bool converged = false;
                        while (n < std::uint32_t(rule.maxSamples)) {
                            const std::uint32_t count = std::min(std::uint32_t(rule.batchSize),
                                                                 std::uint32_t(rule.maxSamples) - n);
                            for (std::uint32_t i = 0; i < count; ++i)
                                values[i].fill(0.0);
                            localRays += sample(pixel, n, count, values.data());
                            for (std::uint32_t i = 0; i < count; ++i)
                                moments.add(values[i]);
                            n += count;
                            if (moments.meets(rule)) {
                                converged = true;
                                break;
                            }
                        }
                        moments.store(out.pixels[pixel]);
                        out.pixels[pixel].converged = converged;
                    }
                }
            }
        });
    for (std::uint64_t r : rays)
        out.rayCount += r;
    return out;
}

} // namespace rtlab::reference
