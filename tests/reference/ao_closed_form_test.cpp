// Occlusion quantities against closed forms. Every comparison allows 4 x the reference's own
// standard error plus the exact effect of its ray offset (rays leave eps above the surface, so a
// parallel occluder at height h is seen at h - eps) and float32 storage (1e-6).
//
// Parallel plane at height h above the point, radius r, c = h / r < 1 (mu = cos(theta); the ray
// hits at d = h / mu, which is within r iff mu > c):
//   cosine AO     A   = (1/pi) Int_{mu < c} cos dw = 2 Int_0^c mu dmu = c^2
//   uniform AO    A_u = (1/2pi) Int_{mu < c} dw = c
//   obscurance    W   = 2 Int_0^1 rho(min(1, c / mu)) mu dmu   (linear rho: 2c - c^2)
//   bent normal   n (symmetry); aperture asin(c), uniform aperture acos(1 - c)
// Perpendicular wall at distance d, radius r, c = d / r: occluded iff w_x > c. The cosine-weighted
// measure is uniform on the projected unit disk (Nusselt), so
//   A   = 1 - (acos(c) - c sqrt(1 - c^2)) / pi      (disk segment x > c)
//   A_u = (1 + c) / 2                                 (w_x is uniform on [-1, 1] over a hemisphere)
//   W   = 1 - (1/pi) Int_c^1 (1 - rho(c / x)) 2 sqrt(1 - x^2) dx
// With r = infinity everything with w_x > 0 is occluded: A = A_u = 1/2 and
//   bent ~ ((1/pi) Int_{x<0} x dA, (1/pi) Int_{x<0} sqrt(1 - x^2 - z^2) dA) = (-2/3, pi/3) / pi,
//   i.e. tilted atan(2/pi) = 32.48 degrees away from the wall.
#include "reference/reference.h"

#include "test_scenes.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>

namespace rtlab::reference {
namespace {

constexpr double kPiD = 3.14159265358979323846;
constexpr int kSize = 8; // 8 x 8 pixels: rows vary the distance, columns the position
constexpr double kFloatSlack = 1e-6;

double getRowValue(int row)
{
    return 0.1 + 0.8 * row / double(kSize - 1); // h / r or d / r in [0.1, 0.9]
}

//! A ceiling at y = 1 over [-4, 4]^2 and points at y = 1 - h(row) looking up (radius 1).
struct CeilingCase {
    scene::RenderScene scene;
    scene::GBuffer gbuffer;
    CeilingCase()
    {
        const auto m = test::addMaterial(scene, glm::vec3(0.5f));
        test::addQuad(scene, {-4, 1, -4}, {8, 0, 0}, {0, 0, 8}, m);
        gbuffer =
            test::makePointGBuffer(kSize, kSize, [](int x, int y, glm::vec3& p, glm::vec3& n) {
                p = glm::vec3(-0.5f + float(x) / kSize, 1.0f - float(getRowValue(y)), 0.3f);
                n = glm::vec3(0, 1, 0);
                return true;
            });
    }
};

//! A wall x = 1 over y in [0, 2], z in [-3, 3] and points at distance d(row) on the floor y = 0.
struct WallCase {
    scene::RenderScene scene;
    scene::GBuffer gbuffer;
    WallCase()
    {
        const auto m = test::addMaterial(scene, glm::vec3(0.5f));
        test::addQuad(scene, {1, 0, -3}, {0, 2, 0}, {0, 0, 6}, m);
        gbuffer =
            test::makePointGBuffer(kSize, kSize, [](int x, int y, glm::vec3& p, glm::vec3& n) {
                p = glm::vec3(1.0f - float(getRowValue(y)), 0.0f, -0.5f + float(x) / kSize);
                n = glm::vec3(0, 1, 0);
                return true;
            });
    }
};

ReferenceSettings makeOcclusionSettings(Quantity q, double radius)
{
    ReferenceSettings s = test::makeSettings(q);
    s.radius = radius;
    s.targetStdErr = 0.004;
    s.targetRelStdErr = 0.0;
    s.batchSize = 256;
    s.maxSamples = 32768;
    s.seed = 11;
    return s;
}

//! Compares a scalar image with expected(row, value at h - eps): |ref - A(h)| <= 4 se + |A(h) -
//! A(h - eps)| + float slack; returns the largest error in units of se (for the log).
double checkScalar(const Image<float>& value, const Image<float>& stdErr,
                   const std::function<double(double)>& expected, double epsilonShift,
                   const char* what)
{
    double worst = 0.0;
    for (int y = 0; y < kSize; ++y) {
        const double c = getRowValue(y);
        const double exact = expected(c);
        const double bias = std::abs(exact - expected(c - epsilonShift));
        for (int x = 0; x < kSize; ++x) {
            const double se = stdErr.at(x, y);
            const double error = std::abs(double(value.at(x, y)) - exact);
            EXPECT_GT(se, 0.0) << what << " at (" << x << ", " << y << ")";
            EXPECT_LE(error, 4.0 * se + bias + kFloatSlack)
                << what << " at (" << x << ", " << y << "): " << value.at(x, y) << " vs " << exact
                << ", se " << se << ", bias bound " << bias;
            worst = std::max(worst, (error - bias) / se);
        }
    }
    std::printf("    %s: worst |error| - bias = %.2f standard errors\n", what, worst);
    return worst;
}

double integrateObscuranceCeiling(Falloff f, double c)
{
    // rho = 1 below mu = c (the hit is beyond r); split there, where the integrand has a kink.
    return c * c + 2.0 * test::integrate([&](double mu) { return evaluateFalloff(f, c / mu) * mu; },
                                         c, 1.0);
}

double integrateObscuranceWall(Falloff f, double c)
{
    // x = cos(t) removes the square-root endpoint of the disk's chord length 2 sqrt(1 - x^2).
    return 1.0 - test::integrate(
                     [&](double t) {
                         const double x = std::cos(t);
                         return (1.0 - evaluateFalloff(f, c / x)) * 2.0 * std::sin(t) * std::sin(t);
                     },
                     0.0, std::acos(c)) /
                     kPiD;
}

TEST(ReferenceClosedForm, CeilingCosineAndUniformAo)
{
    const CeilingCase ceiling;
    const auto ao =
        computeReference(ceiling.scene, ceiling.gbuffer, makeOcclusionSettings(Quantity::Ao, 1.0));
    const double eps = ao.stats.rayEpsilon; // h -> h - eps, in units of r = 1
    EXPECT_GT(eps, 0.0);
    EXPECT_EQ(ao.stats.pixelsAtCap, 0);
    checkScalar(
        ao.occlusion, ao.occlusionStdErr, [](double c) { return c * c; }, eps, "ao");

    const auto au = computeReference(ceiling.scene, ceiling.gbuffer,
                                     makeOcclusionSettings(Quantity::AoUniform, 1.0));
    checkScalar(
        au.occlusion, au.occlusionStdErr, [](double c) { return c; }, eps, "ao_uniform");
}

TEST(ReferenceClosedForm, CeilingObscurance)
{
    const CeilingCase ceiling;
    // The linear falloff has the closed form 2c - c^2; check the quadrature against it first.
    EXPECT_NEAR(integrateObscuranceCeiling(Falloff::Linear, 0.3), 2 * 0.3 - 0.09, 1e-12);
    for (Falloff f : {Falloff::Linear, Falloff::Smoothstep}) {
        ReferenceSettings s = makeOcclusionSettings(Quantity::Obscurance, 1.0);
        s.falloff = f;
        const auto w = computeReference(ceiling.scene, ceiling.gbuffer, s);
        checkScalar(
            w.occlusion, w.occlusionStdErr,
            [&](double c) { return integrateObscuranceCeiling(f, c); }, w.stats.rayEpsilon,
            f == Falloff::Linear ? "obscurance linear" : "obscurance smoothstep");
    }
}

TEST(ReferenceClosedForm, CeilingBentConeIsTheNormal)
{
    const CeilingCase ceiling;
    const auto b = computeReference(ceiling.scene, ceiling.gbuffer,
                                    makeOcclusionSettings(Quantity::Bent, 1.0));
    const double eps = b.stats.rayEpsilon;
    checkScalar(
        b.occlusion, b.occlusionStdErr, [](double c) { return c * c; }, eps, "bent ao");
    checkScalar(
        b.aperture, b.apertureStdErr, [](double c) { return std::asin(c); }, eps,
        "aperture (sin^2 = A)");
    checkScalar(
        b.apertureUniform, b.apertureUniformStdErr, [](double c) { return std::acos(1.0 - c); },
        eps, "aperture (1 - cos = A_u)");
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const double angle = std::acos(std::min(1.0, double(b.bentNormal.at(x, y).y)));
            EXPECT_LE(angle, 4.0 * b.bentNormalStdErr.at(x, y) + kFloatSlack) << x << ", " << y;
        }
}

TEST(ReferenceClosedForm, PerpendicularWallAo)
{
    // The ray offset is parallel to the wall: no bias. The quadrature reproduces the cosine AO's
    // closed form when rho = 0 (step falloff), which checks it.
    const double c = 0.35;
    EXPECT_NEAR(1.0 - test::integrate([&](double t) { return 2.0 * std::sin(t) * std::sin(t); },
                                      0.0, std::acos(c)) /
                          kPiD,
                1.0 - (std::acos(c) - c * std::sqrt(1.0 - c * c)) / kPiD, 1e-12);
    const WallCase wall;
    const auto ao =
        computeReference(wall.scene, wall.gbuffer, makeOcclusionSettings(Quantity::Ao, 1.0));
    checkScalar(
        ao.occlusion, ao.occlusionStdErr,
        [](double c) { return 1.0 - (std::acos(c) - c * std::sqrt(1.0 - c * c)) / kPiD; }, 0.0,
        "wall ao");
    const auto au =
        computeReference(wall.scene, wall.gbuffer, makeOcclusionSettings(Quantity::AoUniform, 1.0));
    checkScalar(
        au.occlusion, au.occlusionStdErr, [](double c) { return 0.5 * (1.0 + c); }, 0.0,
        "wall ao_uniform");
    ReferenceSettings s = makeOcclusionSettings(Quantity::Obscurance, 1.0);
    s.falloff = Falloff::Smoothstep;
    const auto w = computeReference(wall.scene, wall.gbuffer, s);
    checkScalar(
        w.occlusion, w.occlusionStdErr,
        [](double c) { return integrateObscuranceWall(Falloff::Smoothstep, c); }, 0.0,
        "wall obscurance smoothstep");
}

TEST(ReferenceClosedForm, BentNormalBesideAnInfiniteWall)
{
    // A 1e4-high, 2e4-wide wall at x = 1, points 0.1 .. 0.9 from it, radius infinite. Directions
    // with 0 < w_x < 1e-4 may pass the wall's edges: a cosine-weighted share below 2e-4/pi of the
    // hemisphere, which bounds the bias of A, A_u and the bent vector's components by 1e-4 (the
    // bent direction, |m| = 0.395, by 2.6e-4 rad; the apertures by 1.2e-4 rad).
    scene::RenderScene wallScene;
    const auto m = test::addMaterial(wallScene, glm::vec3(0.5f));
    test::addQuad(wallScene, {1, 0, -1e4f}, {0, 1e4f, 0}, {0, 0, 2e4f}, m);
    const auto g =
        test::makePointGBuffer(kSize, kSize, [](int x, int y, glm::vec3& p, glm::vec3& n) {
            p = glm::vec3(1.0f - float(getRowValue(y)), 0.0f, -0.5f + float(x) / kSize);
            n = glm::vec3(0, 1, 0);
            return true;
        });
    const auto b = computeReference(
        wallScene, g,
        makeOcclusionSettings(Quantity::Bent, std::numeric_limits<double>::infinity()));
    const glm::dvec3 expected = glm::normalize(glm::dvec3(-2.0 / 3.0, kPiD / 3.0, 0.0));
    EXPECT_NEAR(std::acos(expected.y), std::atan(2.0 / kPiD), 1e-12); // 32.48 degrees
    double worst = 0.0;
    for (int y = 0; y < kSize; ++y) {
        for (int x = 0; x < kSize; ++x) {
            const double angle =
                std::acos(std::min(1.0, glm::dot(glm::dvec3(b.bentNormal.at(x, y)), expected)));
            EXPECT_LE(angle, 4.0 * b.bentNormalStdErr.at(x, y) + 2.6e-4)
                << "(" << x << ", " << y << "): " << angle << " rad off";
            worst = std::max(worst, angle);
            EXPECT_LE(std::abs(b.occlusion.at(x, y) - 0.5),
                      4.0 * b.occlusionStdErr.at(x, y) + 1e-4);
            EXPECT_LE(std::abs(b.aperture.at(x, y) - kPiD / 4.0),
                      4.0 * b.apertureStdErr.at(x, y) + 1.2e-4);
            EXPECT_LE(std::abs(b.apertureUniform.at(x, y) - kPiD / 3.0),
                      4.0 * b.apertureUniformStdErr.at(x, y) + 1.2e-4);
        }
    }
    std::printf("    bent normal: worst angle %.5f rad (%.3f deg)\n", worst, worst * 180.0 / kPiD);
}

} // namespace
} // namespace rtlab::reference
