// LDR-FLIP and HDR-FLIP: identities, closed forms on uniform images, monotonicity, exposures.

#include "metrics/image_metrics.h"

#include "metrics_test_support.h"

#include <glm/common.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace rtlab;
using namespace rtlab::metrics;
using rtlab::metrics::testing::makePattern;
using rtlab::metrics::testing::makeRandomRgb;

namespace {

// Narkowicz's ACES fit as published, applied to 0.6 x (HDR-FLIP's ACES tone mapper).
double applyAcesCurve(double x)
{
    x *= 0.6;
    return (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14);
}

// The x with applyAcesCurve(x) = t, by bisection (the curve is increasing on [0, 100]).
double invertAcesByBisection(double t)
{
    double lo = 0, hi = 100;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (applyAcesCurve(mid) < t ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// ---- FLIP at one pixel straight from the paper's formulas, in double precision, with full 2D
// (non-separable) kernels and the textbook 4-digit sRGB matrix. Independent of the library's
// separable filters and derived matrices; borders replicate the edge pixel.

constexpr double kPi = 3.14159265358979323846;
constexpr double kM[3][3] = {
    {0.4124, 0.3576, 0.1805}, {0.2126, 0.7152, 0.0722}, {0.0193, 0.1192, 0.9505}};

glm::dvec3 convertToXyz(const glm::dvec3& rgb)
{
    return {kM[0][0] * rgb.x + kM[0][1] * rgb.y + kM[0][2] * rgb.z,
            kM[1][0] * rgb.x + kM[1][1] * rgb.y + kM[1][2] * rgb.z,
            kM[2][0] * rgb.x + kM[2][1] * rgb.y + kM[2][2] * rgb.z};
}

glm::dvec3 computeWhiteXyz()
{
    return convertToXyz(glm::dvec3(1.0));
}

glm::dvec3 convertToYcxcz(const glm::dvec3& rgb)
{
    const glm::dvec3 n = convertToXyz(rgb) / computeWhiteXyz();
    return {116 * n.y - 16, 500 * (n.x - n.y), 200 * (n.y - n.z)};
}

glm::dvec3 convertYcxczToRgb(const glm::dvec3& o)
{
    const double y = (o.x + 16) / 116;
    const glm::dvec3 xyz = glm::dvec3(y + o.y / 500, y, y - o.z / 200) * computeWhiteXyz();
    // Solve M rgb = xyz by Cramer's rule.
    const auto det = [](const double a[3][3]) {
        return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
               a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    const double d = det(kM);
    glm::dvec3 rgb;
    for (int c = 0; c < 3; ++c) {
        double m[3][3];
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
                m[i][j] = j == c ? xyz[i] : kM[i][j];
        rgb[c] = det(m) / d;
    }
    return rgb;
}

glm::dvec3 convertToHuntLab(const glm::dvec3& rgb)
{
    const glm::dvec3 n = convertToXyz(rgb) / computeWhiteXyz();
    const double d = 6.0 / 29.0;
    const auto f = [d](double t) {
        return t > d * d * d ? std::cbrt(t) : t / (3 * d * d) + 4.0 / 29;
    };
    const double l = 116 * f(n.y) - 16;
    return {l, 0.01 * l * 500 * (f(n.x) - f(n.y)), 0.01 * l * 200 * (f(n.y) - f(n.z))};
}

double computeHyab(const glm::dvec3& a, const glm::dvec3& b)
{
    return std::abs(a.x - b.x) + std::hypot(a.y - b.y, a.z - b.z);
}

glm::dvec3 fetchPixel(const Image<glm::vec3>& image, int x, int y)
{
    return glm::dvec3(
        image.at(std::clamp(x, 0, image.width - 1), std::clamp(y, 0, image.height - 1)));
}

double computeFlipByDefinition(const Image<glm::vec3>& testLinear,
                               const Image<glm::vec3>& refLinear, int px, int py, double ppd)
{
    // Colour pipeline: CSF filters over a (2r+1)^2 square, r = ceil(3 sqrt(0.04 / (2 pi^2)) ppd).
    const int r = int(std::ceil(3 * std::sqrt(0.04 / (2 * kPi * kPi)) * ppd));
    const double params[3][4] = {
        {1, 0.0047, 0, 1e-5}, {1, 0.0053, 0, 1e-5}, {34.1, 0.04, 13.5, 0.025}};
    glm::dvec3 filtered[2] = {glm::dvec3(0), glm::dvec3(0)};
    for (int c = 0; c < 3; ++c) {
        const double* p = params[c];
        double sum = 0, acc[2] = {0, 0};
        for (int j = -r; j <= r; ++j)
            for (int i = -r; i <= r; ++i) {
                const double d2 = (i * i + j * j) / (ppd * ppd);
                const double s = p[0] * std::sqrt(kPi / p[1]) * std::exp(-kPi * kPi * d2 / p[1]) +
                                 p[2] * std::sqrt(kPi / p[3]) * std::exp(-kPi * kPi * d2 / p[3]);
                sum += s;
                acc[0] += s * convertToYcxcz(fetchPixel(testLinear, px + i, py + j))[c];
                acc[1] += s * convertToYcxcz(fetchPixel(refLinear, px + i, py + j))[c];
            }
        filtered[0][c] = acc[0] / sum;
        filtered[1][c] = acc[1] / sum;
    }
    const glm::dvec3 labT = convertToHuntLab(glm::clamp(convertYcxczToRgb(filtered[0]), 0.0, 1.0));
    const glm::dvec3 labR = convertToHuntLab(glm::clamp(convertYcxczToRgb(filtered[1]), 0.0, 1.0));
    const double cmax =
        std::pow(computeHyab(convertToHuntLab({0, 1, 0}), convertToHuntLab({0, 0, 1})), 0.7);
    const double e = std::pow(computeHyab(labT, labR), 0.7);
    const double colorError =
        e < 0.4 * cmax ? 0.95 / (0.4 * cmax) * e : 0.95 + (e - 0.4 * cmax) / (0.6 * cmax) * 0.05;

    // Feature pipeline: 2D Gaussian derivative kernels, sd = 0.5 * 0.082 * ppd, radius ceil(3 sd),
    // positive weights normalised to 1 and negative weights to -1, on Y / Yn.
    const double sd = 0.5 * 0.082 * ppd;
    const int fr = int(std::ceil(3 * sd));
    double posE = 0, negE = 0, posP = 0, negP = 0;
    for (int j = -fr; j <= fr; ++j)
        for (int i = -fr; i <= fr; ++i) {
            const double g = std::exp(-(i * i + j * j) / (2 * sd * sd));
            const double edge = -i * g, point = (i * i / (sd * sd) - 1) * g;
            (edge > 0 ? posE : negE) += std::abs(edge);
            (point > 0 ? posP : negP) += std::abs(point);
        }
    double magnitudes[2][2]; // [image][edge, point]
    for (int k = 0; k < 2; ++k) {
        const Image<glm::vec3>& image = k == 0 ? testLinear : refLinear;
        double ex = 0, ey = 0, qx = 0, qy = 0;
        for (int j = -fr; j <= fr; ++j)
            for (int i = -fr; i <= fr; ++i) {
                const double g = std::exp(-(i * i + j * j) / (2 * sd * sd));
                const double y = (convertToYcxcz(fetchPixel(image, px + i, py + j)).x + 16) / 116;
                const double edgeX = -i * g, edgeY = -j * g;
                const double pointX = (i * i / (sd * sd) - 1) * g;
                const double pointY = (j * j / (sd * sd) - 1) * g;
                ex += y * edgeX / (edgeX > 0 ? posE : negE);
                ey += y * edgeY / (edgeY > 0 ? posE : negE);
                qx += y * pointX / (pointX > 0 ? posP : negP);
                qy += y * pointY / (pointY > 0 ? posP : negP);
            }
        magnitudes[k][0] = std::hypot(ex, ey);
        magnitudes[k][1] = std::hypot(qx, qy);
    }
    const double featureError = std::pow(std::max(std::abs(magnitudes[0][0] - magnitudes[1][0]),
                                                  std::abs(magnitudes[0][1] - magnitudes[1][1])) /
                                             std::sqrt(2.0),
                                         0.5);
    return std::pow(colorError, 1 - featureError);
}

} // namespace

TEST(Flip, DefaultViewingConditionsGive67PixelsPerDegree)
{
    // 0.7 m * (3840 px / 0.7 m) * pi / 180 = 3840 pi / 180.
    EXPECT_NEAR(computePixelsPerDegree(0.7, 0.7, 3840), 67.02064, 1e-5);
    EXPECT_NEAR(kDefaultPixelsPerDegree, 67.02064, 1e-5);
}

TEST(Flip, IdenticalImagesGiveZero)
{
    const Image<glm::vec3> image = makeRandomRgb(48, 40, 11, 0.0, 1.0);
    const FlipResult r = computeFlip(image, image, ColorEncoding::Srgb);
    EXPECT_EQ(r.mean, 0.0);
    EXPECT_EQ(r.pixels, 48u * 40u);
    for (float v : r.map.pixels)
        EXPECT_EQ(v, 0.0f);
}

TEST(Flip, BlackVersusWhiteMatchesTheColorPipelineClosedForm)
{
    // Uniform images: CSF filtering leaves them unchanged and there are no features, so FLIP is
    // the redistributed colour error alone. HyAB(white, black) = |100 - 0| = 100. The largest
    // difference, green vs blue in Hunt-adjusted L*a*b* (textbook L*a*b* of sRGB green
    // (87.737, -86.188, 83.186) and blue (32.303, 79.194, -107.854)), is HyAB = 203.312, so
    // cmax = 203.312^0.7 = 41.2776. 100^0.7 = 25.1189 lies above the knee pc cmax = 16.511:
    // FLIP = 0.95 + (25.1189 - 16.511) / (41.2776 - 16.511) * 0.05 = 0.96738.
    // The paper maps the largest possible colour difference to 1 and compresses the top 60% of
    // the range into [0.95, 1]; black vs white is about half the maximum, hence ~0.967, not 1.
    // Tolerance 5e-4: the matrices differ in the 5th digit and the pipeline runs in float.
    const Image<glm::vec3> black(32, 32, glm::vec3(0.0f)), white(32, 32, glm::vec3(1.0f));
    const double expected = 0.967378;
    const FlipResult bw = computeFlip(black, white, ColorEncoding::Srgb);
    EXPECT_NEAR(bw.mean, expected, 5e-4);
    for (float v : bw.map.pixels)
        EXPECT_NEAR(v, expected, 5e-4);
    EXPECT_NEAR(computeFlip(white, black, ColorEncoding::Linear).mean, expected, 5e-4);
}

TEST(Flip, UniformRedShiftMatchesTheColorPipelineClosedForm)
{
    // Linear (0.7, 0.5, 0.5) against (0.5, 0.5, 0.5): HyAB of the Hunt-adjusted L*a*b* colours
    // is 8.807; 8.807^0.7 = 4.5804 is below the knee, so FLIP = 0.95 * 4.5804 / 16.511 = 0.31981
    // (computed from the textbook formulas above).
    const Image<glm::vec3> ref(24, 24, glm::vec3(0.5f)), test(24, 24, glm::vec3(0.7f, 0.5f, 0.5f));
    EXPECT_NEAR(computeFlip(test, ref, ColorEncoding::Linear).mean, 0.319814, 5e-4);
}

TEST(Flip, GrowsMonotonicallyWithAColorShift)
{
    const Image<glm::vec3> ref = makePattern(64, 64);
    double previous = 0;
    for (float shift : {0.02f, 0.05f, 0.1f, 0.2f, 0.4f}) {
        Image<glm::vec3> test = ref;
        for (glm::vec3& p : test.pixels)
            p.x = std::min(1.0f, p.x + shift);
        const double flip = computeFlip(test, ref, ColorEncoding::Srgb).mean;
        EXPECT_GT(flip, previous) << "shift " << shift;
        EXPECT_LT(flip, 1.0) << "shift " << shift;
        previous = flip;
    }
}

TEST(Flip, ErrorsStayLocalToTheFilterSupport)
{
    // One firefly in a grey image. The widest filter (blue-yellow CSF) has radius
    // ceil(3 sqrt(0.04 / (2 pi^2)) 67.02) = 10 px, the feature filters ceil(3 * 0.041 * 67.02)
    // = 9 px: beyond 10 px the two images are indistinguishable and the error is exactly 0.
    const Image<glm::vec3> ref(64, 64, glm::vec3(0.5f));
    Image<glm::vec3> test = ref;
    test.at(32, 32) = glm::vec3(1.0f);
    const FlipResult r = computeFlip(test, ref, ColorEncoding::Srgb);
    float maxValue = 0;
    int maxX = -1, maxY = -1;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) {
            const float v = r.map.at(x, y);
            EXPECT_GE(v, 0.0f);
            EXPECT_LE(v, 1.0f);
            if (std::max(std::abs(x - 32), std::abs(y - 32)) > 10) {
                EXPECT_EQ(v, 0.0f) << x << "," << y;
            }
            if (v > maxValue) {
                maxValue = v;
                maxX = x;
                maxY = y;
            }
        }
    EXPECT_EQ(maxX, 32);
    EXPECT_EQ(maxY, 32);
}

TEST(Flip, MatchesADirectEvaluationOfThePaperFormulas)
{
    // The library filters separably in float; computeFlipByDefinition uses full 2D kernels in
    // double with an independently written colour pipeline. They must agree to float precision
    // (1e-4 leaves room for the 4-digit matrix and float rounding amplified by the exponents).
    const double ppd = kDefaultPixelsPerDegree;
    // A firefly on grey (colour and point-feature error) ...
    const Image<glm::vec3> grey(48, 48, glm::vec3(0.2f));
    Image<glm::vec3> firefly = grey;
    firefly.at(24, 24) = glm::vec3(1.0f);
    const FlipResult a = computeFlip(firefly, grey, ColorEncoding::Linear);
    for (auto [x, y] : {std::pair{24, 24}, std::pair{26, 24}, std::pair{24, 29}, std::pair{30, 30}})
        EXPECT_NEAR(a.map.at(x, y), computeFlipByDefinition(firefly, grey, x, y, ppd), 1e-4)
            << x << "," << y;
    // ... and textured colour images with edges, including pixels at the image border.
    const Image<glm::vec3> ref = makePattern(40, 36);
    Image<glm::vec3> test = makeRandomRgb(40, 36, 13, 0.0, 1.0);
    for (std::size_t i = 0; i < test.pixels.size(); ++i)
        test.pixels[i] = 0.7f * ref.pixels[i] + 0.3f * test.pixels[i];
    for (int y = 10; y < 36; ++y)
        test.at(20, y) = glm::vec3(0.0f, 0.0f, 1.0f); // a blue edge
    const FlipResult b = computeFlip(test, ref, ColorEncoding::Linear);
    for (auto [x, y] : {std::pair{20, 20}, std::pair{21, 12}, std::pair{5, 7}, std::pair{0, 0},
                        std::pair{39, 35}, std::pair{33, 2}})
        EXPECT_NEAR(b.map.at(x, y), computeFlipByDefinition(test, ref, x, y, ppd), 1e-4)
            << x << "," << y;
    // A different observer (30 ppd) changes the filter sizes.
    FlipOptions observer;
    observer.pixelsPerDegree = 30.0;
    const FlipResult c = computeFlip(test, ref, ColorEncoding::Linear, observer);
    for (auto [x, y] : {std::pair{20, 20}, std::pair{8, 30}})
        EXPECT_NEAR(c.map.at(x, y), computeFlipByDefinition(test, ref, x, y, 30.0), 1e-4)
            << x << "," << y;
}

TEST(Flip, SrgbEncodingIsDecodedBeforeComparison)
{
    const Image<glm::vec3> a = makePattern(40, 40);
    Image<glm::vec3> b = a;
    for (glm::vec3& p : b.pixels)
        p = glm::vec3(p.y, p.z, p.x);
    const auto decode = [](float v) {
        return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
    };
    Image<glm::vec3> la = a, lb = b;
    for (glm::vec3& p : la.pixels)
        p = glm::vec3(decode(p.x), decode(p.y), decode(p.z));
    for (glm::vec3& p : lb.pixels)
        p = glm::vec3(decode(p.x), decode(p.y), decode(p.z));
    const double encoded = computeFlip(b, a, ColorEncoding::Srgb).mean;
    const double linear = computeFlip(lb, la, ColorEncoding::Linear).mean;
    EXPECT_NEAR(encoded, linear, 1e-5);
    // Reading encoded values as linear gives a different answer.
    EXPECT_GT(std::abs(computeFlip(b, a, ColorEncoding::Linear).mean - encoded), 1e-3);
}

TEST(HdrFlip, IdenticalImagesGiveZero)
{
    Image<glm::vec3> hdr = makeRandomRgb(40, 32, 12, 0.0, 20.0);
    const FlipResult r = computeHdrFlip(hdr, hdr);
    EXPECT_EQ(r.mean, 0.0);
    EXPECT_GE(r.exposureCount, 2);
}

TEST(HdrFlip, ExposureRangeComesFromTheReferenceLuminance)
{
    // Grey pixels: luminance = value. 30 pixels at 6, 70 at 0.5: max 6, median 0.5.
    // start = log2(T^-1(0.85) / 6), stop = log2(T^-1(0.85) / 0.5), stop - start = log2(12) =
    // 3.585, so max(2, ceil(3.585)) = 4 exposures.
    Image<glm::vec3> ref(10, 10, glm::vec3(0.5f));
    for (int i = 0; i < 30; ++i)
        ref.pixels[std::size_t(i * 3)] = glm::vec3(6.0f);
    const double x85 = invertAcesByBisection(0.85);
    EXPECT_NEAR(x85, 2.11887, 1e-4);
    const FlipResult r = computeHdrFlip(ref, ref);
    EXPECT_NEAR(r.startExposure, std::log2(x85 / 6.0), 1e-9);
    EXPECT_NEAR(r.stopExposure, std::log2(x85 / 0.5), 1e-9);
    EXPECT_EQ(r.exposureCount, 4);
    // The ACES tone mapper itself.
    for (double x : {0.0, 0.1, 1.0, 3.0, 10.0})
        EXPECT_NEAR(applyToneMapper(ToneMapper::Aces, glm::vec3(float(x))).x,
                    std::min(1.0, applyAcesCurve(x)), 1e-6);
}

TEST(HdrFlip, LargerExposureDifferenceGivesLargerError)
{
    Image<glm::vec3> ref = makePattern(48, 48);
    for (glm::vec3& p : ref.pixels)
        p *= 4.0f;
    double previous = 0;
    for (double stops : {0.1, 0.3, 1.0, 2.0}) {
        Image<glm::vec3> test = ref;
        for (glm::vec3& p : test.pixels)
            p *= float(std::exp2(stops));
        const double flip = computeHdrFlip(test, ref).mean;
        EXPECT_GT(flip, previous) << stops << " stops";
        previous = flip;
    }
}

TEST(HdrFlip, IsThePerPixelMaximumOfLdrFlipOverExposures)
{
    Image<glm::vec3> ref = makePattern(40, 40);
    for (glm::vec3& p : ref.pixels)
        p *= 3.0f;
    Image<glm::vec3> test = ref;
    for (std::size_t i = 0; i < test.pixels.size(); i += 7)
        test.pixels[i] *= 2.5f;

    const FlipResult full = computeHdrFlip(test, ref);
    ASSERT_GE(full.exposureCount, 2);
    for (double exposure : {full.startExposure, full.stopExposure}) {
        FlipOptions one;
        one.startExposure = exposure;
        one.stopExposure = exposure;
        const FlipResult single = computeHdrFlip(test, ref, one);
        EXPECT_EQ(single.exposureCount, 1);
        // One exposure is LDR-FLIP of the tone-mapped (linear) images.
        Image<glm::vec3> tt = test, tr = ref;
        const float scale = float(std::exp2(exposure));
        for (glm::vec3& p : tt.pixels)
            p = applyToneMapper(ToneMapper::Aces, p * scale);
        for (glm::vec3& p : tr.pixels)
            p = applyToneMapper(ToneMapper::Aces, p * scale);
        const FlipResult ldr = computeFlip(tt, tr, ColorEncoding::Linear);
        EXPECT_NEAR(single.mean, ldr.mean, 1e-5);
        for (std::size_t i = 0; i < full.map.pixels.size(); ++i)
            ASSERT_GE(full.map.pixels[i], single.map.pixels[i]) << "pixel " << i;
        EXPECT_GE(full.mean, single.mean);
    }
}

TEST(Flip, SizeMismatchAndBadOptionsThrow)
{
    const Image<glm::vec3> a(8, 8), b(8, 9);
    EXPECT_THROW(computeFlip(a, b, ColorEncoding::Srgb), std::invalid_argument);
    EXPECT_THROW(computeHdrFlip(a, b), std::invalid_argument);
    FlipOptions bad;
    bad.pixelsPerDegree = 0;
    EXPECT_THROW(computeFlip(a, a, ColorEncoding::Srgb, bad), std::invalid_argument);
    FlipOptions reversed;
    reversed.startExposure = 2;
    reversed.stopExposure = 1;
    EXPECT_THROW(computeHdrFlip(a, a, reversed), std::invalid_argument);
}
