#include "sign_rows.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rtlab::isosurface {
namespace {

//! Classifies one row of n samples into words; returns false when it holds a NaN.
bool classifyRow(const float* values, int n, float threshold, std::uint64_t* bits)
{
    bool clean = true;
    for (int start = 0, w = 0; start < n; start += 64, ++w) {
        const float* v = values + start;
        const int count = std::min(64, n - start);
        std::uint64_t mask = 0;
        int k = 0;
#if defined(__SSE2__)
        const __m128 t = _mm_set1_ps(threshold);
        __m128 nan = _mm_setzero_ps();
        for (; k + 4 <= count; k += 4) {
            const __m128 x = _mm_loadu_ps(v + k);
            mask |= std::uint64_t(_mm_movemask_ps(_mm_cmplt_ps(x, t))) << k;
            nan = _mm_or_ps(nan, _mm_cmpunord_ps(x, x));
        }
        clean = clean && _mm_movemask_ps(nan) == 0;
#endif
        for (; k < count; ++k) {
            mask |= std::uint64_t(v[k] < threshold) << k;
            clean = clean && !std::isnan(v[k]);
        }
        bits[w] = mask;
    }
    return clean;
}

} // namespace

float getInsideThreshold(double iso)
{
    constexpr float kMax = std::numeric_limits<float>::max();
    if (iso > double(kMax))
        return std::numeric_limits<float>::infinity();
    if (iso <= -double(kMax))
        return -kMax;
    float t = static_cast<float>(iso);
    if (double(t) < iso)
        t = std::nextafter(t, std::numeric_limits<float>::infinity());
    return t;
}

SignRows::SignRows(const SampledField& field, double iso, std::size_t& firstNan)
    : mSize(field.samples), mWords((std::size_t(std::max(field.samples.x, 1)) + 63) / 64),
      mLastWord(std::size_t(std::max(field.samples.x, 1) - 1) / 64),
      mLastMask(~(std::uint64_t(1) << ((std::max(field.samples.x, 1) - 1) % 64))),
      // classifyRow writes every word of every row
      mBits(std::make_unique_for_overwrite<std::uint64_t[]>(
          mWords * std::size_t(std::max(field.samples.y, 0)) *
          std::size_t(std::max(field.samples.z, 0))))
{
    const float threshold = getInsideThreshold(iso);
    const int nx = mSize.x;
    const int ny = mSize.y;
    std::vector<std::size_t> layerNan(std::size_t(std::max(mSize.z, 0)), kNoNan);
    tbb::parallel_for(tbb::blocked_range<int>(0, mSize.z), [&](const tbb::blocked_range<int>& r) {
        for (int z = r.begin(); z != r.end(); ++z) {
            bool clean = true;
            for (int y = 0; y < ny; ++y)
                clean = classifyRow(&field.values[field.index(0, y, z)], nx, threshold,
                                    mutableRow(y, z)) &&
                        clean;
            if (clean)
                continue;
            const std::size_t begin = field.index(0, 0, z);
            const std::size_t end = begin + std::size_t(nx) * std::size_t(ny);
            for (std::size_t i = begin; i != end; ++i)
                if (std::isnan(field.values[i])) {
                    layerNan[std::size_t(z)] = i;
                    break;
                }
        }
    });
    firstNan = kNoNan;
    for (const std::size_t i : layerNan)
        if (i != kNoNan) {
            firstNan = i;
            break;
        }
}

std::uint64_t SignRows::countCrossedEdges(int z) const
{
    std::uint64_t count = 0;
    for (int y = 0; y < mSize.y; ++y)
        for (std::size_t w = 0; w < mWords; ++w)
            count += std::uint64_t(getCrossings(y, z, w).count());
    return count;
}

std::uint64_t SignRows::getActiveCells(int y, int z, std::size_t w) const
{
    const std::uint64_t* r[4] = {row(y, z), row(y + 1, z), row(y, z + 1), row(y + 1, z + 1)};
    // A cell is active unless its eight corners agree: some row differs from row 0 at sample x or
    // x + 1, or row 0 changes from x to x + 1.
    const auto differ = [&](std::size_t k) {
        return (r[0][k] ^ r[1][k]) | (r[0][k] ^ r[2][k]) | (r[0][k] ^ r[3][k]);
    };
    const std::uint64_t d = differ(w);
    const std::uint64_t dNext = w + 1 < mWords ? differ(w + 1) : 0;
    const std::uint64_t active = d | (d >> 1) | (dNext << 63) | getXCrossings(r[0], w);
    return w == mLastWord ? active & mLastMask : active;
}

} // namespace rtlab::isosurface
