// SSIM against closed forms and a direct evaluation of Wang et al.'s definition.

#include "metrics/image_metrics.h"

#include "metrics_test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace rtlab;
using namespace rtlab::metrics;
using rtlab::metrics::testing::makeRandomRgb;
using rtlab::metrics::testing::makeRandomScalar;
using rtlab::metrics::testing::TestRandom;

namespace {

// SSIM at (px, py) straight from [Wang et al. 2004, Eqs. (13)-(16)]: 11 x 11 Gaussian weights
// (sigma 1.5) over the part of the window inside the image, renormalised to sum to 1.
double computeSsimDirectly(const Image<float>& x, const Image<float>& y, int px, int py, double l)
{
    double wsum = 0, mx = 0, my = 0;
    for (int j = -5; j <= 5; ++j)
        for (int i = -5; i <= 5; ++i) {
            const int sx = px + i, sy = py + j;
            if (sx < 0 || sy < 0 || sx >= x.width || sy >= x.height)
                continue;
            const double w = std::exp(-(i * i + j * j) / (2 * 1.5 * 1.5));
            wsum += w;
            mx += w * x.at(sx, sy);
            my += w * y.at(sx, sy);
        }
    mx /= wsum;
    my /= wsum;
    double vx = 0, vy = 0, cov = 0;
    for (int j = -5; j <= 5; ++j)
        for (int i = -5; i <= 5; ++i) {
            const int sx = px + i, sy = py + j;
            if (sx < 0 || sy < 0 || sx >= x.width || sy >= x.height)
                continue;
            const double w = std::exp(-(i * i + j * j) / (2 * 1.5 * 1.5)) / wsum;
            vx += w * (x.at(sx, sy) - mx) * (x.at(sx, sy) - mx);
            vy += w * (y.at(sx, sy) - my) * (y.at(sx, sy) - my);
            cov += w * (x.at(sx, sy) - mx) * (y.at(sx, sy) - my);
        }
    const double c1 = (0.01 * l) * (0.01 * l), c2 = (0.03 * l) * (0.03 * l);
    return ((2 * mx * my + c1) * (2 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
}

} // namespace

TEST(Ssim, IdenticalImagesGiveOne)
{
    const Image<glm::vec3> rgb = makeRandomRgb(40, 30, 5, 0.0, 1.0);
    const SsimResult lum = computeSsim(rgb, rgb);
    EXPECT_NEAR(lum.mean, 1.0, 1e-9);
    EXPECT_EQ(lum.pixels, 40u * 30u);
    ASSERT_EQ(lum.map.width, 40);
    ASSERT_EQ(lum.map.height, 30);
    for (float v : lum.map.pixels)
        EXPECT_NEAR(v, 1.0f, 1e-6f);
    EXPECT_NEAR(computeSsim(rgb, rgb, {.channels = SsimChannels::PerChannel}).mean, 1.0, 1e-9);
}

TEST(Ssim, ConstantImagesMatchTheClosedForm)
{
    // Both windows have zero variance, so SSIM = (2 mx my + C1) / (mx^2 + my^2 + C1) at every
    // pixel, C1 = (0.01 L)^2.
    const double a = 0.3, b = 0.7;
    const Image<float> x(24, 20, float(a)), y(24, 20, float(b));
    const double xa = double(float(a)), yb = double(float(b));
    for (double l : {1.0, 4.0}) {
        const double c1 = (0.01 * l) * (0.01 * l);
        const double expected = (2 * xa * yb + c1) / (xa * xa + yb * yb + c1);
        const SsimResult r = computeSsim(x, y, {.dynamicRange = l});
        EXPECT_NEAR(r.mean, expected, 1e-12) << "L = " << l;
        for (float v : r.map.pixels)
            EXPECT_NEAR(v, expected, 1e-6);
    }
    // Per channel: the average of the three channels' closed forms.
    const glm::vec3 ca(0.2f, 0.5f, 0.9f), cb(0.4f, 0.5f, 0.1f);
    const Image<glm::vec3> rx(16, 16, ca), ry(16, 16, cb);
    double expected = 0;
    const double c1 = 1e-4;
    for (int c = 0; c < 3; ++c)
        expected +=
            (2.0 * ca[c] * cb[c] + c1) / (double(ca[c]) * ca[c] + double(cb[c]) * cb[c] + c1);
    expected /= 3.0;
    EXPECT_NEAR(computeSsim(rx, ry, {.channels = SsimChannels::PerChannel}).mean, expected, 1e-12);
}

TEST(Ssim, MapMatchesDirectEvaluationInsideAndAtTheEdge)
{
    const Image<float> x = makeRandomScalar(32, 28, 6, 0.0, 1.0);
    Image<float> y = x;
    TestRandom rng(7);
    for (float& p : y.pixels)
        p = float(std::clamp(p + 0.1 * rng.normal(), 0.0, 1.0));
    const SsimResult r = computeSsim(x, y);
    // The map is stored as float: compare to 1e-6.
    for (auto [px, py] :
         {std::pair{16, 14}, std::pair{5, 5}, std::pair{0, 0}, std::pair{31, 27}, std::pair{2, 20}})
        EXPECT_NEAR(r.map.at(px, py), computeSsimDirectly(x, y, px, py, 1.0), 1e-6)
            << px << "," << py;
}

TEST(Ssim, NoiseLowersSsimMonotonically)
{
    // A constant reference (zero variance) against Gaussian noise of increasing sigma: SSIM is
    // ~C2 / (v + C2) (C2 = 9e-4, v the local weighted variance of the noise), strictly inside
    // (0, 1) and decreasing in sigma. The weighted variance is biased low, E[v] = sigma^2 (1 -
    // sum w^2) with sum w^2 = 0.035 for the 11x11 window, and C2 / (v + C2) is convex in v, so by
    // Jensen the mean SSIM is at least C2 / (sigma^2 + C2): 0.900, 0.265, 0.083. (The luminance
    // term lowers it by < 1e-5 here.) The margins are 0.4%, 6% and 9%, against a sampling
    // standard deviation of the mean below 0.1%.
    const Image<float> ref(256, 256, 0.5f);
    double previous = 1.0;
    for (double sigma : {0.01, 0.05, 0.1}) {
        Image<float> test = ref;
        TestRandom rng(2024);
        for (float& p : test.pixels)
            p = float(0.5 + sigma * rng.normal());
        const double ssim = computeSsim(test, ref).mean;
        EXPECT_GT(ssim, 0.0) << sigma;
        EXPECT_LT(ssim, 1.0) << sigma;
        EXPECT_LT(ssim, previous) << sigma;
        EXPECT_GT(ssim, 9e-4 / (sigma * sigma + 9e-4)) << sigma;
        previous = ssim;
    }
}

TEST(Ssim, MaskSelectsMapValuesAndEmptyMaskIsNan)
{
    const Image<float> x = makeRandomScalar(20, 20, 8, 0.0, 1.0);
    const Image<float> y = makeRandomScalar(20, 20, 9, 0.0, 1.0);
    const SsimResult all = computeSsim(x, y);
    Image<std::uint8_t> one(20, 20, 0);
    one.at(7, 11) = 1;
    const SsimResult single = computeSsim(x, y, {}, one);
    EXPECT_EQ(single.pixels, 1u);
    EXPECT_NEAR(single.mean, all.map.at(7, 11), 1e-6);
    const SsimResult none = computeSsim(x, y, {}, Image<std::uint8_t>(20, 20, 0));
    EXPECT_EQ(none.pixels, 0u);
    EXPECT_TRUE(std::isnan(none.mean));
}
