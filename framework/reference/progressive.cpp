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

    //! add() for each of `count` samples, merged as one batch: the batch's own mean and co-moment,
    //! then the pairwise update of Chan, Golub & LeVeque (1979), one division per batch instead of
    //! one per sample and channel. Equal to the per-sample updates up to rounding.
    void addBatch(const SampleValue* x, std::uint32_t count)
    {
        switch (mChannels) {
        case 1:
            addBatchOf<1>(x, count);
            return;
        case 3:
            addBatchOf<3>(x, count);
            return;
        case 5:
            addBatchOf<5>(x, count);
            return;
        default:
            for (std::uint32_t k = 0; k < count; ++k)
                add(x[k]);
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
    template <int C> void addBatchOf(const SampleValue* x, std::uint32_t count)
    {
        if (count == 0)
            return;
        // Deviations from the batch's first sample: exact zeros for a constant batch (a pixel
        // every sample of which agrees keeps a standard error of exactly 0), and no cancellation
        // against a large common offset.
        double mean[C] = {};
        for (std::uint32_t k = 1; k < count; ++k)
            for (int c = 0; c < C; ++c)
                mean[c] += x[k][c] - x[0][c];
        const double inverse = 1.0 / double(count);
        for (int c = 0; c < C; ++c)
            mean[c] *= inverse;
        double comoment[C * C] = {};
        for (std::uint32_t k = 0; k < count; ++k) {
            double d[C];
            for (int c = 0; c < C; ++c)
                d[c] = (x[k][c] - x[0][c]) - mean[c];
            for (int i = 0; i < C; ++i)
                for (int j = 0; j < C; ++j)
                    comoment[i * C + j] += d[i] * d[j];
        }
        for (int c = 0; c < C; ++c)
            mean[c] += x[0][c];
        const double before = double(mCount), total = before + double(count);
        const double weight = double(count) / total, cross = before * weight;
        double delta[C];
        for (int c = 0; c < C; ++c) {
            delta[c] = mean[c] - mMean[c];
            mMean[c] += delta[c] * weight;
        }
        for (int i = 0; i < C; ++i)
            for (int j = 0; j < C; ++j)
                mComoment[i * kMaxChannels + j] +=
                    comoment[i * C + j] + delta[i] * delta[j] * cross;
        mCount += count;
    }

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
                            moments.addBatch(values.data(), count);
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
