// The low-discrepancy sequence: Sobol's first two dimensions, the net property that survives
// Owen scrambling and index shuffling, and reproducibility.
#include "reference/sequences.h"

#include <gtest/gtest.h>

#include <random>

#include <cmath>
#include <set>
#include <vector>

namespace rtlab::reference {
namespace {

TEST(ReferenceSequences, SobolFirstPointsInNaturalOrder)
{
    // Dimension 0: van der Corput; dimension 1: direction numbers m = 1, 3, 5, 15.
    const double d0[8] = {0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875};
    const double d1[8] = {0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
    for (std::uint32_t i = 0; i < 8; ++i) {
        EXPECT_EQ(computeSobol32(i, 0) * 0x1.0p-32, d0[i]) << i;
        EXPECT_EQ(computeSobol32(i, 1) * 0x1.0p-32, d1[i]) << i;
    }
    EXPECT_EQ(computeSobol32(8, 1), 15u << 28); // v_4 = 15 / 16
}

// sampleScrambledSobol2D cancels the reversals its definition would apply twice; its points must
// be exactly those of the definition: the shuffled index's Sobol point, each coordinate scrambled.
TEST(ReferenceSequences, ScrambledSobolEqualsItsDefinition)
{
    std::mt19937_64 rng(17);
    for (int trial = 0; trial < 20000; ++trial) {
        const std::uint32_t index = trial < 1000 ? std::uint32_t(trial) : std::uint32_t(rng());
        const std::uint64_t stream = rng();
        const std::uint64_t h0 = mixBits64(stream), h1 = mixBits64(h0 ^ 0x9e3779b97f4a7c15ull);
        const std::uint32_t shuffled = scrambleNestedUniform(index, std::uint32_t(h0));
        const glm::dvec2 expected(
            toUnitInterval(scrambleNestedUniform(computeSobol32(shuffled, 0), std::uint32_t(h0 >> 32))),
            toUnitInterval(scrambleNestedUniform(computeSobol32(shuffled, 1), std::uint32_t(h1))));
        const glm::dvec2 got = sampleScrambledSobol2D(index, stream);
        ASSERT_EQ(got.x, expected.x) << index;
        ASSERT_EQ(got.y, expected.y) << index;
    }
}

TEST(ReferenceSequences, ReverseBitsIsAnInvolution)
{
    EXPECT_EQ(reverseBits32(1u), 0x80000000u);
    EXPECT_EQ(reverseBits32(0x12345678u), 0x1e6a2c48u);
    for (std::uint32_t x : {0u, 7u, 0xdeadbeefu, 0xffffffffu})
        EXPECT_EQ(reverseBits32(reverseBits32(x)), x);
}

TEST(ReferenceSequences, NestedScramblingKeepsPrefixes)
{
    // Owen scrambling maps each dyadic interval [k 2^-m, (k+1) 2^-m) onto one such interval.
    for (std::uint32_t seed : {1u, 0x9e3779b9u, 0xabcdef01u}) {
        for (int m = 1; m <= 12; ++m) {
            std::set<std::uint32_t> images;
            const std::uint32_t shift = 32 - m;
            for (std::uint32_t k = 0; k < (1u << m); ++k) {
                const std::uint32_t first = scrambleNestedUniform(k << shift, seed) >> shift;
                const std::uint32_t last =
                    scrambleNestedUniform((k << shift) | ((1u << shift) - 1), seed) >> shift;
                EXPECT_EQ(first, last);
                images.insert(first);
            }
            EXPECT_EQ(images.size(), std::size_t(1) << m); // a permutation of the intervals
        }
    }
}

//! Whether points [0, 2^m) of a stream form a (0, m, 2)-net: every elementary interval of area
//! 2^-m (2^a x 2^(m-a) cells) holds exactly one point.
bool isZeroNet(std::uint64_t streamSeed, int m)
{
    const std::uint32_t n = 1u << m;
    std::vector<glm::dvec2> points;
    for (std::uint32_t i = 0; i < n; ++i)
        points.push_back(sampleScrambledSobol2D(i, streamSeed));
    for (int a = 0; a <= m; ++a) {
        const std::uint32_t nx = 1u << a, ny = 1u << (m - a);
        std::vector<int> count(std::size_t(nx) * ny, 0);
        for (const auto& p : points)
            ++count[std::size_t(p.x * nx) * ny + std::size_t(p.y * ny)];
        for (int c : count)
            if (c != 1)
                return false;
    }
    return true;
}

TEST(ReferenceSequences, EveryPowerOfTwoPrefixIsANet)
{
    for (std::uint64_t seed : {0ull, 1ull, 42ull, 0x123456789abcdefull})
        for (int m = 0; m <= 11; ++m)
            EXPECT_TRUE(isZeroNet(seed, m)) << "seed " << seed << ", 2^" << m << " points";
}

TEST(ReferenceSequences, PixelStreamsAreReproducibleAndDistinct)
{
    const PixelSequence a(7, 100), b(7, 100), c(7, 101), d(8, 100);
    std::set<double> firstValues;
    for (std::uint32_t i = 0; i < 64; ++i) {
        for (std::uint32_t pair = 0; pair < 4; ++pair) {
            const glm::dvec2 u = a.get2D(i, pair);
            EXPECT_EQ(u, b.get2D(i, pair));
            EXPECT_GT(u.x, 0.0);
            EXPECT_LT(u.x, 1.0);
            EXPECT_GT(u.y, 0.0);
            EXPECT_LT(u.y, 1.0);
        }
    }
    for (std::uint32_t pair = 0; pair < 16; ++pair) {
        firstValues.insert(a.get2D(0, pair).x);
        firstValues.insert(c.get2D(0, pair).x);
        firstValues.insert(d.get2D(0, pair).x);
    }
    EXPECT_EQ(firstValues.size(), 48u); // other pixels, seeds, pairs: other scrambles
}

TEST(ReferenceSequences, DimensionPairsAreDecorrelated)
{
    // Across many pixels, the first coordinates of pairs 0 and 1 of sample 0 are uncorrelated
    // (|r| < 4 / sqrt(n)) and have mean 1/2 (within 4 standard errors).
    const int n = 20000;
    double sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (int p = 0; p < n; ++p) {
        const PixelSequence seq(3, std::uint64_t(p));
        const double x = seq.get2D(0, 0).x, y = seq.get2D(0, 1).x;
        sx += x;
        sy += y;
        sxx += x * x;
        syy += y * y;
        sxy += x * y;
    }
    const double mx = sx / n, my = sy / n;
    const double r = (sxy / n - mx * my) / std::sqrt((sxx / n - mx * mx) * (syy / n - my * my));
    EXPECT_LT(std::abs(r), 4.0 / std::sqrt(double(n)));
    EXPECT_NEAR(mx, 0.5, 4.0 * std::sqrt(1.0 / 12.0 / n));
}

} // namespace
} // namespace rtlab::reference
