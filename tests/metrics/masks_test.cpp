// Mask builders and metrics restricted to masks.

#include "metrics/image_metrics.h"

#include "metrics_test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace rtlab;
using namespace rtlab::metrics;
using rtlab::metrics::testing::makeRandomRgb;

namespace {

std::size_t countSetPixels(const Image<std::uint8_t>& mask)
{
    return std::size_t(std::count_if(mask.pixels.begin(), mask.pixels.end(),
                                     [](std::uint8_t v) { return v != 0; }));
}

} // namespace

TEST(Masks, MetricsInsideAMaskUseOnlyMaskedPixels)
{
    // All errors (+0.2) are in the left half; the right half is exact.
    const int w = 40, h = 30;
    const Image<glm::vec3> ref = makeRandomRgb(w, h, 21, 0.1, 0.7);
    Image<glm::vec3> test = ref;
    Image<std::uint8_t> left(w, h, 0), right(w, h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (x < w / 2) {
                test.at(x, y) += glm::vec3(0.2f);
                left.at(x, y) = 1;
            } else {
                right.at(x, y) = 255; // any nonzero value selects
            }
        }
    EXPECT_NEAR(computeRmse(test, ref, left), 0.2, 1e-6);
    EXPECT_NEAR(computeMeanSignedError(test, ref, left), 0.2, 1e-6);
    EXPECT_NEAR(computePsnr(test, ref, 1.0, left), 10 * std::log10(1 / 0.04), 1e-4);
    EXPECT_EQ(computeRmse(test, ref, right), 0.0);
    EXPECT_EQ(computeMeanSignedError(test, ref, right), 0.0);
    EXPECT_EQ(computePsnr(test, ref, 1.0, right), std::numeric_limits<double>::infinity());
    // Whole image: half the pixels are off by 0.2.
    EXPECT_NEAR(computeMeanSignedError(test, ref), 0.1, 1e-6);
    EXPECT_NEAR(computeRmse(test, ref), std::sqrt(0.5 * 0.04), 1e-6);

    // Fractional weights give a weighted mean: weight 1 on the left, 3 on the right.
    Image<float> weights(w, h, 3.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w / 2; ++x)
            weights.at(x, y) = 1.0f;
    EXPECT_NEAR(computeMeanSignedError(test, ref, weights), 0.2 * 1.0 / 4.0, 1e-6);

    // FLIP inside the exact half, away from the boundary by more than the filter radius (10 px
    // at 67 ppd): exactly 0. Inside the shifted half: positive.
    Image<std::uint8_t> farRight(w, h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = w / 2 + 11; x < w; ++x)
            farRight.at(x, y) = 1;
    EXPECT_EQ(computeFlip(test, ref, ColorEncoding::Srgb, {}, farRight).mean, 0.0);
    EXPECT_GT(computeFlip(test, ref, ColorEncoding::Srgb, {}, left).mean, 0.05);
}

TEST(Masks, EmptyMaskGivesNanWithZeroPixels)
{
    const Image<glm::vec3> a = makeRandomRgb(16, 16, 22, 0.0, 1.0);
    const Image<glm::vec3> b = makeRandomRgb(16, 16, 23, 0.0, 1.0);
    const Image<std::uint8_t> none(16, 16, 0);
    EXPECT_TRUE(std::isnan(computeRmse(a, b, none)));
    EXPECT_TRUE(std::isnan(computePsnr(a, b, 1.0, none)));
    EXPECT_TRUE(std::isnan(computeMeanSignedError(a, b, none)));
    const FlipResult flip = computeFlip(a, b, ColorEncoding::Srgb, {}, none);
    EXPECT_EQ(flip.pixels, 0u);
    EXPECT_TRUE(std::isnan(flip.mean));
    EXPECT_EQ(countMaskPixels(none, 16, 16), 0u);
    EXPECT_EQ(countMaskPixels({}, 16, 16), 256u);
}

TEST(Masks, BadMasksThrow)
{
    const Image<float> a(8, 8, 0.5f);
    EXPECT_THROW(computeRmse(a, a, Image<std::uint8_t>(8, 7, 1)), std::invalid_argument);
    Image<float> negative(8, 8, 1.0f);
    negative.at(3, 3) = -1.0f;
    EXPECT_THROW(computeRmse(a, a, negative), std::invalid_argument);
    Image<float> nan(8, 8, 1.0f);
    nan.at(0, 0) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(computeRmse(a, a, nan), std::invalid_argument);
}

TEST(Masks, DepthEdgeMaskMarksExactlyThePixelsNearAStep)
{
    // Depth 1 left of column 20, 2 from column 20 on: columns 19 and 20 form the discontinuity;
    // with k = 3 the mask is columns 16..23 in every row.
    const int w = 40, h = 30, s = 20, k = 3;
    Image<float> depth(w, h, 1.0f);
    for (int y = 0; y < h; ++y)
        for (int x = s; x < w; ++x)
            depth.at(x, y) = 2.0f;
    const Image<std::uint8_t> mask = makeDepthEdgeMask(depth, k, 0.1);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            EXPECT_EQ(mask.at(x, y), (x >= s - 1 - k && x <= s + k) ? 1 : 0) << x << "," << y;
    EXPECT_EQ(countSetPixels(mask), std::size_t(2 * k + 2) * h);

    // k = 0: just the two columns.
    EXPECT_EQ(countSetPixels(makeDepthEdgeMask(depth, 0, 0.1)), std::size_t(2 * h));
    // A 5% jump is below a 10% threshold: nothing. Above a 4% threshold: the two columns.
    Image<float> gentle(w, h, 1.0f);
    for (int y = 0; y < h; ++y)
        for (int x = s; x < w; ++x)
            gentle.at(x, y) = 1.05f;
    EXPECT_EQ(countSetPixels(makeDepthEdgeMask(gentle, 2, 0.1)), 0u);
    EXPECT_EQ(countSetPixels(makeDepthEdgeMask(gentle, 0, 0.04)), std::size_t(2 * h));
    // A smooth ramp (1% per pixel) has no discontinuity at all.
    Image<float> ramp(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            ramp.at(x, y) = float(std::pow(1.01, x));
    EXPECT_EQ(countSetPixels(makeDepthEdgeMask(ramp, 2, 0.1)), 0u);
}

TEST(Masks, DepthEdgeMaskTreatsBackgroundAsDiscontinuous)
{
    // A 6x4 object at depth 5 on an infinite background: the object's outline and the
    // background pixels touching it (4-neighbours) are marked, k = 0.
    const float inf = std::numeric_limits<float>::infinity();
    Image<float> depth(20, 16, inf);
    for (int y = 6; y < 10; ++y)
        for (int x = 7; x < 13; ++x)
            depth.at(x, y) = 5.0f;
    const Image<std::uint8_t> mask = makeDepthEdgeMask(depth, 0, 0.1);
    // Object outline: 2 * (6 + 4) - 4 = 16 pixels; outside neighbours: 2 * 6 + 2 * 4 = 20.
    EXPECT_EQ(countSetPixels(mask), 36u);
    EXPECT_EQ(mask.at(9, 7), 0); // object interior
    EXPECT_EQ(mask.at(2, 2), 0); // background far away
    EXPECT_EQ(mask.at(6, 5), 0); // diagonal neighbour only: not a 4-neighbour pair
    EXPECT_EQ(mask.at(6, 6), 1); // left of the corner
    EXPECT_EQ(mask.at(7, 6), 1); // object corner
    EXPECT_EQ(mask.at(7, 5), 1); // background above it
}

TEST(Masks, BorderMaskCountMatchesTheFormula)
{
    struct Case {
        int w, h, k;
    };
    for (const Case c :
         {Case{64, 48, 5}, Case{10, 7, 4}, Case{5, 5, 3}, Case{8, 6, 0}, Case{1920, 1080, 16}}) {
        const Image<std::uint8_t> mask = makeBorderMask(c.w, c.h, c.k);
        const std::size_t expected =
            std::size_t(c.w) * c.h -
            std::size_t(std::max(0, c.w - 2 * c.k)) * std::size_t(std::max(0, c.h - 2 * c.k));
        EXPECT_EQ(countSetPixels(mask), expected) << c.w << "x" << c.h << " k=" << c.k;
    }
    const Image<std::uint8_t> mask = makeBorderMask(64, 48, 5);
    EXPECT_EQ(mask.at(4, 20), 1);
    EXPECT_EQ(mask.at(5, 20), 0);
    EXPECT_EQ(mask.at(58, 20), 0);
    EXPECT_EQ(mask.at(59, 20), 1);
    EXPECT_EQ(mask.at(30, 43), 1);
    EXPECT_EQ(mask.at(30, 42), 0);
}

TEST(Masks, ThinStructuresByOpening)
{
    // Coverage: a 1-px line, a 2-px line, a 3-px line and a 10x10 block. With r = 1 (3x3
    // squares) the 1- and 2-px lines are thin, the 3-px line and the block are not.
    Image<std::uint8_t> coverage(40, 30, 0);
    for (int y = 2; y < 28; ++y) {
        coverage.at(3, y) = 1;
        coverage.at(8, y) = coverage.at(9, y) = 1;
        coverage.at(14, y) = coverage.at(15, y) = coverage.at(16, y) = 1;
    }
    for (int y = 5; y < 15; ++y)
        for (int x = 25; x < 35; ++x)
            coverage.at(x, y) = 1;
    const Image<std::uint8_t> thin = makeThinStructureMask(coverage, 1);
    EXPECT_EQ(countSetPixels(thin), std::size_t(26 * 3));
    for (int y = 2; y < 28; ++y) {
        EXPECT_EQ(thin.at(3, y), 1);
        EXPECT_EQ(thin.at(8, y), 1);
        EXPECT_EQ(thin.at(9, y), 1);
        EXPECT_EQ(thin.at(15, y), 0);
    }
    // r = 2 (5x5 squares): the 3-px line becomes thin as well, the block stays.
    EXPECT_EQ(countSetPixels(makeThinStructureMask(coverage, 2)), std::size_t(26 * 6));
    // Regions touching the image edge are judged by the part inside the image.
    Image<std::uint8_t> full(12, 12, 1);
    EXPECT_EQ(countSetPixels(makeThinStructureMask(full, 2)), 0u);
}

TEST(Masks, ThinObjectsInFrontOfOtherObjects)
{
    // A 1-px wire (id 2) across a wall (id 1) that fills the frame: coverage is full, so the
    // coverage opening finds nothing, but the per-object opening finds the wire.
    Image<std::uint32_t> ids(30, 20, 1u);
    for (int x = 0; x < 30; ++x)
        ids.at(x, 9) = 2u;
    EXPECT_EQ(countSetPixels(makeThinStructureMask(Image<std::uint8_t>(30, 20, 1), 1)), 0u);
    const Image<std::uint8_t> thin = makeThinStructureMask(ids, 1);
    EXPECT_EQ(countSetPixels(thin), 30u);
    for (int x = 0; x < 30; ++x)
        EXPECT_EQ(thin.at(x, 9), 1);

    // Known-thin ids, dilated by 1: the wire row and its two neighbours.
    EXPECT_EQ(countSetPixels(makeObjectMask(ids, {2u})), 30u);
    EXPECT_EQ(countSetPixels(makeObjectMask(ids, {2u}, 1)), 90u);
    EXPECT_EQ(countSetPixels(makeObjectMask(ids, {7u}, 3)), 0u);
}

TEST(Masks, DilationIsAChebyshevSquareClippedAtTheEdge)
{
    Image<std::uint8_t> seed(20, 20, 0);
    seed.at(10, 10) = 1;
    EXPECT_EQ(countSetPixels(dilateMask(seed, 2)), 25u);
    Image<std::uint8_t> corner(20, 20, 0);
    corner.at(0, 0) = 1;
    EXPECT_EQ(countSetPixels(dilateMask(corner, 2)), 9u);
    EXPECT_THROW(dilateMask(seed, -1), std::invalid_argument);
    EXPECT_THROW(makeBorderMask(8, 8, -1), std::invalid_argument);
    EXPECT_THROW(makeDepthEdgeMask(Image<float>(4, 4, 1.0f), 1, 0.0), std::invalid_argument);
    EXPECT_THROW(makeThinStructureMask(seed, 0), std::invalid_argument);
}
