// Unit tests of bentcone_ssdo on analytic G-buffers: registration, an open plane, a floor in
// front of a wall (closed form of this estimator), monotonicity in the radius, determinism, and
// CPU/GPU parity (lavapipe with the validation layer). The family suite in tests/ also runs
// every occlusion technique.

#include "bentcone_ssdo_cpu.h"
#include "bentcone_ssdo_test_scene.h"

#include "core/error.h"
#include "gpu/context.h"
#include "families/occlusion/occlusion.h"
#include "scene/sky.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <string>

// Defined by RTLAB_REGISTER_TECHNIQUE at the bottom of bentcone_ssdo.cpp.
void rtlabRegisterTechnique_occlusion_bentcone_ssdo(rtlab::plugin::Registry& registry);

namespace rtlab::bentcone_ssdo {
namespace {

using Overrides = std::map<std::string, config::ParamValue>;
constexpr double kPiD = std::numbers::pi;

std::unique_ptr<plugin::OcclusionTechnique> makeTechnique(const Overrides& overrides = {})
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    rtlabRegisterTechnique_occlusion_bentcone_ssdo(registry);
    const plugin::TechniqueEntry* entry = registry.findTechnique("occlusion", "bentcone_ssdo");
    if (entry == nullptr)
        throw std::logic_error("bentcone_ssdo is not registered");
    config::ParamSet params = config::ParamSet::defaultsOf(entry->schema);
    for (const auto& [name, value] : overrides)
        params.set(name, value);
    std::unique_ptr<plugin::Technique> technique = entry->create(params);
    return std::unique_ptr<plugin::OcclusionTechnique>(
        dynamic_cast<plugin::OcclusionTechnique*>(technique.release()));
}

plugin::OcclusionInput makeInput(const test::TestGBuffer& g, int frameIndex = 0,
                                 gpu::Context* context = nullptr)
{
    plugin::OcclusionInput input{&g.depth, &g.normal, g.projection, g.view, frameIndex, context};
    return input;
}

TEST(BentConeSsdo, RegistersWithItsParameters)
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    rtlabRegisterTechnique_occlusion_bentcone_ssdo(registry);
    const plugin::TechniqueEntry* entry = registry.findTechnique("occlusion", "bentcone_ssdo");
    ASSERT_NE(entry, nullptr);
    EXPECT_EQ(entry->info.seed, "000_3da000e866ebc485.txt");
    const auto technique = makeTechnique({{"radius", 0.75}, {"samples", std::int64_t(9)}});
    const config::ParamSet effective = technique->effectiveParams();
    EXPECT_EQ(effective.values().size(), entry->schema.specs().size());
    EXPECT_EQ(effective.getFloat("radius"), 0.75);
    EXPECT_EQ(effective.getInt("samples"), 9);
    EXPECT_EQ(effective.getString("cone_intersection"), "exact");
    const plugin::OcclusionDefinition definition = technique->definition();
    EXPECT_EQ(definition.quantity, plugin::OcclusionQuantity::CosineAo);
    EXPECT_EQ(definition.radius, 0.75);
}

//! A plane facing the camera at depth 3, seen by a camera turned arbitrarily in the world (the
//! 16 world directions then land at various angles to the view-space normal +z).
test::TestGBuffer makeFacingPlane(int w, int h)
{
    test::TestGBuffer g;
    scene::Camera camera;
    camera.position = glm::vec3(1.0f, 2.0f, 3.0f);
    camera.target = glm::vec3(-0.3f, 0.4f, -0.2f);
    camera.up = glm::vec3(0.2f, 1.0f, 0.1f);
    g.view = camera.viewMatrix();
    g.projection = camera.projectionMatrix(float(w) / float(h));
    g.depth = Image<float>(w, h, 3.0f);
    g.normal = Image<glm::vec3>(w, h, glm::vec3(0.0f, 0.0f, 1.0f));
    return g;
}

void checkFacingPlane(const plugin::OcclusionOutput& out, const glm::mat4& view, float tolerance)
{
    const float coneArea = 2.0f * kPi * (1.0f - kConeCosHalfAngle);
    const double coneHalfAngle = std::acos(7.0 / 8.0);
    std::array<double, kConeCount> expected{};
    for (int i = 0; i < kConeCount; ++i) {
        const glm::dvec3 d = glm::normalize(glm::dmat3(glm::dmat4(view)) *
                                            scene::getConeDirections()[std::size_t(i)]);
        const double angle = std::acos(std::clamp(d.z, -1.0, 1.0)); // to the normal +z
        expected[std::size_t(i)] =
            test::integrateCapIntersection(angle, coneHalfAngle, kPiD / 2.0) / coneArea;
        if (angle < kPiD / 2.0 - coneHalfAngle - 1e-3) {
            EXPECT_EQ(out.coneVisibility[std::size_t(i)].pixels[0], 1.0f) << "well above " << i;
        }
        if (angle > kPiD / 2.0 + coneHalfAngle + 1e-3) {
            EXPECT_EQ(out.coneVisibility[std::size_t(i)].pixels[0], 0.0f) << "well below " << i;
        }
    }
    for (std::size_t p = 0; p < out.ambient.pixels.size(); ++p) {
        ASSERT_EQ(out.ambient.pixels[p], 1.0f);
        ASSERT_NEAR(out.bentNormal.pixels[p].x, 0.0f, 1e-6f);
        ASSERT_NEAR(out.bentNormal.pixels[p].y, 0.0f, 1e-6f);
        ASSERT_NEAR(out.bentNormal.pixels[p].z, 1.0f, 1e-6f);
        ASSERT_NEAR(out.coneAperture.pixels[p], 0.5f * kPi, 1e-6f);
        for (int i = 0; i < kConeCount; ++i)
            ASSERT_NEAR(out.coneVisibility[std::size_t(i)].pixels[p], expected[std::size_t(i)],
                        tolerance)
                << "cone " << i;
    }
}

TEST(BentConeSsdo, PlaneFacingTheCameraIsOpenAndItsConesAreCutByThePlane)
{
    // Nothing occludes: A = 1 exactly, bent normal = normal (antipodal sample pairs cancel),
    // aperture pi/2, and each direction cone's visibility is the fraction of it above the plane
    // (numerical integration; tolerance 2e-5 sr / |C| from the cap test).
    const test::TestGBuffer g = makeFacingPlane(13, 7);
    for (int samples : {1, 16, 33}) {
        plugin::OcclusionOutput out;
        makeTechnique({{"samples", std::int64_t(samples)}, {"radius", 2.0}})
            ->compute(makeInput(g, 3), out);
        checkFacingPlane(out, g.view, 2e-5f / (2.0f * kPi / 8.0f));
    }
}

//! Azimuth-averaged expectation of this estimator at a floor point at distance d from a wall
//! (radius r, bias b, wall depth Zw): sample k (disk radius rho, height z, distance u) reaches
//! behind the wall by r u rho cos(psi) - d, and counts as occluded when that exceeds
//! b * (Zw + behind) [bias relative to the sample depth], i.e. when
//! r u rho cos(psi) > d' = d + b Zw / (1 - b). Averaged over psi: occluded a fraction
//! acos(tau) / pi of the time, tau = d' / (r u rho) when tau < 1. The unoccluded directions add
//! z (1 - acos(tau)/pi) along the normal and rho sqrt(1 - tau^2) / pi away from the wall.
struct WallExpectation {
    double ambient = 0.0;
    double tilt = 0.0; //!< radians from the normal, away from the wall
};

WallExpectation expectWallEstimate(const std::vector<glm::vec4>& pattern, double d, double r,
                                   double bias, double wallDepth)
{
    const double dEffective = d + bias * wallDepth / (1.0 - bias);
    double visible = 0.0, along = 0.0, away = 0.0;
    for (const glm::vec4& s : pattern) {
        const double rho = std::hypot(double(s.x), double(s.y));
        const double reach = r * s.w * rho;
        double occludedFraction = 0.0, awayMean = 0.0;
        if (reach > dEffective) {
            const double tau = dEffective / reach;
            occludedFraction = std::acos(tau) / kPiD;
            awayMean = rho * std::sqrt(1.0 - tau * tau) / kPiD;
        }
        visible += 1.0 - occludedFraction;
        along += s.z * (1.0 - occludedFraction);
        away += awayMean;
    }
    return {visible / double(pattern.size()), std::atan2(away, along)};
}

TEST(BentConeSsdo, FloorInFrontOfAWallMatchesTheClosedFormOfTheEstimator)
{
    // Crease scene (wall facing the camera at depth 4, eye 1.5 above the floor). Each floor row
    // is at one distance d from the wall. Averaged over 4 pixels of a row (4 cell rotations) and
    // 1024 frames (golden-ratio turns), the estimate must match the azimuth average above.
    // Tolerance 0.006 on A and 0.01 rad on the tilt: the turns are a Kronecker sequence whose
    // discrepancy for 1024 points is about log(1024) / 1024 = 0.007, a bound on each sample's
    // indicator average (the errors of different samples partly cancel); besides, samples within
    // a pixel of the wall's bottom edge on screen, or below the tangent-plane threshold near the
    // crease, may be classified otherwise than the plane geometry says (1-3% of r, and few of
    // those flip). Measured: about 1e-4 for both.
    const test::CreaseScene scene;
    const int w = 384, h = 384;
    const test::TestGBuffer g = test::renderGBuffer(scene.camera(), w, h, scene.trace());
    for (int samples : {16, 64}) {
        Settings settings;
        settings.radius = 1.0f;
        settings.sampleCount = samples;
        const std::vector<glm::vec4> pattern = makeSamplePattern(samples);
        const std::vector<glm::vec4> apertures = makeApertureTable(samples);
        const int x0 = w / 2;
        std::vector<int> rows; // the floor row nearest the wall, then every 9th
        for (int y = h / 2; y < h; ++y) {
            if (g.normal.at(x0, y).y < 0.5f)
                continue; // the wall
            if (rows.empty() || y - rows.back() >= 9)
                rows.push_back(y);
        }
        ASSERT_GE(rows.size(), 5u);
        double worstAmbient = 0.0, worstTilt = 0.0;
        for (int y : rows) {
            const double d = scene.wallDistance - double(g.depth.at(x0, y));
            double ambient = 0.0;
            glm::dvec4 sh(0.0);
            const int frames = 1024;
            for (int f = 0; f < frames; ++f) {
                const FrameSetup frame =
                    makeFrameSetup(settings, pattern, apertures, makeInput(g, f));
                for (int x = x0; x < x0 + 4; ++x) {
                    const PixelResult r = shadePixel(frame, g.depth, g.normal, x, y);
                    ambient += r.ambient;
                    sh += glm::dvec4(r.sh);
                }
            }
            ambient /= 4.0 * frames;
            const double tilt = std::atan2(sh.z, sh.y); // L1 = (y, z, x): toward the camera
            const WallExpectation expected = expectWallEstimate(
                pattern, d, settings.radius, settings.depthBias, scene.wallDistance);
            EXPECT_NEAR(ambient, expected.ambient, 0.006) << "row " << y << " d " << d;
            EXPECT_NEAR(tilt, expected.tilt, 0.01) << "row " << y << " d " << d;
            worstAmbient = std::max(worstAmbient, std::abs(ambient - expected.ambient));
            worstTilt = std::max(worstTilt, std::abs(tilt - expected.tilt));
        }
        RecordProperty("worst_ambient_" + std::to_string(samples), std::to_string(worstAmbient));
        RecordProperty("worst_tilt_" + std::to_string(samples), std::to_string(worstTilt));
        const double nearestD = scene.wallDistance - double(g.depth.at(x0, rows.front()));
        // Within one floor row of the base: at the base the floor's depth changes by
        // Zw^2 / eye * (pi/3 / 384) = 0.029 per row.
        EXPECT_LT(nearestD, 0.03);
        // At the base of the wall (d -> 0, no bias) the estimate is the crease's: A = 1/2 and a
        // tilt of atan(2/pi), exactly for an even pattern (see the math test).
        const WallExpectation base = expectWallEstimate(pattern, 0.0, 1.0, 0.0, 4.0);
        EXPECT_NEAR(base.ambient, 0.5, 1e-12);
        EXPECT_NEAR(base.tilt, std::atan(2.0 / kPiD), 2e-6);
    }
}

TEST(BentConeSsdo, ContinuousLimitOfTheWallExpectationIsTheBallIntegral)
{
    // For N -> infinity the azimuth-averaged occlusion at t = d / r (no bias) is
    // Int_t^1 3u^2 F(t/u) du with F(x) = (acos x - x sqrt(1 - x^2)) / pi, the cosine-weighted
    // share of directions reaching the wall from distance u (a disk segment). It is below the
    // ray-traced ground truth's occlusion F(t) within r, which counts every direction reaching
    // the wall before r: point samples miss occluders beyond their own distance. With 256
    // samples the pattern integrates it within 2e-3 (stratified distances, 128 elevations).
    const std::vector<glm::vec4> pattern = makeSamplePattern(256);
    for (double t : {0.0, 0.05, 0.2, 0.5, 0.8}) {
        double integral = 0.0;
        const int steps = 100000;
        for (int i = 0; i < steps; ++i) {
            const double u = t + (1.0 - t) * (i + 0.5) / steps;
            const double x = t / u;
            integral += 3.0 * u * u * (std::acos(x) - x * std::sqrt(1.0 - x * x)) / kPiD *
                        (1.0 - t) / steps;
        }
        const WallExpectation expected = expectWallEstimate(pattern, t, 1.0, 0.0, 1.0);
        EXPECT_NEAR(1.0 - expected.ambient, integral, 2e-3) << "t " << t;
        const double rayTraced = (std::acos(t) - t * std::sqrt(1.0 - t * t)) / kPiD;
        EXPECT_LE(integral, rayTraced + 1e-9);
    }
}

TEST(BentConeSsdo, AmbientDoesNotGrowWithTheRadius)
{
    // Crease scene, floor pixels: a sample's reach behind the wall, r u rho cos(psi) - d, grows
    // with r and the range check never rejects it (the wall faces the camera, so the depth
    // difference is the reach, < r): every floor pixel's occluded set only grows (centre
    // columns, where samples stay on screen). Not so on the wall: a sample below the floor is
    // in front of the floor by z delta / (eye + delta) in depth, up to ~2.7 delta here, so the
    // range check drops the deeper ones as r grows.
    const test::CreaseScene scene;
    const test::TestGBuffer g = test::renderGBuffer(scene.camera(), 192, 128, scene.trace());
    Image<float> previous(192, 128, 1.0f);
    for (double radius : {0.125, 0.25, 0.5, 1.0}) {
        plugin::OcclusionOutput out;
        makeTechnique({{"radius", radius}})->compute(makeInput(g, 2), out);
        for (int y = 0; y < 128; ++y) {
            for (int x = 64; x < 128; ++x) {
                if (g.normal.at(x, y).y < 0.5f)
                    continue; // wall pixels: see above
                ASSERT_LE(out.ambient.at(x, y), previous.at(x, y))
                    << "radius " << radius << " pixel " << x << "," << y;
            }
        }
        previous = out.ambient;
    }
    // Box scene: the mean over the image does not grow either (a statistical statement: single
    // samples may pass beyond a thin occluder as the radius grows).
    const test::TestGBuffer box =
        test::renderGBuffer(test::makeBoxSceneCamera(), 160, 90, test::makeBoxSceneTrace());
    double previousMean = 1.0;
    for (double radius : {0.1, 0.2, 0.4, 0.8}) {
        plugin::OcclusionOutput out;
        makeTechnique({{"radius", radius}})->compute(makeInput(box, 0), out);
        double mean = 0.0;
        for (float a : out.ambient.pixels)
            mean += a / double(out.ambient.pixels.size());
        EXPECT_LT(mean, previousMean) << "radius " << radius;
        previousMean = mean;
    }
}

} // namespace
} // namespace rtlab::bentcone_ssdo
