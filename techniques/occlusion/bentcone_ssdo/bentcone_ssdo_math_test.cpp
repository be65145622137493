// Tests of the math of bentcone_ssdo: the sample pattern and rotations, the 2-band SH projection
// and reconstruction on analytic visibility functions, and the cone-cone intersection against
// numerical integration on the sphere.

#include "bentcone_ssdo_math.h"
#include "bentcone_ssdo_test_scene.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <set>
#include <vector>

namespace rtlab::bentcone_ssdo {
namespace {

using test::integrateCapIntersection;

constexpr double kPiD = std::numbers::pi;

TEST(BentConeSsdoMath, PatternIsCosineDistributedInAntipodalPairs)
{
    for (int count : {1, 2, 7, 16, 256}) {
        SCOPED_TRACE(count);
        const std::vector<glm::vec4> pattern = makeSamplePattern(count);
        ASSERT_EQ(int(pattern.size()), count);
        for (std::size_t k = 0; k < pattern.size(); ++k) {
            const glm::vec3 w(pattern[k]);
            EXPECT_NEAR(glm::length(w), 1.0f, 1e-6f);
            EXPECT_GT(w.z, 0.0f);
            EXPECT_GT(pattern[k].w, 0.0f);
            EXPECT_LE(pattern[k].w, 1.0f);
        }
        for (int j = 0; j + 1 < count; j += 2) { // pairs cancel bit for bit
            EXPECT_EQ(pattern[std::size_t(j)].x, -pattern[std::size_t(j + 1)].x);
            EXPECT_EQ(pattern[std::size_t(j)].y, -pattern[std::size_t(j + 1)].y);
            EXPECT_EQ(pattern[std::size_t(j)].z, pattern[std::size_t(j + 1)].z);
        }
        if (count % 2 == 1) {
            EXPECT_EQ(glm::vec3(pattern.back()), glm::vec3(0.0f, 0.0f, 1.0f));
        }
    }
    // Cosine distribution: E[cos theta] = 2/3. The z values are the midpoint rule for
    // Int_0^1 sqrt(1 - s) ds over P = 128 strata, whose error is O(P^-1.5) ~ 7e-4 / 20.
    // The distance law P(u <= s) = s^3 makes u^3 uniform; stratified, its values are the
    // midpoints (r + 1/2) / N, one per stratum, so their mean is 1/2 up to float rounding.
    const std::vector<glm::vec4> pattern = makeSamplePattern(256);
    double meanZ = 0.0, meanU3 = 0.0;
    for (const glm::vec4& s : pattern) {
        meanZ += s.z / 256.0;
        meanU3 += double(s.w) * s.w * s.w / 256.0;
    }
    EXPECT_NEAR(meanZ, 2.0 / 3.0, 1e-4);
    EXPECT_NEAR(meanU3, 0.5, 1e-6);
    std::vector<float> cubes;
    for (const glm::vec4& s : pattern)
        cubes.push_back(s.w * s.w * s.w);
    std::sort(cubes.begin(), cubes.end());
    for (int r = 0; r < 256; ++r)
        EXPECT_NEAR(cubes[std::size_t(r)], (r + 0.5) / 256.0, 1e-6);
}

TEST(BentConeSsdoMath, CellRotationsCoverTheCircleAndAdvanceByTheGoldenRatio)
{
    std::set<int> ranks;
    for (int y = 0; y < kCellSide; ++y)
        for (int x = 0; x < kCellSide; ++x)
            ranks.insert(getCellRank(x, y));
    EXPECT_EQ(ranks.size(), 16u);
    EXPECT_EQ(*ranks.begin(), 0);
    EXPECT_EQ(*ranks.rbegin(), 15);
    EXPECT_EQ(getCellRank(5, 6), getCellRank(1, 2)); // periodic
    EXPECT_EQ(getFrameTurn(0), 0.0);
    EXPECT_EQ(getFrameTurn(1), 40503.0 / 65536.0);
    EXPECT_GE(getFrameTurn(-7), 0.0);
    EXPECT_LT(getFrameTurn(-7), 1.0);
    for (const glm::vec2& r : makeCellRotations(12345))
        EXPECT_NEAR(glm::length(r), 1.0f, 1e-6f);
}

TEST(BentConeSsdoMath, ShOfTheClampedCosineReconstructsItsTwoBandProjection)
{
    // The clamped cosine max(cos theta, 0) about z has L00 = Y00 pi, L10 = Y1 2pi/3; its 2-band
    // reconstruction is 1/4 + cos(theta)/2: 3/4 at the pole, 1/4 at the horizon, -1/4 below.
    // Tolerance 1e-5: the basis constants are rounded to 6 digits (relative 1e-6).
    const glm::vec4 sh(kShY00 * kPi, 0.0f, kShY1 * 2.0f * kPi / 3.0f, 0.0f);
    EXPECT_NEAR(reconstructSh(sh, {0, 0, 1}), 0.75f, 1e-5f);
    EXPECT_NEAR(reconstructSh(sh, {1, 0, 0}), 0.25f, 1e-5f);
    EXPECT_NEAR(reconstructSh(sh, {0, 0, -1}), -0.25f, 1e-5f);
    const BentCone cone = convertShToBentCone(sh, {0, 0, 1});
    EXPECT_NEAR(cone.visibleFraction, 1.0f, 1e-6f);
    EXPECT_NEAR(cone.axis.z, 1.0f, 1e-7f);
    EXPECT_NEAR(cone.aperture, kPi / 2.0f, 2e-3f); // asin near 1: sqrt(2 * 1e-6)
    const BentCone closed = convertShToBentCone(glm::vec4(0.0f), {0.6f, 0.0f, 0.8f});
    EXPECT_EQ(closed.visibleFraction, 0.0f);
    EXPECT_EQ(closed.aperture, 0.0f);
    EXPECT_EQ(closed.axis, glm::vec3(0.6f, 0.0f, 0.8f)); // nothing visible: the normal
}

//! Projects V(w) max(cos, 0) with the sample pattern as the technique does (weight pi/N per
//! unoccluded sample), averaged over `turns` evenly spaced rotations of the pattern about z.
glm::dvec4 projectWithPattern(const std::vector<glm::vec4>& pattern, int turns,
                              const std::function<bool(const glm::dvec3&)>& isVisible)
{
    glm::dvec4 sh(0.0);
    for (int m = 0; m < turns; ++m) {
        const double angle = 2.0 * kPiD * (m + 0.5) / turns;
        const double c = std::cos(angle), s = std::sin(angle);
        for (const glm::vec4& p : pattern) {
            const glm::dvec3 w(c * p.x - s * p.y, s * p.x + c * p.y, p.z);
            if (isVisible(w))
                sh += kPiD / double(pattern.size()) *
                      glm::dvec4(kShY00, kShY1 * w.y, kShY1 * w.z, kShY1 * w.x);
        }
    }
    return sh / double(turns);
}

TEST(BentConeSsdoMath, ShProjectionOfAnOpenHemisphereGivesTheNormalAndFullVisibility)
{
    const std::vector<glm::vec4> pattern = makeSamplePattern(256);
    const glm::dvec4 sh = projectWithPattern(pattern, 1, [](const glm::dvec3&) { return true; });
    EXPECT_NEAR(sh.x, kShY00 * kPiD, 1e-9);
    EXPECT_NEAR(sh.y, 0.0, 1e-12); // antipodal pairs cancel
    EXPECT_NEAR(sh.w, 0.0, 1e-12);
    // L10 = Y1 * pi * mean(z), mean(z) = 2/3 within 1e-4 (pattern test).
    EXPECT_NEAR(sh.z, kShY1 * 2.0 * kPiD / 3.0, kShY1 * kPiD * 1e-4);
    const BentCone cone = convertShToBentCone(glm::vec4(sh), {0, 0, 1});
    EXPECT_NEAR(cone.visibleFraction, 1.0f, 1e-6f);
    EXPECT_NEAR(cone.axis.z, 1.0f, 1e-7f);
    EXPECT_NEAR(reconstructSh(glm::vec4(sh), {0, 0, 1}), 0.75f, 1e-4f);
}

TEST(BentConeSsdoMath, ShProjectionOfAHalfSpaceTiltsTheBentNormalByAtanTwoOverPi)
{
    // Visible where w.x > 0 (a wall through the point along x = 0). Continuous values:
    // A = 1/2; Int V cos w = (2/3, 0, pi/3), so the bent normal tilts by atan(2/pi) toward +x,
    // and the SH are L00 = Y00 pi/2, L11 = Y1 2/3, L10 = Y1 pi/3. With the pattern averaged over
    // rotations, each sample (disk radius rho, height z) is visible half of the time and adds
    // rho/pi to x on average, and the pattern's sum of rho equals its sum of z (strata mirrored
    // about 1/2), so the tilt is exactly atan(2/pi) up to the rotation average's O(turns^-2) and
    // float rounding of the pattern (1e-7); L11 and L10 keep the 1e-4 error of mean(z).
    const std::vector<glm::vec4> pattern = makeSamplePattern(256);
    const glm::dvec4 sh =
        projectWithPattern(pattern, 4096, [](const glm::dvec3& w) { return w.x > 0.0; });
    EXPECT_NEAR(sh.x, kShY00 * kPiD / 2.0, 1e-9);
    EXPECT_NEAR(sh.w, kShY1 * 2.0 / 3.0, kShY1 * 2e-4);
    EXPECT_NEAR(sh.z, kShY1 * kPiD / 3.0, kShY1 * 2e-4);
    EXPECT_NEAR(sh.y, 0.0, 1e-6);
    const BentCone cone = convertShToBentCone(glm::vec4(sh), {0, 0, 1});
    EXPECT_NEAR(cone.visibleFraction, 0.5f, 1e-6f);
    const double tilt = std::atan2(double(cone.axis.x), double(cone.axis.z));
    EXPECT_NEAR(tilt, std::atan(2.0 / kPiD), 1e-5);
    EXPECT_NEAR(cone.aperture, kPi / 4.0f, 1e-6f); // sin^2 = 1/2
    // Reconstruction of the 2-band projection:
    // f(w) = Y00 L00 + Y1 (L11 w.x + L10 w.z) = 1/8 + Y1^2 (2/3 w.x + pi/3 w.z).
    const double y1Squared = double(kShY1) * kShY1;
    EXPECT_NEAR(reconstructSh(glm::vec4(sh), {1, 0, 0}), 0.125 + y1Squared * 2.0 / 3.0, 1e-4);
    EXPECT_NEAR(reconstructSh(glm::vec4(sh), {0, 0, 1}), 0.125 + y1Squared * kPiD / 3.0, 1e-4);
}

TEST(BentConeSsdoMath, ExactCapIntersectionMatchesNumericalIntegration)
{
    // Tolerance 3e-6 sr + 1e-4 of the smaller cap: the float formula keeps ~1e-6 sr absolute and
    // ~3e-5 relative (small caps: their versine carries the digits), the integration < 1e-6 sr.
    const float cone = getDirectionCap().angle;
    const std::vector<float> halfAngles = {0.0f, 0.02f, 0.3f, cone, 0.9f, 1.3f, 0.5f * kPi};
    double worst = 0.0;
    for (float a : halfAngles) {
        for (float b : halfAngles) {
            const double smaller = 2.0 * kPiD * (1.0 - std::cos(double(std::min(a, b))));
            for (int i = 0; i <= 64; ++i) {
                const float d = kPi * float(i) / 64.0f;
                const double exact = integrateCapIntersection(d, a, b);
                const double closed = intersectCaps(d, a, b, ConeIntersection::Exact);
                worst = std::max(worst, std::abs(closed - exact));
                ASSERT_NEAR(closed, exact, 3e-6 + 1e-4 * smaller)
                    << "d " << d << " a " << a << " b " << b;
            }
        }
    }
    RecordProperty("worst_abs_error_sr", std::to_string(worst));
    // Symmetry and the limits: containment and disjointness are exact, tangency is continuous.
    EXPECT_FLOAT_EQ(intersectCaps(0.7f, 0.4f, 1.2f, ConeIntersection::Exact),
                    intersectCaps(0.7f, 1.2f, 0.4f, ConeIntersection::Exact));
    EXPECT_NEAR(intersectCaps(0.1f, 0.3f, 1.0f, ConeIntersection::Exact),
                2.0 * kPiD * (1.0 - std::cos(0.3)), 1e-6);
    EXPECT_EQ(intersectCaps(1.31f, 0.3f, 1.0f, ConeIntersection::Exact), 0.0f);
    EXPECT_LT(intersectCaps(1.2999f, 0.3f, 1.0f, ConeIntersection::Exact), 1e-5f);
    EXPECT_GT(intersectCaps(0.7001f, 0.3f, 1.0f, ConeIntersection::Exact),
              2.0 * kPiD * (1.0 - std::cos(0.3)) - 1e-5);
    // Two hemispheres d apart meet in a lune of angle pi - d: 2 (pi - d).
    EXPECT_NEAR(intersectCaps(1.0f, kPi / 2, kPi / 2, ConeIntersection::Exact), 2.0f * (kPi - 1.0f),
                2e-6f);
}

TEST(BentConeSsdoMath, SmoothstepIntersectionIsExactAtTheEndsAndCloseBetween)
{
    // [Oat & Sander 2007] is a fit: it is exact at containment and separation, and in between
    // (direction cone against apertures 0..pi/2, all axis angles) it stays within 0.15 of the
    // direction cone's solid angle of the exact value (0.141 measured on this grid; documented
    // in README.md as the approximation's error, not a tolerance of the implementation).
    const float cone = getDirectionCap().angle;
    const float coneArea = 2.0f * kPi * (1.0f - kConeCosHalfAngle);
    double worst = 0.0;
    for (int j = 0; j <= 32; ++j) {
        const float aperture = 0.5f * kPi * float(j) / 32.0f;
        for (int i = 0; i <= 256; ++i) {
            const float d = kPi * float(i) / 256.0f;
            const float smooth = intersectCaps(d, cone, aperture, ConeIntersection::Smoothstep);
            const float exact = intersectCaps(d, cone, aperture, ConeIntersection::Exact);
            worst = std::max(worst, double(std::abs(smooth - exact)) / coneArea);
            if (d < std::abs(aperture - cone) - 1e-4f || d > aperture + cone + 1e-4f) {
                EXPECT_EQ(smooth, exact);
            }
        }
    }
    RecordProperty("worst_error_of_cone", std::to_string(worst));
    EXPECT_LT(worst, 0.15);
}

TEST(BentConeSsdoMath, ConeVisibilityOfAnOpenHemisphereIsTheFractionAboveTheSurface)
{
    // B = H (aperture pi/2 about the normal): the visibility of each direction cone is the
    // fraction of it above the surface, by numerical integration (tolerance as above / |C|).
    const float coneArea = 2.0f * kPi * (1.0f - kConeCosHalfAngle);
    const Cap open = makeApertureCap(1.0);
    const glm::vec3 normal(0.0f, 0.0f, 1.0f);
    for (int i = 0; i <= 90; ++i) {
        const double elevation = kPiD * (i - 45) / 90.0; // -90 .. 90 degrees
        const glm::vec3 dir(float(std::cos(elevation)), 0.0f, float(std::sin(elevation)));
        const double expected =
            integrateCapIntersection(kPiD / 2.0 - elevation, std::acos(7.0 / 8.0), kPiD / 2.0) /
            coneArea;
        EXPECT_NEAR(computeConeVisibility(dir, normal, open, normal, ConeIntersection::Exact),
                    expected, 3e-6 / coneArea)
            << "elevation " << elevation;
    }
    // Closed cone (nothing visible): every direction 0.
    EXPECT_EQ(computeConeVisibility(normal, normal, makeApertureCap(0.0), normal,
                                    ConeIntersection::Exact),
              0.0f);
}

TEST(BentConeSsdoMath, ApertureTableFollowsTheCosineConvention)
{
    const std::vector<glm::vec4> table = makeApertureTable(16);
    ASSERT_EQ(table.size(), 17u);
    for (int c = 0; c <= 16; ++c) {
        const glm::vec4 e = table[std::size_t(c)];
        const double a = c / 16.0;
        EXPECT_NEAR(std::sin(double(e.x)) * std::sin(double(e.x)), a, 1e-6); // sin^2 = A
        EXPECT_NEAR(e.y, std::sqrt(1.0 - a), 1e-7);
        EXPECT_NEAR(e.z, std::sqrt(a), 1e-7);
        EXPECT_NEAR(e.w, 1.0 - std::sqrt(1.0 - a), 1e-7);
    }
    EXPECT_EQ(table[0].x, 0.0f);
    EXPECT_EQ(table[16].x, 0.5f * kPi);
}

} // namespace
} // namespace rtlab::bentcone_ssdo
