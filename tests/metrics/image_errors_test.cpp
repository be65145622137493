// computeImageErrors: all metrics at once, peaks, non-finite pixels, masks, bad input.

#include "metrics/image_metrics.h"

#include "metrics_test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace rtlab;
using namespace rtlab::metrics;
using rtlab::metrics::testing::makePattern;
using rtlab::metrics::testing::makeRandomScalar;

TEST(ImageErrors, IdenticalImages)
{
    const Image<glm::vec3> image = makePattern(48, 32);
    const ImageErrors e = computeImageErrors(image, image);
    EXPECT_EQ(e.rmse, 0.0);
    EXPECT_EQ(e.relMse, 0.0);
    EXPECT_EQ(e.psnr, std::numeric_limits<double>::infinity());
    EXPECT_NEAR(e.ssim, 1.0, 1e-9);
    EXPECT_EQ(e.flip, 0.0);
    EXPECT_EQ(e.meanSignedError, 0.0);
    EXPECT_EQ(e.pixels, 48u * 32u);
    EXPECT_EQ(e.nonFinitePixels, 0u);
    EXPECT_EQ(e.peak, 1.0);
}

TEST(ImageErrors, AgreesWithTheIndividualFunctions)
{
    const Image<glm::vec3> ref = makePattern(40, 40);
    Image<glm::vec3> test = ref;
    for (std::size_t i = 0; i < test.pixels.size(); ++i)
        test.pixels[i] += glm::vec3(0.05f * float(i % 3), -0.02f, 0.01f);
    Image<std::uint8_t> mask(40, 40, 0);
    for (int y = 5; y < 30; ++y)
        for (int x = 10; x < 35; ++x)
            mask.at(x, y) = 1;
    const ImageErrors e = computeImageErrors(test, ref, {}, mask);
    EXPECT_EQ(e.pixels, 25u * 25u);
    EXPECT_DOUBLE_EQ(e.rmse, computeRmse(test, ref, mask));
    EXPECT_DOUBLE_EQ(e.relMse, computeRelativeMse(test, ref, mask));
    EXPECT_DOUBLE_EQ(e.psnr, computePsnr(test, ref, 1.0, mask));
    EXPECT_DOUBLE_EQ(e.meanSignedError, computeMeanSignedError(test, ref, mask));
    EXPECT_DOUBLE_EQ(e.ssim, computeSsim(test, ref, {}, mask).mean);
    EXPECT_DOUBLE_EQ(e.flip, computeFlip(test, ref, ColorEncoding::Srgb, {}, mask).mean);
}

TEST(ImageErrors, HdrUsesTheReferenceMaximumAsPeakAndHdrFlip)
{
    Image<glm::vec3> ref = makePattern(32, 32);
    for (glm::vec3& p : ref.pixels)
        p *= 10.0f;
    float maxValue = 0;
    for (const glm::vec3& p : ref.pixels)
        maxValue = std::max({maxValue, p.x, p.y, p.z});
    Image<glm::vec3> test = ref;
    for (glm::vec3& p : test.pixels)
        p *= 1.5f;
    ImageErrorOptions options;
    options.range = DynamicRange::Hdr;
    const ImageErrors e = computeImageErrors(test, ref, options);
    EXPECT_DOUBLE_EQ(e.peak, double(maxValue));
    EXPECT_DOUBLE_EQ(e.psnr, computePsnr(test, ref, double(maxValue)));
    EXPECT_DOUBLE_EQ(e.flip, computeHdrFlip(test, ref).mean);
    EXPECT_GT(e.meanSignedError, 0.0);
    options.peak = 2.0;
    EXPECT_DOUBLE_EQ(computeImageErrors(test, ref, options).psnr, computePsnr(test, ref, 2.0));
}

TEST(ImageErrors, NonFinitePixelsAreCountedAndScoredAsWorstValues)
{
    // Reference 0.3 everywhere; 5 of 100 test pixels are NaN or infinite. Each is replaced by
    // the valid value farthest from 0.3, i.e. peak 1 (error 0.7): MSE = 5 * 0.49 / 100.
    Image<float> ref(10, 10, 0.3f);
    Image<float> test = ref;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    test.at(1, 1) = nan;
    test.at(2, 5) = nan;
    test.at(7, 3) = inf;
    test.at(8, 8) = -inf;
    test.at(0, 9) = nan;
    const ImageErrors e = computeImageErrors(test, ref);
    EXPECT_EQ(e.nonFinitePixels, 5u);
    EXPECT_NEAR(e.rmse, std::sqrt(5 * 0.49 / 100), 1e-6);
    EXPECT_NEAR(e.meanSignedError, 5 * 0.7 / 100, 1e-6);
    EXPECT_TRUE(std::isfinite(e.ssim));
    EXPECT_TRUE(std::isfinite(e.flip));
    EXPECT_GE(e.flip, 5 * 1.0 / 100); // the FLIP map is 1 at those pixels

    // A reference near the top picks 0 instead: reference 0.8, error 0.8.
    Image<float> bright(10, 10, 0.8f);
    Image<float> brightTest = bright;
    brightTest.at(4, 4) = nan;
    EXPECT_NEAR(computeImageErrors(brightTest, bright).meanSignedError, -0.8 / 100, 1e-6);

    // Only the selected non-finite pixels are counted.
    Image<std::uint8_t> mask(10, 10, 1);
    mask.at(1, 1) = 0;
    mask.at(2, 5) = 0;
    EXPECT_EQ(computeImageErrors(test, ref, {}, mask).nonFinitePixels, 3u);
}

TEST(ImageErrors, EmptyMaskGivesNanAndZeroPixels)
{
    const Image<float> a = makeRandomScalar(12, 12, 31, 0.0, 1.0);
    const Image<float> b = makeRandomScalar(12, 12, 32, 0.0, 1.0);
    const ImageErrors e = computeImageErrors(a, b, {}, Image<std::uint8_t>(12, 12, 0));
    EXPECT_EQ(e.pixels, 0u);
    EXPECT_TRUE(std::isnan(e.rmse));
    EXPECT_TRUE(std::isnan(e.relMse));
    EXPECT_TRUE(std::isnan(e.psnr));
    EXPECT_TRUE(std::isnan(e.ssim));
    EXPECT_TRUE(std::isnan(e.flip));
    EXPECT_TRUE(std::isnan(e.meanSignedError));
}

TEST(ImageErrors, BadInputThrows)
{
    const Image<glm::vec3> a(8, 6), b(6, 8);
    try {
        computeImageErrors(a, b);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("8x6"), std::string::npos) << what;
        EXPECT_NE(what.find("6x8"), std::string::npos) << what;
    }
    Image<glm::vec3> nanRef(8, 6, glm::vec3(0.5f));
    nanRef.at(3, 3).y = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(computeImageErrors(a, nanRef), std::invalid_argument);
    ImageErrorOptions badPeak;
    badPeak.peak = -1.0;
    EXPECT_THROW(computeImageErrors(a, a, badPeak), std::invalid_argument);
}

TEST(ImageErrors, OptionalMetricsCanBeSkipped)
{
    const Image<glm::vec3> a = makePattern(16, 16);
    ImageErrorOptions options;
    options.withSsim = false;
    options.withFlip = false;
    const ImageErrors e = computeImageErrors(a, a, options);
    EXPECT_TRUE(std::isnan(e.ssim));
    EXPECT_TRUE(std::isnan(e.flip));
    EXPECT_EQ(e.rmse, 0.0);
}
