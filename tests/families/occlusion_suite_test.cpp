// The occlusion family suite: every registered occlusion technique, on its plain C++ path and on
// Vulkan (lavapipe here), through the same stability checks. A new occlusion plugin inherits them.
//
// Each case is a synthetic G-buffer built analytically (ScreenProjection gives view positions),
// so no scene or rasteriser is involved: floors, walls, depth steps, grazing planes, extreme
// depths, degenerate normals, tiny and odd image sizes, and extreme radii. The checks: every
// pixel's ambient is finite and in [0, 1], bent normals are finite (unit where there is a
// surface), apertures are finite and in [0, pi/2], and more radius never brightens the image.

#include "families/occlusion/occlusion.h"
#include "gpu/context.h"
#include "plugin/screen_space.h"
#include "render/image_transfer.h"
#include "scene/camera.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>

using namespace rtlab;

namespace {

struct SyntheticGBuffer {
    Image<float> depth;
    Image<glm::vec3> normal;
    glm::mat4 projection{1.0f};
    glm::mat4 view{1.0f};
};

// A G-buffer whose pixel (x, y) sees the surface `hit(ray) -> (distance along ray, normal)`; the
// ray leaves the camera at the origin through the pixel's sample. Distance <= 0 or inf: sky.
SyntheticGBuffer makeGBuffer(int w, int h, float fovDegrees,
                             const std::function<std::pair<float, glm::vec3>(const glm::vec3&)>& hit)
{
    scene::Camera camera;
    camera.position = {0, 0, 0};
    camera.target = {0, 0, -1};
    camera.verticalFovDegrees = fovDegrees;
    camera.nearPlane = 1e-3f;
    camera.farPlane = 1e6f;
    SyntheticGBuffer g;
    g.projection = camera.projectionMatrix(float(w) / float(h), glm::vec2(0.0f), {w, h});
    g.view = camera.viewMatrix();
    g.depth = Image<float>(w, h, std::numeric_limits<float>::infinity());
    g.normal = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    const auto sp = plugin::ScreenProjection::fromMatrix(g.projection, w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::vec3 dir = glm::normalize(sp.toView({x + 0.5f, y + 0.5f}, 1.0f));
            const auto [t, n] = hit(dir);
            if (t > 0.0f && std::isfinite(t)) {
                g.depth.at(x, y) = -(dir * t).z;
                g.normal.at(x, y) = n;
            }
        }
    return g;
}

// The view-space plane through point p with normal n (facing the camera side).
std::pair<float, glm::vec3> hitPlane(const glm::vec3& dir, const glm::vec3& p, glm::vec3 n)
{
    const float d = glm::dot(dir, n);
    if (std::abs(d) < 1e-8f)
        return {-1.0f, n};
    const float t = glm::dot(p, n) / d;
    if (d > 0.0f)
        n = -n;
    return {t, n};
}

struct Case {
    const char* name;
    std::function<SyntheticGBuffer()> make;
};

std::vector<Case> makeCases()
{
    // A floor 1 unit below the camera and a wall 4 units ahead: a crease across the image.
    auto floorAndWall = [](int w, int h) {
        return makeGBuffer(w, h, 60.0f, [](const glm::vec3& d) {
            auto a = hitPlane(d, {0, -1, 0}, {0, 1, 0});
            auto b = hitPlane(d, {0, 0, -4}, {0, 0, 1});
            if (a.first <= 0) return b;
            if (b.first <= 0) return a;
            return a.first < b.first ? a : b;
        });
    };
    return {
        {"floor_and_wall_64x48", [=] { return floorAndWall(64, 48); }},
        {"odd_size_17x9", [=] { return floorAndWall(17, 9); }},
        {"one_pixel", [=] { return floorAndWall(1, 1); }},
        {"depth_discontinuity",
         [] {
             // A near box face (depth 1) in front of a far wall (depth 50).
             return makeGBuffer(48, 32, 60.0f, [](const glm::vec3& d) {
                 if (std::abs(d.x / -d.z) < 0.2f && std::abs(d.y / -d.z) < 0.2f)
                     return hitPlane(d, {0, 0, -1}, {0, 0, 1});
                 return hitPlane(d, {0, 0, -50}, {0, 0, 1});
             });
         }},
        {"grazing_plane",
         [] {
             // A plane seen almost edge-on: normal nearly perpendicular to the view rays.
             const glm::vec3 n = glm::normalize(glm::vec3(0, 1, 0.02f));
             return makeGBuffer(40, 30, 60.0f, [=](const glm::vec3& d) { return hitPlane(d, {0, -0.05f, 0}, n); });
         }},
        {"near_plane_extreme",
         [] { return makeGBuffer(32, 24, 60.0f, [](const glm::vec3& d) { return hitPlane(d, {0, 0, -1e-3f}, {0, 0, 1}); }); }},
        {"far_plane_extreme",
         [] {
             return makeGBuffer(32, 24, 60.0f, [](const glm::vec3& d) {
                 return hitPlane(d, {0, -1e4f, -1e5f}, glm::normalize(glm::vec3(0, 1, 1)));
             });
         }},
        {"zero_length_normals",
         [=] {
             auto g = floorAndWall(32, 24);
             for (std::size_t i = 0; i < g.normal.pixels.size(); i += 3)
                 g.normal.pixels[i] = glm::vec3(0.0f);
             return g;
         }},
        {"all_sky", [] { return makeGBuffer(16, 12, 60.0f, [](const glm::vec3&) { return std::pair{-1.0f, glm::vec3(0)}; }); }},
    };
}

void expectValid(const plugin::OcclusionOutput& out, const SyntheticGBuffer& g, const std::string& what)
{
    ASSERT_EQ(out.ambient.width, g.depth.width) << what;
    ASSERT_EQ(out.ambient.height, g.depth.height) << what;
    for (std::size_t i = 0; i < out.ambient.pixels.size(); ++i) {
        const float a = out.ambient.pixels[i];
        ASSERT_TRUE(std::isfinite(a) && a >= 0.0f && a <= 1.0f) << what << ": ambient " << a << " at pixel " << i;
    }
    if (out.bentNormal.size() == out.ambient.size())
        for (std::size_t i = 0; i < out.bentNormal.pixels.size(); ++i) {
            const glm::vec3 b = out.bentNormal.pixels[i];
            ASSERT_TRUE(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z)) << what << ": bent at " << i;
            const bool surface = std::isfinite(g.depth.pixels[i]) && glm::dot(g.normal.pixels[i], g.normal.pixels[i]) > 0;
            if (surface) {
                ASSERT_NEAR(glm::length(b), 1.0f, 1e-3f) << what << ": bent normal not unit at " << i;
            }
        }
    if (out.coneAperture.size() == out.ambient.size())
        for (std::size_t i = 0; i < out.coneAperture.pixels.size(); ++i) {
            const float c = out.coneAperture.pixels[i];
            ASSERT_TRUE(std::isfinite(c) && c >= 0.0f && c <= glm::half_pi<float>() + 1e-5f)
                << what << ": aperture " << c << " at " << i;
        }
    for (const auto& v : out.coneVisibility)
        for (float x : v.pixels)
            ASSERT_TRUE(std::isfinite(x) && x >= 0.0f && x <= 1.0f) << what << ": cone visibility " << x;
}

class OcclusionSuite : public testing::TestWithParam<const plugin::TechniqueEntry*> {
protected:
    std::unique_ptr<plugin::Technique> make(double radius) const
    {
        config::ParamSet p = config::ParamSet::defaultsOf(GetParam()->schema);
        if (GetParam()->schema.find("radius"))
            p.set("radius", radius);
        return GetParam()->create(p);
    }
    static gpu::Context& context()
    {
        static gpu::Context ctx(gpu::ContextOptions{.enableValidation = true, .echoValidationMessages = true});
        return ctx;
    }
};

void run(plugin::Technique& t, const SyntheticGBuffer& g, gpu::Context* gpu, plugin::OcclusionOutput& out)
{
    plugin::OcclusionInput in;
    in.linearDepth = &g.depth;
    in.normal = &g.normal;
    in.projection = g.projection;
    in.view = g.view;
    in.gpu = gpu;
    dynamic_cast<plugin::OcclusionTechnique&>(t).compute(in, out);
}

} // namespace

TEST_P(OcclusionSuite, FiniteAndInRangeOnEveryCaseCpuAndGpu)
{
    for (const auto& c : makeCases()) {
        const SyntheticGBuffer g = c.make();
        for (double radius : {0.0, 0.5, 1e6}) {
            for (bool onGpu : {false, true}) {
                auto t = make(radius);
                plugin::OcclusionOutput out;
                run(*t, g, onGpu ? &context() : nullptr, out);
                expectValid(out, g, std::string(c.name) + (onGpu ? " gpu" : " cpu") + " radius " + std::to_string(radius));
            }
        }
    }
    EXPECT_EQ(context().getValidationLog()->countMessages(), 0u);
}

TEST_P(OcclusionSuite, MoreRadiusNeverBrightens)
{
    // On the floor-and-wall crease the mean ambient must not grow with the radius (a larger
    // radius only adds occluders), and radius 0 means no occluder at all: ambient 1. Per-pixel
    // monotonicity is not required of estimators that rotate samples; the image mean must hold
    // to 1e-3 (float accumulation). The radii stop at 2 (half the distance to the wall): beyond
    // that, a fixed number of samples spread over a larger radius may miss near occluders, which
    // is sampling error that the studies measure, not an instability.
    const SyntheticGBuffer g = makeCases()[0].make();
    double previous = 1.0 + 1e-3;
    for (double radius : {0.0, 0.1, 0.5, 2.0}) {
        auto t = make(radius);
        plugin::OcclusionOutput out;
        run(*t, g, nullptr, out);
        double mean = 0.0;
        for (float a : out.ambient.pixels)
            mean += a;
        mean /= double(out.ambient.size());
        EXPECT_LE(mean, previous + 1e-3) << "radius " << radius;
        if (radius == 0.0) {
            EXPECT_NEAR(mean, 1.0, 1e-3) << "radius 0 leaves nothing to occlude";
        }
        previous = mean;
    }
}

TEST_P(OcclusionSuite, AnUnoccludedPlaneIsUnoccluded)
{
    // A plane facing the camera with nothing in front: ambient 1 everywhere inside the image
    // margin, bent normal = normal. 1e-3 allows float accumulation; no estimator may invent
    // occlusion on a plane.
    const SyntheticGBuffer g =
        makeGBuffer(32, 24, 50.0f, [](const glm::vec3& d) { return hitPlane(d, {0, 0, -3}, {0, 0, 1}); });
    for (bool onGpu : {false, true}) {
        auto t = make(0.5);
        plugin::OcclusionOutput out;
        run(*t, g, onGpu ? &context() : nullptr, out);
        for (std::size_t i = 0; i < out.ambient.pixels.size(); ++i) {
            ASSERT_NEAR(out.ambient.pixels[i], 1.0f, 1e-3f) << (onGpu ? "gpu" : "cpu") << " pixel " << i;
            if (out.bentNormal.size() == out.ambient.size()) {
                ASSERT_NEAR(glm::dot(out.bentNormal.pixels[i], glm::vec3(0, 0, 1)), 1.0f, 1e-3f) << i;
            }
        }
    }
}

TEST_P(OcclusionSuite, ResultsLeftOnTheGpuReadBackToWhatAnImmediateReadBackGives)
{
    // A technique that keeps its result on the GPU (outputsOnGpu) must give, with the read-back
    // deferred, GPU images of the G-buffer's size holding exactly its CPU outputs, and readBack()
    // must return bitwise what compute() with the read-back gives. Others must refuse readBack().
    const SyntheticGBuffer g = makeCases()[0].make();
    auto t = make(0.5);
    auto& technique = dynamic_cast<plugin::OcclusionTechnique&>(*t);
    if (!technique.outputsOnGpu()) {
        plugin::OcclusionOutput out;
        EXPECT_THROW(technique.readBack(out), Error);
        return;
    }
    plugin::OcclusionOutput immediate, deferred;
    run(technique, g, &context(), immediate);
    plugin::OcclusionInput in;
    in.linearDepth = &g.depth;
    in.normal = &g.normal;
    in.projection = g.projection;
    in.view = g.view;
    in.gpu = &context();
    in.readBack = false;
    technique.compute(in, deferred);
    EXPECT_TRUE(deferred.ambient.pixels.empty()) << "nothing read back yet";
    const plugin::OcclusionGpuOutput images = deferred.gpu;
    ASSERT_TRUE(images.ambient != nullptr || images.coneVisibility[0] != nullptr);
    technique.readBack(deferred);
    EXPECT_EQ(deferred.ambient.pixels, immediate.ambient.pixels);
    EXPECT_EQ(deferred.coneAperture.pixels, immediate.coneAperture.pixels);
    EXPECT_TRUE(deferred.bentNormal.pixels == immediate.bentNormal.pixels);
    ASSERT_EQ(deferred.coneVisibility.size(), immediate.coneVisibility.size());
    for (std::size_t k = 0; k < deferred.coneVisibility.size(); ++k)
        EXPECT_EQ(deferred.coneVisibility[k].pixels, immediate.coneVisibility[k].pixels) << k;
    if (images.ambient != nullptr) {
        const Image<float> onGpu = render::downloadScalar(*images.ambient, 0);
        ASSERT_EQ(onGpu.width, g.depth.width);
        ASSERT_EQ(onGpu.height, g.depth.height);
        EXPECT_EQ(onGpu.pixels, immediate.ambient.pixels);
    }
    if (images.coneVisibility[0] != nullptr) {
        ASSERT_EQ(immediate.coneVisibility.size(), 16u);
        for (std::size_t k = 0; k < 16; ++k) {
            ASSERT_NE(images.coneVisibility[k / 4], nullptr);
            const Image<float> onGpu = render::downloadScalar(*images.coneVisibility[k / 4], int(k % 4));
            EXPECT_EQ(onGpu.pixels, immediate.coneVisibility[k].pixels) << "cone " << k;
        }
    }
}

static std::vector<const plugin::TechniqueEntry*> getOcclusionTechniques()
{
    return plugin::builtinRegistry().techniques("occlusion");
}

INSTANTIATE_TEST_SUITE_P(Registered, OcclusionSuite, testing::ValuesIn(getOcclusionTechniques()),
                         [](const auto& info) { return info.param->info.name; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(OcclusionSuite);
