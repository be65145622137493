// Unit tests of occlusion/gtao on the C++ path: registration, the closed forms, the flat plane,
// the wall and corner checks against the analytic answer with tolerances derived from the slice
// and step discretisation (gtao_test_oracle.h), monotonicity and determinism. GPU tests:
// gtao_gpu_test.cpp. The family suite in tests/ also runs every occlusion technique.

#include "gtao.h"
#include "gtao_math.h"
#include "gtao_test_oracle.h"
#include "gtao_test_scene.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <vector>

// Defined by RTLAB_REGISTER_TECHNIQUE at the bottom of gtao.cpp.
void rtlabRegisterTechnique_occlusion_gtao(rtlab::plugin::Registry& registry);

namespace rtlab::occlusion::test {
namespace {

using Overrides = std::map<std::string, config::ParamValue>;

config::ParamSet makeParams(const Overrides& overrides)
{
    config::ParamSet params = config::ParamSet::defaultsOf(Gtao::declareParams());
    for (const auto& [name, value] : overrides)
        params.set(name, value);
    return params;
}

plugin::OcclusionOutput computeCpu(const Overrides& overrides, const TestGBuffer& g, int frame = 0)
{
    Gtao gtao(makeParams(overrides));
    plugin::OcclusionOutput out;
    gtao.compute(g.makeInput(frame), out);
    return out;
}

TEST(Gtao, RegistersWithItsParametersAndDefinition)
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    rtlabRegisterTechnique_occlusion_gtao(registry);
    const auto* entry = registry.findTechnique("occlusion", "gtao");
    ASSERT_NE(entry, nullptr);
    EXPECT_FALSE(entry->info.reference.empty());
    const config::ParamSet defaults = config::ParamSet::defaultsOf(entry->schema);
    const auto technique = entry->create(defaults);
    EXPECT_EQ(technique->effectiveParams(), defaults);
    auto& gtao = dynamic_cast<plugin::OcclusionTechnique&>(*technique);
    EXPECT_EQ(gtao.definition().quantity, plugin::OcclusionQuantity::CosineAo);
    EXPECT_EQ(gtao.definition().radius, 1.0);

    const Overrides changed = {{"radius", 0.25},
                               {"slices", std::int64_t(7)},
                               {"steps", std::int64_t(3)},
                               {"max_pixel_radius", 33.0},
                               {"falloff_fraction", 0.5},
                               {"normalize", false},
                               {"temporal_rotation", false},
                               {"search_extent", std::string("depth")}};
    Gtao custom(makeParams(changed));
    EXPECT_EQ(custom.effectiveParams(), makeParams(changed));
    EXPECT_EQ(custom.definition().radius, 0.25);
    EXPECT_THROW(Gtao(makeParams({{"slices", std::int64_t(33)}})), std::invalid_argument);
    EXPECT_THROW(Gtao(makeParams({{"radius", -1.0}})), std::invalid_argument);
    EXPECT_THROW(Gtao(makeParams({{"search_extent", std::string("cone")}})), std::invalid_argument);
}

// The closed forms of gtao_math.h against Simpson quadrature of their integrands (1e-6: float
// evaluation of terms of size <= 2), and the polynomials against the standard library (their
// approximation errors, 2e-8 and 6e-8, plus rounding: 3e-7 for cos/sin in [-1, 1], 5e-7 = 2 ulp
// for acos in [0, pi]).
TEST(Gtao, ClosedFormsMatchTheirIntegrals)
{
    const auto integrate = [](const std::function<double(double)>& f, double a, double b) {
        const int n = 2000;
        const double h = (b - a) / n;
        double sum = f(a) + f(b);
        for (int i = 1; i < n; ++i)
            sum += f(a + i * h) * (i % 2 == 1 ? 4.0 : 2.0);
        return sum * h / 3.0;
    };
    const double half = 0.5 * std::numbers::pi;
    for (double gamma = -1.5; gamma <= 1.5; gamma += 0.25) {
        for (double h = gamma - half; h <= gamma + half; h += 0.2) {
            const auto w = [&](double t) { return std::cos(t - gamma) * std::abs(std::sin(t)); };
            // The side's arc is [0, h] for h > 0 and [h, 0] for h < 0.
            const double lo = std::min(0.0, h), hi = std::max(0.0, h);
            const double a = integrate(w, lo, hi);
            const double bs = integrate([&](double t) { return w(t) * std::sin(t); }, lo, hi);
            const double bv = integrate([&](double t) { return w(t) * std::cos(t); }, lo, hi);
            EXPECT_NEAR(gtao::integrateArc(float(h), float(gamma)), a, 1e-6) << h << " " << gamma;
            EXPECT_NEAR(gtao::integrateBentS(float(h), float(gamma)), bs, 1e-6);
            EXPECT_NEAR(gtao::integrateBentV(float(h), float(gamma)), bv, 1e-6);
        }
        EXPECT_NEAR(gtao::integrateFullSlice(float(gamma)),
                    gtao::integrateArc(float(gamma - half), float(gamma)) +
                        gtao::integrateArc(float(gamma + half), float(gamma)),
                    1e-6);
    }
    for (double x = -1.0; x <= 1.0; x += 1.0 / 1024.0)
        EXPECT_NEAR(gtao::computeAcos(float(x)), std::acos(x), 5e-7) << x; // 2 ulp at pi
    for (double phi = 0.0; phi <= std::numbers::pi; phi += 1.0 / 512.0) {
        const glm::vec2 cs = gtao::computeCosSin(float(phi));
        EXPECT_NEAR(cs.x, std::cos(phi), 3e-7) << phi;
        EXPECT_NEAR(cs.y, std::sin(phi), 3e-7) << phi;
    }
}

// A plane facing the camera seen off-centre (normals up to 40 degrees from the view vectors):
// nothing occludes, so ambient is 1 up to float rounding of the closed forms (1e-5), the bent
// normal is the normal and sin^2(aperture) = 1. With normalize = false (the paper's plain mean)
// the image centre is still exactly 1, but off-centre pixels with few slices are not: each
// slice's unoccluded value |n_p| (cos(gamma) + gamma sin(gamma)) only averages to 1 over all
// slice angles.
TEST(Gtao, FlatPlaneFacingTheCameraIsUnoccluded)
{
    AnalyticScene scene;
    scene.floorY = -4.0f;
    scene::Camera camera;
    camera.position = {0.0f, 0.0f, 0.0f};
    camera.target = {0.0f, -1.0f, 0.0f};
    camera.up = {0.0f, 0.0f, -1.0f};
    camera.verticalFovDegrees = 70.0f;
    const TestGBuffer g = renderScene(scene, camera, 64, 48, glm::vec2(0.3f, -0.2f));
    for (const Overrides& o :
         {Overrides{}, Overrides{{"slices", std::int64_t(1)}, {"radius", 100.0}},
          Overrides{{"slices", std::int64_t(7)}, {"search_extent", std::string("depth")}},
          Overrides{{"steps", std::int64_t(64)}, {"falloff_fraction", 0.5}}}) {
        for (int frame : {0, 5}) {
            const plugin::OcclusionOutput out = computeCpu(o, g, frame);
            for (int y = 0; y < 48; ++y) {
                for (int x = 0; x < 64; ++x) {
                    ASSERT_NEAR(out.ambient.at(x, y), 1.0f, 1e-5f) << x << ", " << y;
                    ASSERT_LE(glm::length(out.bentNormal.at(x, y) - g.normal.at(x, y)), 1e-5f);
                    const float s = std::sin(out.coneAperture.at(x, y));
                    ASSERT_NEAR(s * s, 1.0f, 1e-5f);
                }
            }
        }
    }
    const plugin::OcclusionOutput plain = computeCpu({{"normalize", false}}, g);
    double worst = 0.0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x)
            worst = std::max(worst, 1.0 - double(plain.ambient.at(x, y)));
    EXPECT_GT(worst, 1e-3) << "off-centre slices do not integrate to 1 individually";
}

//! A floor in front of an infinite wall x = 2, seen from a camera that looks toward the wall.
struct WallSetup {
    scene::Camera camera;
    TestGBuffer g;

    WallSetup()
    {
        AnalyticScene scene;
        scene.wallX = 2.0f;
        camera.position = {-1.5f, 1.5f, 0.3f};
        camera.target = {1.5f, 0.0f, 0.0f};
        camera.verticalFovDegrees = 60.0f;
        g = renderScene(scene, camera, 160, 120);
    }
    //! Distance of floor pixel (x, y) from the wall, or NaN for a wall pixel.
    double getDistance(int x, int y) const
    {
        const glm::dvec3 p = g.worldPosition.at(x, y);
        return std::abs(p.y) < 1e-9 ? 2.0 - p.x : std::numeric_limits<double>::quiet_NaN();
    }
    //! The floor pixel of column x whose distance from the wall is closest to `d`.
    int findRow(int x, double d) const
    {
        int best = -1;
        for (int y = 0; y < g.depth.height; ++y) {
            const double e = getDistance(x, y);
            if (std::isfinite(e) &&
                (best < 0 || std::abs(e - d) < std::abs(getDistance(x, best) - d)))
                best = y;
        }
        return best;
    }
};

//! Cosine AO on a floor at distance d from an infinite wall, occluders within r.
double computeWallAo(double d, double r)
{
    const double t = std::min(1.0, d / r);
    return 1.0 - (std::acos(t) - t * std::sqrt(1.0 - t * t)) / std::numbers::pi;
}

// Floor points at distance d from the wall with radius r: 32 slices and 64 steps approach
// 1 - (acos t - t sqrt(1 - t^2)) / pi, t = min(1, d / r). The tolerance of each pixel is derived,
// not chosen: sliceError + stepError from the oracle (worst 32-slice rule over all rotations, and
// the horizon angle one step plus one pixel can miss) + 1e-4 for float rounding. The oracle's own
// fine quadrature must match the closed form to 1e-4 (it checks the slice formulation itself).
TEST(Gtao, FloorInFrontOfAWallMatchesTheClosedForm)
{
    const WallSetup wall;
    const int x = 80;
    for (const double r : {0.5, 1.0}) {
        const plugin::OcclusionOutput out = computeCpu({{"radius", r},
                                                        {"slices", std::int64_t(32)},
                                                        {"steps", std::int64_t(64)},
                                                        {"max_pixel_radius", 4096.0}},
                                                       wall.g);
        WallOracleSettings settings;
        settings.radius = r;
        const WallOracle oracle(wall.g, wall.camera, settings);
        settings.clipToScreen = true;
        const WallOracle clipped(wall.g, wall.camera, settings);
        for (const double fraction : {0.15, 0.3, 0.5, 0.7, 0.9, 1.3}) {
            const int y = wall.findRow(x, fraction * r);
            const double d = wall.getDistance(x, y);
            const double exact = computeWallAo(d, r);
            const WallOracleResult ref = oracle.evaluate(x, y);
            SCOPED_TRACE("r = " + std::to_string(r) + ", d = " + std::to_string(d) + ", pixel " +
                         std::to_string(x) + ", " + std::to_string(y));
            ASSERT_NEAR(ref.ambient, exact, 1e-4) << "oracle";
            ASSERT_NEAR(clipped.evaluate(x, y).ambient, ref.ambient, 1e-9)
                << "the occluders within the radius must be on screen";
            const double tolerance = ref.sliceError + ref.stepError + 1e-4;
            EXPECT_NEAR(out.ambient.at(x, y), exact, tolerance)
                << "sliceError " << ref.sliceError << ", stepError " << ref.stepError;
            EXPECT_LT(tolerance, 0.05) << "the check must stay meaningful";
            // The bent normal: the oracle's direction (view space) within the slice-rule error
            // plus the step error: a side's bent integrand has length <= 1, so horizons off by
            // dh move a slice's vector by <= 2 |n_p| dh (two sides), the mean vector B by as
            // much, and its direction by at most asin(2 dh / |B|).
            const glm::dvec3 b =
                glm::normalize(glm::dmat3(glm::dmat4(wall.g.view)) * ref.bentNormal);
            const double angle =
                std::acos(std::clamp(glm::dot(glm::dvec3(out.bentNormal.at(x, y)), b), -1.0, 1.0));
            const double bentStep =
                std::asin(std::min(1.0, 2.0 * ref.horizonStepError / ref.bentLength));
            EXPECT_LE(angle, ref.bentSliceError + bentStep + 1e-4);
            const float s = std::sin(out.coneAperture.at(x, y));
            EXPECT_NEAR(s * s, out.ambient.at(x, y), 1e-5f);
        }
    }
}

// The 90-degree corner: with unbounded radius the cosine AO of a floor point next to an infinite
// wall is 1/2 at any distance. The image shows the wall only up to its edges, so the reference
// is the oracle with occluders clipped to the image; it tends to 1/2 as d -> 0 (the part of the
// wall outside the image subtends less and less of the hemisphere), and GTAO follows it within
// the derived tolerance.
TEST(Gtao, CornerLimitIsOneHalfWithUnboundedRadius)
{
    const WallSetup wall;
    const double inf = std::numeric_limits<double>::infinity();
    const double maxPixelRadius = 200.0; // the image diagonal
    const plugin::OcclusionOutput out = computeCpu({{"radius", inf},
                                                    {"slices", std::int64_t(32)},
                                                    {"steps", std::int64_t(64)},
                                                    {"max_pixel_radius", maxPixelRadius}},
                                                   wall.g);
    WallOracleSettings settings;
    settings.radius = inf;
    settings.clipToScreen = true;
    settings.maxPixelRadius = maxPixelRadius;
    const WallOracle oracle(wall.g, wall.camera, settings);
    const int x = 80;
    const int nearest = wall.findRow(x, 0.0); // the floor pixel next to the wall
    double previous = 1.0;
    for (const int rowsAway : {16, 8, 4, 2, 1, 0}) {
        const int y = nearest + rowsAway; // rows below are nearer the camera, farther from the wall
        const WallOracleResult ref = oracle.evaluate(x, y);
        SCOPED_TRACE("d = " + std::to_string(wall.getDistance(x, y)));
        EXPECT_LT(ref.ambient, previous);
        EXPECT_GE(ref.ambient, 0.5 - 1e-9);
        previous = ref.ambient;
        EXPECT_NEAR(out.ambient.at(x, y), ref.ambient, ref.sliceError + ref.stepError + 1e-4)
            << "sliceError " << ref.sliceError << ", stepError " << ref.stepError;
    }
    EXPECT_LT(previous - 0.5, 0.02) << "the reference reaches the corner limit";
}

//! A floor with two boxes and sky, seen at an angle.
TestGBuffer renderBoxes(int width, int height)
{
    AnalyticScene scene;
    scene.boxes = {{{-0.6f, 0.0f, -0.5f}, {0.2f, 0.7f, 0.3f}},
                   {{0.5f, 0.0f, -1.2f}, {0.9f, 1.4f, -0.8f}}};
    scene::Camera camera;
    camera.position = {1.6f, 1.5f, 2.6f};
    camera.target = {0.0f, 0.3f, -0.2f};
    camera.verticalFovDegrees = 50.0f;
    return renderScene(scene, camera, width, height, glm::vec2(0.23f, -0.31f));
}

double computeMean(const Image<float>& image)
{
    double sum = 0.0;
    for (float v : image.pixels)
        sum += v;
    return sum / double(image.pixels.size());
}

//! Near the hemisphere boundary a(h) is flat, so a horizon that moves by a rounding error changes
//! the float value of the closed forms by an ulp or two either way (~1e-7 at 1).
constexpr float kFlatRounding = 1e-6f;

// More radius, more occluders: ambient does not grow (up to kFlatRounding). Per pixel where the
// sample positions do not move with the radius (search_extent = depth with the extent clamped to
// max_pixel_radius for every radius, so each larger radius sees a superset of samples); in the
// default mode the positions scale with the radius, so only the mean is compared. A falloff only
// raises the horizon's floor, so ambient does not drop either.
TEST(Gtao, MoreRadiusNeverIncreasesAmbient)
{
    const TestGBuffer g = renderBoxes(96, 64);
    const double inf = std::numeric_limits<double>::infinity();
    const Overrides fixed = {{"search_extent", std::string("depth")}, {"max_pixel_radius", 24.0}};
    // Pixels whose extent is clamped already for the smallest radius.
    const auto projection = plugin::ScreenProjection::fromMatrix(g.projection, 96, 64);
    std::vector<std::size_t> clamped;
    for (std::size_t i = 0; i < g.depth.pixels.size(); ++i)
        if (projection.toPixelLength(2.0f, g.depth.pixels[i]) >= 24.0f)
            clamped.push_back(i);
    ASSERT_GT(clamped.size(), g.depth.pixels.size() / 2);
    plugin::OcclusionOutput previous;
    double previousMean = 2.0;
    for (const double r : {2.0, 5.0, 20.0, 1e6, inf}) {
        Overrides o = fixed;
        o["radius"] = r;
        const plugin::OcclusionOutput out = computeCpu(o, g);
        if (!previous.ambient.pixels.empty()) {
            for (const std::size_t i : clamped)
                ASSERT_LE(out.ambient.pixels[i], previous.ambient.pixels[i] + kFlatRounding)
                    << "pixel " << i;
        }
        previous = out;
    }
    for (const double r : {0.05, 0.1, 0.25, 0.5, 1.0, 2.0}) {
        const double mean = computeMean(computeCpu({{"radius", r}}, g).ambient);
        EXPECT_LE(mean, previousMean) << "radius " << r;
        previousMean = mean;
    }
    EXPECT_LT(previousMean, computeMean(computeCpu({{"radius", 0.05}}, g).ambient) - 0.01);
    const plugin::OcclusionOutput hard = computeCpu({{"radius", 0.5}}, g);
    const plugin::OcclusionOutput soft =
        computeCpu({{"radius", 0.5}, {"falloff_fraction", 0.7}}, g);
    for (std::size_t i = 0; i < hard.ambient.pixels.size(); ++i)
        ASSERT_GE(soft.ambient.pixels[i], hard.ambient.pixels[i] - kFlatRounding) << "pixel " << i;
}

// No absolute length scale: depths and radius scaled by a power of two (exact in float) give the
// same output bit for bit, from depths near 3e-3 to near 4e5.
TEST(Gtao, IsScaleInvariant)
{
    const TestGBuffer g = renderBoxes(64, 40);
    const plugin::OcclusionOutput reference = computeCpu({{"radius", 0.5}}, g);
    for (const float scale : {0x1p-10f, 0x1p17f}) {
        TestGBuffer scaled = g;
        for (float& d : scaled.depth.pixels)
            d *= scale;
        const plugin::OcclusionOutput out = computeCpu({{"radius", 0.5 * double(scale)}}, scaled);
        EXPECT_EQ(out.ambient.pixels, reference.ambient.pixels) << scale;
        EXPECT_EQ(out.bentNormal.pixels, reference.bentNormal.pixels) << scale;
    }
}

// Same input, same output, bit for bit, whatever the thread count; the frame index changes the
// pattern (temporal rotation) unless temporal_rotation is off.
TEST(Gtao, IsDeterministic)
{
    const TestGBuffer g = renderBoxes(53, 31);
    const plugin::OcclusionOutput a = computeCpu({}, g, 4);
    plugin::OcclusionOutput b;
    tbb::task_arena single(1);
    single.execute([&] { b = computeCpu({}, g, 4); });
    EXPECT_EQ(a.ambient.pixels, b.ambient.pixels);
    EXPECT_EQ(a.bentNormal.pixels, b.bentNormal.pixels);
    EXPECT_EQ(a.coneAperture.pixels, b.coneAperture.pixels);
    EXPECT_NE(computeCpu({}, g, 5).ambient.pixels, a.ambient.pixels);
    EXPECT_EQ(computeCpu({{"temporal_rotation", false}}, g, 5).ambient.pixels,
              computeCpu({{"temporal_rotation", false}}, g, 0).ambient.pixels);
}

} // namespace
} // namespace rtlab::occlusion::test
