// The voxel_gi family suite: every registered voxel_gi technique, at its defaults, through the
// same hostile scenes: an empty scene, a single voxel's worth of geometry, a fully solid region,
// a room 1e5 from the origin, geometry on voxel boundaries, a light inside a wall, a closed dark
// room and a white furnace. The checks: finite, non-negative irradiance everywhere, zero where a
// pixel has no surface, exactly zero in the dark room, the furnace's closed form within the
// stated tolerance, and the same bits for 1 and 2 threads. A new voxel_gi plugin inherits them.

#include "families/voxel_gi/voxel_gi.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"

#include "reference/reference.h"

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <functional>

using namespace rtlab;
using namespace rtlab::voxelgi::testing;

namespace {

struct Case {
    const char* name;
    std::function<scene::RenderScene()> make;
    scene::Camera camera;
};

scene::Camera lookAt(glm::vec3 position, glm::vec3 target)
{
    scene::Camera c;
    c.position = position;
    c.target = target;
    c.verticalFovDegrees = 70.0f;
    c.nearPlane = 1e-3f;
    c.farPlane = 1e3f;
    return c;
}

// A G-buffer seen from `camera` (Embree primary rays); all sky when the scene is empty.
scene::GBuffer makeGBuffer(const scene::RenderScene& s, const scene::Camera& camera)
{
    if (!s.indices.empty())
        return reference::castGBuffer(s, camera, 16, 12);
    scene::GBuffer g;
    g.width = 16;
    g.height = 12;
    g.camera = camera;
    g.depth = Image<float>(16, 12, INFINITY);
    g.position = Image<glm::vec3>(16, 12, glm::vec3(0.0f));
    g.normal = Image<glm::vec3>(16, 12, glm::vec3(0.0f));
    g.albedo = Image<glm::vec3>(16, 12, glm::vec3(0.0f));
    g.emission = Image<glm::vec3>(16, 12, glm::vec3(0.0f));
    g.materialId = Image<std::uint32_t>(16, 12, scene::kNoMaterial);
    return g;
}

Image<glm::vec3> runTechnique(const plugin::TechniqueEntry& entry, const scene::RenderScene& s,
                              const scene::GBuffer& g, const scene::Camera& camera)
{
    auto t = entry.create(config::ParamSet::defaultsOf(entry.schema));
    auto& gi = dynamic_cast<plugin::VoxelGiTechnique&>(*t);
    plugin::VoxelGiFrame frame;
    frame.geometry = &s;
    frame.geometryKey = s.computeContentHash();
    frame.cameraPosition = glm::dvec3(camera.position);
    gi.voxelize(frame);
    gi.injectLight(frame);
    plugin::VoxelGiInput input;
    input.gbuffer = &g;
    input.scene = &s;
    input.cameraPosition = frame.cameraPosition;
    Image<glm::vec3> e;
    gi.gather(input, e);
    return e;
}

const std::vector<Case>& getCases()
{
    static const std::vector<Case> cases = {
        {"empty", [] { return scene::RenderScene{}; }, lookAt({0, 1, 3}, {0, 0, 0})},
        {"single_voxel",
         [] {
             scene::RenderScene s;
             addBox(s, glm::vec3(-0.005f), glm::vec3(0.005f), addMaterial(s, glm::vec3(0.8f)));
             s.pointLights.push_back({glm::vec3(0.1f, 0.2f, 0.1f), glm::vec3(1.0f)});
             return s;
         },
         lookAt({0.0f, 0.02f, 0.03f}, {0, 0, 0})},
        {"solid_region",
         [] {
             scene::RenderScene s;
             addBox(s, glm::vec3(-50, -10, -50), glm::vec3(50, 0, 50),
                    addMaterial(s, glm::vec3(0.5f)));
             addBox(s, glm::vec3(-0.5f, 0.0f, -0.5f), glm::vec3(0.5f, 1.0f, 0.5f),
                    addMaterial(s, glm::vec3(0.9f, 0.2f, 0.2f)));
             s.sky.kind = scene::Sky::Kind::Constant;
             s.sky.constant = glm::vec3(1.0f);
             return s;
         },
         lookAt({2, 1.5, 2}, {0, 0.3f, 0})},
        {"far_from_origin",
         [] {
             scene::RenderScene s;
             const glm::vec3 o(1e5f, 0.0f, -1e5f);
             addRoom(s, o - 1.0f, o + 1.0f, 0.2f, addMaterial(s, glm::vec3(0.6f)));
             s.pointLights.push_back({o + glm::vec3(0.3f, 0.5f, 0.0f), glm::vec3(2.0f)});
             return s;
         },
         lookAt({1e5f, 0.2f, -1e5f + 0.8f}, {1e5f, -0.5f, -1e5f})},
        {"on_voxel_boundaries",
         [] {
             scene::RenderScene s;
             const auto m = addMaterial(s, glm::vec3(0.7f));
             addRoom(s, glm::vec3(-2.0f), glm::vec3(2.0f), 1.0f, m);
             addBox(s, glm::vec3(-1.0f, -2.0f, -1.0f), glm::vec3(0.0f, 0.0f, 0.0f), m);
             s.pointLights.push_back({glm::vec3(1.0f, 1.0f, 1.0f), glm::vec3(4.0f)});
             return s;
         },
         lookAt({1.0f, 1.0f, 1.5f}, {-0.5f, -1.0f, -0.5f})},
        {"light_inside_a_wall",
         [] {
             scene::RenderScene s;
             addRoom(s, glm::vec3(-1.0f), glm::vec3(1.0f), 0.4f, addMaterial(s, glm::vec3(0.7f)));
             s.pointLights.push_back({glm::vec3(1.2f, 0.0f, 0.0f), glm::vec3(5.0f)});
             s.pointLights.push_back({glm::vec3(0.0f, 0.5f, 0.0f), glm::vec3(1.0f)});
             return s;
         },
         lookAt({-0.5f, 0.3f, 0.6f}, {0.5f, -0.5f, -0.5f})},
    };
    return cases;
}

std::vector<const plugin::TechniqueEntry*> getTechniques()
{
    return plugin::builtinRegistry().techniques("voxel_gi");
}

void expectValid(const Image<glm::vec3>& e, const scene::GBuffer& g, const std::string& what)
{
    ASSERT_EQ(e.width, g.width) << what;
    ASSERT_EQ(e.height, g.height) << what;
    int bad = 0;
    for (int y = 0; y < g.height; ++y)
        for (int x = 0; x < g.width; ++x) {
            const glm::vec3 v = e.at(x, y);
            const bool finite = std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
            const bool nonNegative = v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f;
            const bool zeroOffSurface = g.hasSurface(x, y) || v == glm::vec3(0.0f);
            bad += (finite && nonNegative && zeroOffSurface) ? 0 : 1;
        }
    EXPECT_EQ(bad, 0) << what << ": pixels with NaN/inf, negative values, or light off the surface";
}

TEST(VoxelGiSuite, EveryTechniqueIsRegistered)
{
    EXPECT_GE(getTechniques().size(), 2u); // cascades and the path-traced baseline at least
}

TEST(VoxelGiSuite, HostileScenesGiveFiniteNonNegativeIrradiance)
{
    for (const auto* entry : getTechniques())
        for (const Case& c : getCases()) {
            const scene::RenderScene s = c.make();
            const scene::GBuffer g = makeGBuffer(s, c.camera);
            expectValid(runTechnique(*entry, s, g, c.camera), g,
                        entry->info.name + " on " + c.name);
        }
}

TEST(VoxelGiSuite, ClosedDarkRoomGivesZero)
{
    scene::RenderScene s;
    addRoom(s, glm::vec3(-1.0f), glm::vec3(1.0f), 0.3f, addMaterial(s, glm::vec3(0.9f)));
    const scene::Camera camera = lookAt({0.0f, 0.2f, 0.5f}, {0.0f, -1.0f, -0.5f});
    const scene::GBuffer g = makeGBuffer(s, camera);
    for (const auto* entry : getTechniques()) {
        const Image<glm::vec3> e = runTechnique(*entry, s, g, camera);
        for (const auto& v : e.pixels)
            EXPECT_EQ(v, glm::vec3(0.0f)) << entry->info.name;
    }
}

TEST(VoxelGiSuite, WhiteFurnaceMatchesItsClosedForm)
{
    // A closed room of emission Le = 1 and albedo a = 0.5, walls 0.5 thick: the light reflected k
    // times arrives with irradiance pi a^k, so 2 bounces give pi (a + a^2) at every point.
    // Tolerance 3.5 % on the mean over the surface pixels: a cone tracer loses up to 1 % of the
    // light at each of its three gathers (cascades stop at 99 % opacity) and 0.5 % goes to float
    // accumulation; path_traced at 4 paths per pixel over the ~190 surface pixels, and
    // adaptive_voxel_tree's probes baked with 32 paths per axis and averaged by the
    // interpolation, have standard errors of the mean well below that (measured: cascades
    // -0.7 %, path_traced -0.02 %, adaptive_voxel_tree +0.2 %).
    // A structure that declares surfacesOnly (svo, adaptive_voxel_tree_cones) keeps the walls'
    // surfaces and a few layers inside them, not their solid interior: its cones, once coarser
    // than those layers, see through the walls and out of the scene, so it must lose light, never
    // gain it, and lose less than a fifth (measured at the defaults, 64 leaves: svo -13.2 % with
    // one inner layer, adaptive_voxel_tree_cones -14.4 % with four; their own tests trace rays
    // through the leaves alone).
    scene::RenderScene s;
    addRoom(s, glm::vec3(-0.5f), glm::vec3(0.5f), 0.5f,
            addMaterial(s, glm::vec3(0.5f), glm::vec3(1.0f)));
    const scene::Camera camera = lookAt({0.0f, 0.1f, 0.3f}, {0.0f, -0.5f, -0.3f});
    const scene::GBuffer g = makeGBuffer(s, camera);
    const double expected = glm::pi<double>() * 0.75;
    for (const auto* entry : getTechniques()) {
        const Image<glm::vec3> e = runTechnique(*entry, s, g, camera);
        double sum = 0.0;
        int n = 0;
        for (int y = 0; y < g.height; ++y)
            for (int x = 0; x < g.width; ++x)
                if (g.hasSurface(x, y)) {
                    sum += e.at(x, y).x;
                    ++n;
                }
        ASSERT_GT(n, 0);
        const auto technique = entry->create(config::ParamSet::defaultsOf(entry->schema));
        const auto& gi = dynamic_cast<const plugin::VoxelGiTechnique&>(*technique);
        std::printf("furnace, %s: %+.1f %%\n", entry->info.name.c_str(), 100.0 * (sum / n / expected - 1.0));
        if (gi.definition().surfacesOnly) {
            EXPECT_LT(sum / n, 1.035 * expected) << entry->info.name;
            EXPECT_GT(sum / n, 0.8 * expected) << entry->info.name;
        } else {
            EXPECT_NEAR(sum / n, expected, 0.035 * expected) << entry->info.name;
        }
    }
}

TEST(VoxelGiSuite, DeterministicForAnyThreadCount)
{
    const Case& c = getCases()[5]; // light inside a wall: every step has work
    const scene::RenderScene s = c.make();
    const scene::GBuffer g = makeGBuffer(s, c.camera);
    for (const auto* entry : getTechniques()) {
        Image<glm::vec3> one, two;
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
            one = runTechnique(*entry, s, g, c.camera);
        }
        {
            tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
            two = runTechnique(*entry, s, g, c.camera);
        }
        EXPECT_EQ(one.pixels, two.pixels) << entry->info.name;
    }
}

} // namespace
