#include "metrics/gradient_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace rtlab::metrics {
namespace {

constexpr int kW = 16;
constexpr int kH = 10;
//! Forward 4-neighbour pairs of a kW x kH image.
constexpr std::size_t kAllPairs = std::size_t(kH) * (kW - 1) + std::size_t(kW) * (kH - 1);

Image<float> makeFlatDepth(float d = 2.0f)
{
    return Image<float>(kW, kH, d);
}

Image<glm::vec3> makeFlatNormals()
{
    return Image<glm::vec3>(kW, kH, glm::vec3(0, 0, 1));
}

//! A smooth reference: a ramp in x and y, in halves so differences are exact.
Image<glm::vec3> makeRamp()
{
    Image<glm::vec3> r(kW, kH);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            r.at(x, y) = glm::vec3(0.5f * float(x), 0.25f * float(y), 1.0f);
    return r;
}

TEST(GradientError, IdenticalAndOffsetImagesHaveNoDiscontinuityError)
{
    const auto pairs = makeSmoothPairMask(makeFlatDepth(), makeFlatNormals());
    const Image<glm::vec3> reference = makeRamp();
    GradientError e = computeGradientError(reference, reference, nullptr, pairs);
    EXPECT_EQ(e.pairs, kAllPairs);
    EXPECT_EQ(e.rmse, 0.0);
    // A constant bias changes no difference between neighbours (exact in these halves).
    Image<glm::vec3> biased = reference;
    for (auto& p : biased.pixels)
        p += glm::vec3(3.0f);
    e = computeGradientError(biased, reference, nullptr, pairs);
    EXPECT_EQ(e.rmse, 0.0);
}

TEST(GradientError, StepGivesItsHeightOverTheCrossingPairs)
{
    // A jump of a between columns 7 and 8: only the kH horizontal pairs across it differ, each by
    // a in every channel, so rmse^2 = kH a^2 / kAllPairs.
    const auto pairs = makeSmoothPairMask(makeFlatDepth(), makeFlatNormals());
    const Image<glm::vec3> reference = makeRamp();
    Image<glm::vec3> stepped = reference;
    const float a = 0.75f;
    for (int y = 0; y < kH; ++y)
        for (int x = 8; x < kW; ++x)
            stepped.at(x, y) += glm::vec3(a);
    const GradientError e = computeGradientError(stepped, reference, nullptr, pairs);
    EXPECT_NEAR(e.rmse, a * std::sqrt(double(kH) / double(kAllPairs)), 1e-12);
    EXPECT_EQ(e.noiseFloor, 0.0);
    EXPECT_EQ(e.excess, e.rmse);
}

TEST(GradientError, ReferenceNoiseIsReportedAndTakenOut)
{
    const auto pairs = makeSmoothPairMask(makeFlatDepth(), makeFlatNormals());
    const Image<glm::vec3> reference = makeRamp();
    const float s = 0.1f;
    const Image<glm::vec3> stderrs(kW, kH, glm::vec3(s));
    Image<glm::vec3> stepped = reference;
    for (int y = 0; y < kH; ++y)
        for (int x = 8; x < kW; ++x)
            stepped.at(x, y) += glm::vec3(1.0f);
    const GradientError e = computeGradientError(stepped, reference, &stderrs, pairs);
    // Two independent pixels: the variance of their difference is 2 s^2.
    EXPECT_NEAR(e.noiseFloor, std::sqrt(2.0) * double(s), 1e-7);
    EXPECT_NEAR(e.excess, std::sqrt(e.rmse * e.rmse - 2.0 * double(s) * double(s)), 1e-7);
    // An estimate equal to the reference is not charged for the reference's noise.
    EXPECT_EQ(computeGradientError(reference, reference, &stderrs, pairs).excess, 0.0);
}

TEST(GradientError, PairsAcrossDepthJumpsCreasesAndBackgroundAreLeftOut)
{
    Image<float> depth = makeFlatDepth(2.0f);
    Image<glm::vec3> normals = makeFlatNormals();
    for (int y = 0; y < kH; ++y) {
        for (int x = 8; x < kW; ++x)
            depth.at(x, y) = 3.0f; // a 50 % jump between columns 7 and 8
        normals.at(3, y) = glm::vec3(1, 0, 0); // a crease: column 3 faces +x
        depth.at(12, y) = std::numeric_limits<float>::infinity(); // background column
    }
    const auto pairs = makeSmoothPairMask(depth, normals);
    // Horizontal pairs lost per row: 7-8 (jump), 2-3 and 3-4 (crease), 11-12 and 12-13
    // (background); vertical pairs lost: every one in the background column.
    const std::size_t expected = kAllPairs - std::size_t(kH) * 5 - std::size_t(kH - 1);
    const Image<glm::vec3> reference = makeRamp();
    Image<glm::vec3> stepped = reference;
    for (int y = 0; y < kH; ++y)
        for (int x = 8; x < kW; ++x)
            stepped.at(x, y) += glm::vec3(1.0f); // the step sits on the depth jump: not an error
    const GradientError e = computeGradientError(stepped, reference, nullptr, pairs);
    EXPECT_EQ(e.pairs, expected);
    EXPECT_EQ(e.rmse, 0.0);
}

TEST(GradientError, PairsSplitByLabelSeparateTransitionsFromTheRest)
{
    // Labels: level 0 left of column 8, level 1 right of it, no level in row 0. The step sits on
    // the label change: all of it is across, nothing within.
    const auto pairs = makeSmoothPairMask(makeFlatDepth(), makeFlatNormals());
    Image<std::uint8_t> labels(kW, kH, 0);
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            labels.at(x, y) = y == 0 ? 255 : (x < 8 ? 0 : 1);
    const LabelledPairs split = splitPairsByLabel(pairs, labels, 255);
    const Image<glm::vec3> reference = makeRamp();
    Image<glm::vec3> stepped = reference;
    for (int y = 0; y < kH; ++y)
        for (int x = 8; x < kW; ++x)
            stepped.at(x, y) += glm::vec3(0.5f);
    const GradientError across = computeGradientError(stepped, reference, nullptr, split.across);
    const GradientError within = computeGradientError(stepped, reference, nullptr, split.within);
    EXPECT_EQ(across.pairs, std::size_t(kH - 1)); // one per labelled row
    EXPECT_NEAR(across.rmse, 0.5, 1e-12);
    // Labelled pairs: rows 1.. with kW - 1 horizontal pairs, and vertical pairs between rows 1..
    EXPECT_EQ(within.pairs, std::size_t(kH - 1) * (kW - 2) + std::size_t(kW) * (kH - 2));
    EXPECT_EQ(within.rmse, 0.0);
    EXPECT_THROW(splitPairsByLabel(pairs, Image<std::uint8_t>(2, 2), 255), std::invalid_argument);
}

TEST(GradientError, NonFiniteValuesAreSkippedAndBadInputThrows)
{
    const auto pairs = makeSmoothPairMask(makeFlatDepth(), makeFlatNormals());
    const Image<glm::vec3> reference = makeRamp();
    Image<glm::vec3> test = reference;
    test.at(5, 5) = glm::vec3(std::numeric_limits<float>::quiet_NaN());
    const GradientError e = computeGradientError(test, reference, nullptr, pairs);
    EXPECT_EQ(e.pairs, kAllPairs - 4); // the four pairs of the NaN pixel
    EXPECT_EQ(e.rmse, 0.0);
    EXPECT_TRUE(std::isfinite(e.excess));

    const Image<std::uint8_t> none(kW, kH, 0);
    const GradientError empty = computeGradientError(test, reference, nullptr, none);
    EXPECT_EQ(empty.pairs, 0u);
    EXPECT_EQ(empty.rmse, 0.0);

    EXPECT_THROW(computeGradientError(Image<glm::vec3>(kW + 1, kH), reference, nullptr, pairs),
                 std::invalid_argument);
    EXPECT_THROW(makeSmoothPairMask(makeFlatDepth(), makeFlatNormals(), 0.0),
                 std::invalid_argument);
    EXPECT_THROW(makeSmoothPairMask(makeFlatDepth(), makeFlatNormals(), 0.05, 1.5),
                 std::invalid_argument);
    EXPECT_THROW(makeSmoothPairMask(makeFlatDepth(), Image<glm::vec3>(3, 3)),
                 std::invalid_argument);
}

} // namespace
} // namespace rtlab::metrics
