// White-furnace tests: inside a closed sphere of albedo a = 0.5 whose surface emits Le, every
// surface leaves L = Le + a L, so L = Le / (1 - a) = 2 Le with unlimited bounces. With the
// bounce convention of reference.h (bounces = B: light reflected by at most B surfaces before the
// G-buffer point), full = Le sum_{k=0}^{B+1} a^k = Le (2 - 0.5^(B+1)), direct = a Le and
// indirect = Le sum_{k=2}^{B+1} a^k. Le = 0.5 normalises the unlimited case to 1.
// Tolerance: |L / expected - 1| <= 0.025 per pixel (pbrt's furnace criterion), and, stricter,
// |L - expected| <= 4 standard errors (+ 1e-6 for float storage): the furnace has no bias to hide.
#include "reference/reference.h"

#include "test_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

namespace rtlab::reference {
namespace {

constexpr float kLe = 0.5f;
constexpr float kAlbedo = 0.5f;

struct Furnace {
    scene::RenderScene scene;
    scene::GBuffer gbuffer;
    Furnace()
    {
        const auto m = test::addMaterial(scene, glm::vec3(kAlbedo), glm::vec3(kLe));
        test::addIcosphere(scene, glm::vec3(0.0f), 1.0f, 3, true, m);
        scene::Camera camera;
        camera.position = glm::vec3(0.1f, -0.2f, 0.05f);
        camera.target = glm::vec3(0.5f, 0.3f, 1.0f);
        camera.verticalFovDegrees = 100.0f;
        camera.nearPlane = 0.01f;
        camera.farPlane = 10.0f;
        gbuffer = castGBuffer(scene, camera, 8, 8);
    }
};

ReferenceSettings makeFurnaceSettings(Quantity q, int bounces)
{
    ReferenceSettings s = test::makeSettings(q);
    s.bounces = bounces;
    s.targetStdErr = 0.002;
    s.targetRelStdErr = 0.0;
    s.batchSize = 128;
    s.maxSamples = 16384;
    s.seed = 5;
    return s;
}

ReferenceResult checkFurnace(const Furnace& furnace, Quantity q, int bounces, double expected,
                             double target = 0.002)
{
    ReferenceSettings s = makeFurnaceSettings(q, bounces);
    s.targetStdErr = target;
    ReferenceResult r = computeReference(furnace.scene, furnace.gbuffer, s);
    EXPECT_EQ(r.stats.surfacePixels, 64); // the camera sees the sphere everywhere
    double worstRelative = 0.0, mean = 0.0;
    for (int y = 0; y < r.height; ++y) {
        for (int x = 0; x < r.width; ++x) {
            for (int c = 0; c < 3; ++c) {
                const double value = r.radiance.at(x, y)[c];
                const double se = r.radianceStdErr.at(x, y)[c];
                EXPECT_LE(std::abs(value / expected - 1.0), 0.025) << "(" << x << ", " << y << ")";
                EXPECT_LE(std::abs(value - expected), 4.0 * se + 1e-6)
                    << "(" << x << ", " << y << "): " << value << " vs " << expected << ", se "
                    << se;
                worstRelative = std::max(worstRelative, std::abs(value / expected - 1.0));
                mean += value / (3.0 * r.width * r.height);
            }
        }
    }
    EXPECT_LE(std::abs(mean / expected - 1.0), 0.025);
    std::printf("    %s, bounces %d: expected %.5f, image mean %.5f, worst pixel %.4f%%, "
                "%.0f samples/pixel\n",
                getQuantityName(q), bounces, expected, mean, 100.0 * worstRelative,
                r.stats.meanSamples);
    return r;
}

TEST(ReferenceFurnace, UnlimitedBouncesGiveTwiceTheEmission)
{
    const Furnace furnace;
    const ReferenceResult r = checkFurnace(furnace, Quantity::Full, -1, 2.0 * kLe, 0.004);
    // Every direction brings L = 1, so the irradiance is pi and radiance = Le + a E / pi.
    for (std::size_t i = 0; i < r.irradiance.size(); ++i) {
        EXPECT_LE(std::abs(r.irradiance.pixels[i].y - M_PI),
                  4.0 * r.irradianceStdErr.pixels[i].y + 1e-5);
        EXPECT_NEAR(r.radiance.pixels[i].y, kLe + kAlbedo * r.irradiance.pixels[i].y / M_PI, 1e-6);
    }
}

TEST(ReferenceFurnace, BounceCountsFollowTheGeometricSeries)
{
    const Furnace furnace;
    checkFurnace(furnace, Quantity::Full, 0, kLe * (2.0 - 0.5));
    checkFurnace(furnace, Quantity::Full, 2, kLe * (2.0 - 0.125));
    checkFurnace(furnace, Quantity::Direct, 2, kAlbedo * kLe);
    checkFurnace(furnace, Quantity::Indirect, 2, kLe * (0.25 + 0.125));
    checkFurnace(furnace, Quantity::Indirect, 1, kLe * 0.25);
}

} // namespace
} // namespace rtlab::reference
