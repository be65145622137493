// RMSE, MSE, relative MSE, PSNR and mean signed error on images with known answers.

#include "metrics/image_metrics.h"

#include "metrics_test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace rtlab;
using namespace rtlab::metrics;
using rtlab::metrics::testing::makeRandomRgb;
using rtlab::metrics::testing::makeRandomScalar;
using rtlab::metrics::testing::TestRandom;

TEST(PixelMetrics, IdenticalImagesHaveZeroErrorAndInfinitePsnr)
{
    const Image<glm::vec3> rgb = makeRandomRgb(64, 48, 1, 0.0, 1.0);
    EXPECT_EQ(computeMse(rgb, rgb), 0.0);
    EXPECT_EQ(computeRmse(rgb, rgb), 0.0);
    EXPECT_EQ(computeRelativeMse(rgb, rgb), 0.0);
    EXPECT_EQ(computeMeanSignedError(rgb, rgb), 0.0);
    EXPECT_EQ(computePsnr(rgb, rgb), std::numeric_limits<double>::infinity());

    const Image<float> scalar = makeRandomScalar(64, 48, 2, 0.0, 1.0);
    EXPECT_EQ(computeRmse(scalar, scalar), 0.0);
    EXPECT_EQ(computePsnr(scalar, scalar), std::numeric_limits<double>::infinity());
}

TEST(PixelMetrics, KnownOffsetGivesExactRmseSignedErrorAndPsnr)
{
    // Values in [0.2, 0.8] so that +-0.1 stays in [0, 1]. The only error is float rounding of
    // ref +- 0.1 (~3e-8), far below the 1e-6 tolerance.
    const Image<glm::vec3> ref = makeRandomRgb(50, 40, 3, 0.2, 0.8);
    Image<glm::vec3> brighter = ref, darker = ref;
    for (std::size_t i = 0; i < ref.pixels.size(); ++i) {
        brighter.pixels[i] = ref.pixels[i] + glm::vec3(0.1f);
        darker.pixels[i] = ref.pixels[i] - glm::vec3(0.1f);
    }
    EXPECT_NEAR(computeRmse(brighter, ref), 0.1, 1e-6);
    EXPECT_NEAR(computeMeanSignedError(brighter, ref), 0.1, 1e-6);
    EXPECT_NEAR(computePsnr(brighter, ref, 1.0), 20.0, 1e-4); // 10 log10(1 / 0.01)
    EXPECT_NEAR(computeRmse(darker, ref), 0.1, 1e-6);
    EXPECT_NEAR(computeMeanSignedError(darker, ref), -0.1, 1e-6);
    EXPECT_NEAR(computePsnr(darker, ref, 1.0), 20.0, 1e-4);
    // With an HDR peak of 10 the PSNR is 20 dB higher: 10 log10(100 / 0.01) = 40 dB.
    EXPECT_NEAR(computePsnr(brighter, ref, 10.0), 40.0, 1e-4);

    const Image<float> sref = makeRandomScalar(50, 40, 4, 0.2, 0.8);
    Image<float> sup = sref;
    for (float& p : sup.pixels)
        p += 0.1f;
    EXPECT_NEAR(computeRmse(sup, sref), 0.1, 1e-6);
    EXPECT_NEAR(computeMeanSignedError(sup, sref), 0.1, 1e-6);
    EXPECT_NEAR(computePsnr(sup, sref), 20.0, 1e-4);
}

TEST(PixelMetrics, RgbErrorIsTheChannelAverage)
{
    // Only the red channel is off by 0.3: the per-pixel squared error is 0.09 / 3.
    const Image<glm::vec3> ref(8, 8, glm::vec3(0.5f));
    const Image<glm::vec3> test(8, 8, glm::vec3(0.8f, 0.5f, 0.5f));
    EXPECT_NEAR(computeMse(test, ref), 0.09 / 3.0, 1e-7);
    EXPECT_NEAR(computeMeanSignedError(test, ref), 0.1, 1e-7);
}

TEST(PixelMetrics, RelativeMseUsesTheDocumentedEpsilon)
{
    const Image<float> ref(16, 16, 0.5f);
    const Image<float> test(16, 16, 0.6f);
    // (0.1)^2 / (0.5^2 + 0.01) = 0.01 / 0.26.
    EXPECT_NEAR(computeRelativeMse(test, ref), 0.01 / 0.26, 1e-6);
    EXPECT_NEAR(computeRelativeMse(test, ref, {}, 1e-3), 0.01 / 0.251, 1e-6);
    // Relative: a dark reference weighs the same absolute error far more.
    const Image<float> darkRef(16, 16, 0.05f);
    const Image<float> darkTest(16, 16, 0.15f);
    EXPECT_NEAR(computeRelativeMse(darkTest, darkRef), 0.01 / (0.0025 + 0.01), 1e-6);
    EXPECT_THROW(computeRelativeMse(test, ref, {}, 0.0), std::invalid_argument);
}

TEST(PixelMetrics, GaussianNoiseRmseMatchesSigma)
{
    // N = 256 * 256 = 65536 samples of N(0, sigma^2). The MSE estimate has relative standard
    // deviation sqrt(2 / N), so the RMSE has 1 / sqrt(2N) = 0.28%: +-3% is about 11 standard
    // deviations, a test that fails only if the metric is wrong.
    const double sigma = 0.05;
    const Image<float> ref(256, 256, 0.5f);
    Image<float> test = ref;
    TestRandom rng(12345);
    for (float& p : test.pixels)
        p = float(0.5 + sigma * rng.normal());
    const double rmse = computeRmse(test, ref);
    EXPECT_NEAR(rmse, sigma, 0.03 * sigma);
    // Zero-mean noise: the mean signed error is ~ sigma / sqrt(N) = 2e-4; 5 standard deviations.
    EXPECT_NEAR(computeMeanSignedError(test, ref), 0.0, 5 * sigma / 256.0);
}

TEST(PixelMetrics, SizeMismatchThrowsNamingBothSizes)
{
    const Image<float> a(4, 3), b(5, 3);
    try {
        computeRmse(a, b);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("4x3"), std::string::npos) << what;
        EXPECT_NE(what.find("5x3"), std::string::npos) << what;
    }
    const Image<glm::vec3> c(4, 3), d(4, 4);
    EXPECT_THROW(computeMse(c, d), std::invalid_argument);
    EXPECT_THROW(computePsnr(c, d), std::invalid_argument);
    EXPECT_THROW(computeMeanSignedError(c, d), std::invalid_argument);
    EXPECT_THROW(computeRelativeMse(c, d), std::invalid_argument);
}

TEST(PixelMetrics, BadPeakOrNonFiniteReferenceThrows)
{
    const Image<float> a(4, 4, 0.5f);
    Image<float> withNan = a;
    withNan.at(1, 2) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(computePsnr(a, a, 0.0), std::invalid_argument);
    EXPECT_THROW(computeRmse(a, withNan), std::invalid_argument);
    // A non-finite test pixel is not screened by the individual functions: it propagates.
    EXPECT_TRUE(std::isnan(computeRmse(withNan, a)));
}
