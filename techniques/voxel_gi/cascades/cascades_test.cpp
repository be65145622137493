// Unit tests of cascades: the furnace against its closed form, a dark room, the schedules
// (one pass converges to three passes), pre-combined directions equal to the three-face blend,
// update skipping, thread-count determinism and huge coordinates.

#include "cascade_volume.h"

#include "families/voxel_gi/voxel_gi.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>

void rtlabRegisterTechnique_voxel_gi_cascades(rtlab::plugin::Registry&);

using namespace rtlab;
using namespace rtlab::voxelgi;
using namespace rtlab::voxelgi::testing;

namespace {

// A G-buffer of points on a horizontal floor at height y (normal +y) over [x0, x1] x [z0, z1].
scene::GBuffer makeFloorGBuffer(int w, int h, double y, double x0, double x1, double z0, double z1,
                                glm::dvec3 offset = glm::dvec3(0.0))
{
    scene::GBuffer g;
    g.width = w;
    g.height = h;
    g.position = Image<glm::vec3>(w, h);
    g.normal = Image<glm::vec3>(w, h, glm::vec3(0, 1, 0));
    g.materialId = Image<std::uint32_t>(w, h, 0u);
    g.depth = Image<float>(w, h, 1.0f);
    for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
            g.position.at(i, j) = glm::vec3(offset + glm::dvec3(x0 + (x1 - x0) * (i + 0.5) / w, y,
                                                                 z0 + (z1 - z0) * (j + 0.5) / h));
    return g;
}

CascadeSettings furnaceSettings()
{
    CascadeSettings s;
    s.levels = 2;
    s.resolution = 32;
    s.voxelSize = 1.0 / 32.0;
    s.supersampling = 2;
    s.bounces = 2;
    s.oneLevelPerFrame = false;
    return s;
}

// The furnace: a closed room of constant emission Le and albedo a. Light reflected k times
// arrives with irradiance pi Le a^k, so the indirect irradiance with B bounces is
// pi Le (a + ... + a^B). Walls 0.3 thick are 4.8 voxels of the coarser level, so that no cone
// leaks through them (leaking through walls thin against a level's voxels is measured by the
// study's leak scene, not here).
Image<glm::vec3> runFurnace(const CascadeSettings& settings, glm::dvec3 offset, int updates = 1)
{
    scene::RenderScene s;
    const auto m = addMaterial(s, glm::vec3(0.5f), glm::vec3(1.0f));
    addRoom(s, glm::vec3(offset - 0.3), glm::vec3(offset + 0.3), 0.3f, m);
    CascadeVolume volume(settings);
    for (int frame = 0; frame < updates; ++frame) {
        volume.voxelize(s, "furnace", offset, frame, false);
        volume.injectLight(s, "lights", frame, false);
    }
    Image<glm::vec3> e;
    volume.gather(makeFloorGBuffer(4, 4, -0.3, -0.2, 0.2, -0.2, 0.2, offset), nullptr, e);
    return e;
}

// Every level of `a` holds bitwise the voxels of `b`.
void expectSameVoxels(const CascadeVolume& a, const CascadeVolume& b)
{
    ASSERT_EQ(a.getLevelCount(), b.getLevelCount());
    for (int level = 0; level < a.getLevelCount(); ++level) {
        const VoxelGrid& x = a.getLevel(level).grid;
        const VoxelGrid& y = b.getLevel(level).grid;
        ASSERT_TRUE(x.region == y.region) << level;
        EXPECT_EQ(x.flags, y.flags) << level;
        EXPECT_EQ(x.surfaceVoxels, y.surfaceVoxels) << level;
        EXPECT_EQ(x.faces, y.faces) << level;
        EXPECT_EQ(x.emission, y.emission) << level;
        EXPECT_EQ(x.normal, y.normal) << level;
    }
}

TEST(Cascades, RegistersWithItsParameters)
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    rtlabRegisterTechnique_voxel_gi_cascades(registry);
    const auto* entry = registry.findTechnique("voxel_gi", "cascades");
    ASSERT_NE(entry, nullptr);
    const auto technique = entry->create(config::ParamSet::defaultsOf(entry->schema));
    EXPECT_EQ(technique->effectiveParams().values().size(), entry->schema.specs().size());
    auto& gi = dynamic_cast<plugin::VoxelGiTechnique&>(*technique);
    EXPECT_EQ(gi.definition().bounces, 2);
}

TEST(Cascades, FurnaceMatchesItsClosedForm)
{
    // Tolerance 3.5 %: each of the three gathers on the light's way (emission to the voxels,
    // the first bounce, the pixel's cones) stops at 99 % opacity and so misses up to 1 % of the
    // light behind it; 0.5 % more for float accumulation.
    const double expected = glm::pi<double>() * 1.0 * (0.5 + 0.25);
    const Image<glm::vec3> e = runFurnace(furnaceSettings(), glm::dvec3(0.0));
    for (const auto& p : e.pixels) {
        EXPECT_NEAR(p.x, expected, 0.035 * expected);
        EXPECT_EQ(p.x, p.y);
    }
}

TEST(Cascades, VoxelRaysSeeTheFurnaceToo)
{
    // The split's reference path (rays through the same voxels and light) in the furnace: the
    // same closed form and tolerance as the cones.
    scene::RenderScene s;
    const auto m = addMaterial(s, glm::vec3(0.5f), glm::vec3(1.0f));
    addRoom(s, glm::vec3(-0.3f), glm::vec3(0.3f), 0.3f, m);
    CascadeVolume volume(furnaceSettings());
    volume.voxelize(s, "furnace", glm::dvec3(0.0), 0, false);
    volume.injectLight(s, "lights", 0, false);
    Image<glm::vec3> e;
    volume.gatherRays(makeFloorGBuffer(4, 4, -0.3, -0.2, 0.2, -0.2, 0.2), 64, e);
    const double expected = glm::pi<double>() * 0.75;
    for (const auto& p : e.pixels)
        EXPECT_NEAR(p.x, expected, 0.035 * expected);
}

TEST(Cascades, OnePassConvergesToThreePasses)
{
    CascadeSettings three = furnaceSettings();
    CascadeSettings one = three;
    one.onePass = true;
    const Image<glm::vec3> a = runFurnace(three, glm::dvec3(0.0));
    // After one update the one-pass buffers hold only direct light; after `bounces` they agree.
    const Image<glm::vec3> early = runFurnace(one, glm::dvec3(0.0), 1);
    const Image<glm::vec3> b = runFurnace(one, glm::dvec3(0.0), 2);
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        EXPECT_LT(early.pixels[i].x, 0.8f * a.pixels[i].x);
        EXPECT_NEAR(b.pixels[i].x, a.pixels[i].x, 1e-4 * a.pixels[i].x);
    }
}

TEST(Cascades, PrecombinedDirectionsEqualTheThreeFaceBlend)
{
    CascadeSettings blended = furnaceSettings();
    blended.precombine = false;
    const Image<glm::vec3> a = runFurnace(furnaceSettings(), glm::dvec3(0.0));
    const Image<glm::vec3> b = runFurnace(blended, glm::dvec3(0.0));
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
        EXPECT_NEAR(a.pixels[i].x, b.pixels[i].x, 1e-5 * a.pixels[i].x);
}

TEST(Cascades, FarFromTheOriginGivesTheSameIrradiance)
{
    const Image<glm::vec3> a = runFurnace(furnaceSettings(), glm::dvec3(0.0));
    const Image<glm::vec3> b = runFurnace(furnaceSettings(), glm::dvec3(1e5, 0.0, -1e5));
    // Float positions at 1e5 are spaced 1/128 = 1/8 voxel: the walls move by up to 1/16 voxel,
    // which changes coverage by at most one ray column of two (supersampling 2). The furnace's
    // answer does not depend on where the walls are; the tolerance is the furnace's.
    const double expected = glm::pi<double>() * 0.75;
    for (std::size_t i = 0; i < a.pixels.size(); ++i) {
        EXPECT_TRUE(std::isfinite(b.pixels[i].x));
        EXPECT_NEAR(b.pixels[i].x, expected, 0.035 * expected);
    }
}

TEST(Cascades, DarkRoomGivesZero)
{
    scene::RenderScene s;
    addRoom(s, glm::vec3(-0.3f), glm::vec3(0.3f), 0.15f, addMaterial(s, glm::vec3(0.8f)));
    CascadeVolume volume(furnaceSettings());
    volume.voxelize(s, "dark", glm::dvec3(0.0), 0, false);
    volume.injectLight(s, "none", 0, false);
    Image<glm::vec3> e;
    volume.gather(makeFloorGBuffer(4, 4, -0.3, -0.2, 0.2, -0.2, 0.2), nullptr, e);
    for (const auto& p : e.pixels)
        EXPECT_EQ(p, glm::vec3(0.0f));
}

TEST(Cascades, SkipsWhatDidNotChangeAndUpdatesOneLevelPerFrame)
{
    scene::RenderScene s;
    const auto m = addMaterial(s, glm::vec3(0.5f), glm::vec3(1.0f));
    addRoom(s, glm::vec3(-0.3f), glm::vec3(0.3f), 0.15f, m);
    CascadeSettings settings = furnaceSettings();
    settings.levels = 3;
    settings.resolution = 16;
    settings.voxelSize = 1.0 / 16.0;
    settings.oneLevelPerFrame = true;
    CascadeVolume volume(settings);
    // Frame 0: every level. Frame 1: level 0 is due; nothing changed, so nothing is done.
    EXPECT_EQ(volume.voxelize(s, "a", glm::dvec3(0.0), 0, false),
              "level 2: first voxelization; level 1: first voxelization; level 0: first voxelization");
    EXPECT_FALSE(volume.injectLight(s, "l", 0, false).empty());
    EXPECT_EQ(volume.getDueLevels(1), std::vector<int>{0});
    EXPECT_EQ(volume.getDueLevels(2), std::vector<int>{1});
    EXPECT_EQ(volume.getDueLevels(3), std::vector<int>{0});
    EXPECT_EQ(volume.getDueLevels(4), std::vector<int>{2});
    EXPECT_EQ(volume.voxelize(s, "a", glm::dvec3(0.0), 1, false), "");
    EXPECT_EQ(volume.injectLight(s, "l", 1, false), "");
    // The camera moves by two level-1 voxels: level 1, due at frame 2, scrolls.
    EXPECT_EQ(volume.voxelize(s, "a", glm::dvec3(0.25, 0.0, 0.0), 2, false),
              "level 1: scrolled by (2, 0, 0) voxels, voxelized the new slabs (512 of 4096 voxels)");
    // Culling off redoes the due level whole.
    EXPECT_EQ(volume.voxelize(s, "a", glm::dvec3(0.25, 0.0, 0.0), 3, true),
              "level 0: scrolled by (4, 0, 0) voxels");
    EXPECT_EQ(volume.voxelize(s, "a", glm::dvec3(0.25, 0.0, 0.0), 5, true), "level 0: culling off");
}

TEST(Cascades, AScrollVoxelizesOnlyTheNewSlabsAndEqualsAFullVoxelization)
{
    // A box room and a furniture box; the camera moves by 3 level-0 voxels in x and 1 in z.
    scene::RenderScene s;
    const auto m = addMaterial(s, {0.6f, 0.5f, 0.4f}, {0.1f, 0.0f, 0.0f});
    addRoom(s, glm::vec3(-0.4f), glm::vec3(0.4f), 0.1f, m);
    addBox(s, glm::vec3(-0.13f, -0.4f, -0.2f), glm::vec3(0.07f, -0.17f, 0.05f), m);
    CascadeSettings settings = furnaceSettings();
    settings.resolution = 16;
    settings.voxelSize = 1.0 / 16.0;
    CascadeVolume scrolled(settings), fresh(settings);
    const glm::dvec3 a(0.0), b(3.0 / 16.0 + 0.01, 0.0, -1.0 / 16.0);
    scrolled.voxelize(s, "k", a, 0, false);
    const std::string what = scrolled.voxelize(s, "k", b, 1, false);
    EXPECT_NE(what.find("voxelized the new slabs"), std::string::npos) << what;
    fresh.voxelize(s, "k", b, 0, false);
    expectSameVoxels(scrolled, fresh);
}

TEST(Cascades, AnEditReVoxelizesOnlyTheChangedRegionAndEqualsAFullVoxelization)
{
    // The room with a box, then the box moved (a dig removes triangles and adds others).
    const scene::RenderScene before = makeRoomWithBox(-0.2f), after = makeRoomWithBox(-0.14f);
    CascadeSettings settings = furnaceSettings();
    settings.resolution = 16;
    settings.voxelSize = 1.0 / 16.0;
    CascadeVolume edited(settings), fresh(settings);
    edited.voxelize(before, before.computeContentHash(), glm::dvec3(0.0), 0, false);
    const std::string what =
        edited.voxelize(after, after.computeContentHash(), glm::dvec3(0.0), 1, false);
    EXPECT_NE(what.find("re-voxelized the changed region"), std::string::npos) << what;
    fresh.voxelize(after, after.computeContentHash(), glm::dvec3(0.0), 0, false);
    expectSameVoxels(edited, fresh);
}

// The frame knows what a dig re-meshed (FrameStart::findSdfChangeSince): the volume takes that box
// instead of comparing the triangles, and its voxels equal a fresh voxelization. A note about
// another geometry than the one it saw last is refused (it then compares, as before).
TEST(Cascades, AKnownChangeBoxReplacesTheTriangleComparison)
{
    const scene::RenderScene before = makeRoomWithBox(-0.2f), after = makeRoomWithBox(-0.14f);
    const std::string keyBefore = before.computeContentHash(), keyAfter = after.computeContentHash();
    CascadeSettings settings = furnaceSettings();
    settings.resolution = 16;
    settings.voxelSize = 1.0 / 16.0;
    CascadeVolume noted(settings), fresh(settings);
    noted.voxelize(before, keyBefore, glm::dvec3(0.0), 0, false);
    EXPECT_FALSE(noted.noteGeometryChange("another geometry", keyAfter, glm::dvec3(0.0), glm::dvec3(0.0)));
    // The box's old and new place (makeRoomWithBox: x to x + 0.13).
    const glm::dvec3 lo(-0.2f, -0.4f, -0.2f), hi(-0.14f + 0.13f, -0.27f, -0.05f);
    EXPECT_TRUE(noted.noteGeometryChange(keyBefore, keyAfter, lo, hi));
    const std::string what = noted.voxelize(after, keyAfter, glm::dvec3(0.0), 1, false);
    EXPECT_NE(what.find("re-voxelized the changed region"), std::string::npos) << what;
    fresh.voxelize(after, keyAfter, glm::dvec3(0.0), 0, false);
    expectSameVoxels(noted, fresh);
}

// A dig frame with a moving camera: the level scrolled and the geometry changed in one step.
// Only the new slabs and the changed box are voxelized, and the voxels equal a fresh
// voxelization of the edited scene at the new position.
TEST(Cascades, AScrollAndAnEditInOneFrameVoxelizeTheSlabsAndTheChangedRegionOnly)
{
    const scene::RenderScene before = makeRoomWithBox(-0.2f), after = makeRoomWithBox(-0.14f);
    CascadeSettings settings = furnaceSettings();
    settings.resolution = 16;
    settings.voxelSize = 1.0 / 16.0;
    CascadeVolume edited(settings), fresh(settings);
    const glm::dvec3 a(0.0), b(2.0 / 16.0 + 0.01, 0.0, -1.0 / 16.0);
    edited.voxelize(before, before.computeContentHash(), a, 0, false);
    const std::string what = edited.voxelize(after, after.computeContentHash(), b, 1, false);
    EXPECT_NE(what.find("voxelized the new slabs"), std::string::npos) << what;
    EXPECT_NE(what.find("and re-voxelized the changed region"), std::string::npos) << what;
    fresh.voxelize(after, after.computeContentHash(), b, 0, false);
    expectSameVoxels(edited, fresh);
}

// An edit outside a level (a box moved 1.5 m out, beyond level 0's 1 m but inside level 1's 2 m)
// leaves that level's voxels and light as they were: when it comes due it is neither
// re-voxelized nor re-lit, while level 1 re-voxelizes the change and is re-lit.
TEST(Cascades, AnEditOutsideALevelLeavesItsVoxelsAndLight)
{
    const auto makeScene = [](float x) {
        scene::RenderScene s;
        const auto m = addMaterial(s, glm::vec3(0.5f), glm::vec3(0.2f));
        addBox(s, glm::vec3(-0.3f, -0.5f, -0.3f), glm::vec3(0.3f, -0.4f, 0.3f),
               m); // a floor in level 0
        addBox(s, glm::vec3(x, -0.4f, -0.1f), glm::vec3(x + 0.2f, -0.2f, 0.1f), m);
        return s;
    };
    const scene::RenderScene before = makeScene(0.7f), after = makeScene(0.72f);
    CascadeSettings settings = furnaceSettings();
    settings.levels = 2;
    settings.resolution = 16;
    settings.voxelSize = 1.0 / 16.0;
    settings.oneLevelPerFrame = true;
    CascadeVolume volume(settings);
    volume.voxelize(before, before.computeContentHash(), glm::dvec3(0.0), 0, false);
    volume.injectLight(before, "l", 0, false);
    const std::vector<glm::vec3> light0 = volume.getLevel(0).light[kDirect];
    ASSERT_EQ(volume.getDueLevels(1), std::vector<int>{0});
    EXPECT_EQ(volume.voxelize(after, after.computeContentHash(), glm::dvec3(0.0), 1, false),
              "level 0: geometry changed: the change lies outside the level, nothing re-voxelized "
              "(voxels and light kept)");
    EXPECT_EQ(volume.injectLight(after, "l", 1, false), "");
    EXPECT_EQ(volume.getLevel(0).light[kDirect], light0);
    // Level 1 holds the box: it re-voxelizes the change and is re-lit; then level 0, which reads
    // level 1's light, is due again and re-lit.
    const std::string what =
        volume.voxelize(after, after.computeContentHash(), glm::dvec3(0.0), 2, false);
    EXPECT_NE(what.find("level 1: geometry changed: re-voxelized the changed region"),
              std::string::npos)
        << what;
    EXPECT_EQ(volume.injectLight(after, "l", 2, false), "level 1");
    EXPECT_EQ(volume.voxelize(after, after.computeContentHash(), glm::dvec3(0.0), 3, false), "");
    EXPECT_EQ(volume.injectLight(after, "l", 3, false), "level 0");
    // Its voxels equal a fresh voxelization of the edited scene.
    CascadeVolume fresh(settings);
    fresh.voxelize(after, after.computeContentHash(), glm::dvec3(0.0), 0, false);
    expectSameVoxels(volume, fresh);
}

// Three levels of 32^3 around makeOpenRoom (level 0 1.6 wide, level 2 6.4), and a G-buffer on
// its floor: sky, point light and both bounces reach the pixels.
CascadeSettings openRoomSettings()
{
    CascadeSettings s = furnaceSettings();
    s.levels = 3;
    s.voxelSize = 0.05;
    return s;
}

scene::GBuffer makeOpenRoomFloor()
{
    return makeFloorGBuffer(6, 5, -0.99, -0.8, 0.8, -0.8, 0.8);
}

TEST(Cascades, SplitConesMatchTheFurnaceClosedForm)
{
    // Near parts composited with far cones from the voxel centres: every cone in the furnace
    // sees the same radiance wherever it starts, so the split keeps the closed form. Tolerance:
    // the furnace's 3.5 % (the near part and the far cone each stop at 99 % opacity, as the
    // whole cone does).
    const double expected = glm::pi<double>() * 0.75;
    for (const double farStart : {1.0, 2.5, 6.0}) {
        CascadeSettings s = furnaceSettings();
        s.farStart = farStart;
        const Image<glm::vec3> e = runFurnace(s, glm::dvec3(0.0));
        for (const auto& p : e.pixels)
            EXPECT_NEAR(p.x, expected, 0.035 * expected) << farStart;
    }
}

TEST(Cascades, ASplitBeyondEveryConeIsTheWholeCone)
{
    // When the near part reaches as far as any cone goes, the far cones start outside the
    // cascade and add nothing: bitwise the unsplit gather (on a scene with sky, point light
    // and both bounces).
    const scene::RenderScene s = makeOpenRoom(glm::vec3(0.0f));
    CascadeSettings whole = openRoomSettings();
    CascadeSettings split = whole;
    split.farStart = 1e4;
    const scene::GBuffer g = makeOpenRoomFloor();
    std::vector<glm::vec3> a, b;
    for (auto [settings, out] : {std::pair{&whole, &a}, std::pair{&split, &b}}) {
        CascadeVolume volume(*settings);
        volume.voxelize(s, "room", glm::dvec3(0.0), 0, false);
        volume.injectLight(s, "lights", 0, false);
        volume.gatherCones(g, *out);
    }
    ASSERT_EQ(a.size(), b.size());
    float total = 0.0f;
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i], b[i]) << i;
        total += a[i].x;
    }
    EXPECT_GT(total, 0.0f); // the scene is lit: the comparison is not between zeros
}

TEST(Cascades, FarConesAreTracedOnceUntilALevelTheySampleChanges)
{
    const scene::RenderScene s = makeOpenRoom(glm::vec3(0.0f));
    CascadeSettings settings = openRoomSettings();
    settings.farStart = 2.5;
    CascadeVolume volume(settings);
    volume.voxelize(s, "room", glm::dvec3(0.0), 0, false);
    volume.injectLight(s, "lights", 0, false);
    const scene::GBuffer g = makeOpenRoomFloor();
    std::vector<glm::vec3> first, second, third;
    volume.gatherCones(g, first);
    const std::size_t traced = volume.getCounters().farConesTraced;
    EXPECT_GT(traced, 0u);
    EXPECT_EQ(traced, volume.getCounters().farVoxelsCached * std::size_t(kConeCount));
    // Nothing changed: no far cone is traced again, and the result is the same.
    volume.gatherCones(g, second);
    EXPECT_EQ(volume.getCounters().farConesTraced, 0u);
    EXPECT_EQ(first, second);
    // New lights re-light every level: the far cones are traced again.
    volume.injectLight(s, "other lights", 1, false);
    volume.gatherCones(g, third);
    EXPECT_EQ(volume.getCounters().farConesTraced, traced);
    EXPECT_EQ(first, third);
}

// A split nearer than the cones' start is raised to it (the default far_start 1 with a larger
// start_offset), and the row records the value used; 0 keeps whole cones.
TEST(Cascades, TheSplitStartsNoNearerThanTheCones)
{
    const auto farStart = [](double far, double offset) {
        auto t = createTechnique(
            rtlabRegisterTechnique_voxel_gi_cascades, "cascades",
            {{"far_start", far}, {"start_offset", offset}, {"device", std::string("cpu")}});
        return t->effectiveParams().getFloat("far_start");
    };
    EXPECT_EQ(farStart(2.5, 1.0), 2.5);
    EXPECT_EQ(farStart(0.5, 1.0), 1.0);
    EXPECT_EQ(farStart(1.0, 2.0), 2.0);
    EXPECT_EQ(farStart(0.0, 2.0), 0.0);
}

TEST(Cascades, TheExtrapolatedBounceCompletesTheFurnacesSeries)
{
    // In the furnace each bounce is a = 0.5 of the one before, so the extrapolated bounce is
    // exactly the next term: 2 gathered + 1 extrapolated = pi Le (a + a^2 + a^3); the furnace's
    // tolerance. Without it the answer is 14 % lower, far outside that tolerance.
    CascadeSettings s = furnaceSettings();
    s.extrapolate = true;
    const double expected = glm::pi<double>() * (0.5 + 0.25 + 0.125);
    for (const auto& p : runFurnace(s, glm::dvec3(0.0)).pixels)
        EXPECT_NEAR(p.x, expected, 0.035 * expected);
}

TEST(Cascades, ExtrapolateBounceFollowsTheGainAndCapsIt)
{
    // A gain below 1: the geometric next term; above 1 (more second bounce than first, the
    // talk's case) or no previous bounce: capped at the last bounce; nothing from nothing.
    EXPECT_EQ(extrapolateBounce(glm::vec3(0.4f, 1.0f, 0.0f), glm::vec3(0.2f, 2.0f, 0.5f)),
              glm::vec3(0.1f, 2.0f, 0.5f));
    EXPECT_EQ(extrapolateBounce(glm::vec3(1.0f), glm::vec3(0.0f)), glm::vec3(0.0f));
    EXPECT_EQ(extrapolateBounce(glm::vec3(0.0f), glm::vec3(-1.0f)), glm::vec3(0.0f));
}

TEST(Cascades, ExtrapolationClaimsOneMoreBounceAndNeedsTwo)
{
    const auto t = createTechnique(rtlabRegisterTechnique_voxel_gi_cascades, "cascades",
                                   {{"extrapolate", true}});
    EXPECT_EQ(dynamic_cast<plugin::VoxelGiTechnique&>(*t).definition().bounces, 3);
    EXPECT_THROW(createTechnique(rtlabRegisterTechnique_voxel_gi_cascades, "cascades",
                                 {{"extrapolate", true}, {"bounces", std::int64_t(1)}}),
                 Error);
}

TEST(Cascades, TheValueNoiseIsSmoothBoundedAndSpread)
{
    // In [0, 1); continuous across cell faces (the corner hashes are shared); not constant: over
    // 4096 cells the values spread over most of [0, 1].
    float lo = 1.0f, hi = 0.0f;
    for (int z = -8; z < 8; ++z)
        for (int y = -8; y < 8; ++y)
            for (int x = -8; x < 8; ++x) {
                const glm::ivec3 c(x * 977, y, z - 1000000);
                const float n = computeValueNoise(c, glm::vec3(0.25f, 0.5f, 0.75f));
                ASSERT_GE(n, 0.0f);
                ASSERT_LT(n, 1.0f);
                lo = std::min(lo, n);
                hi = std::max(hi, n);
                EXPECT_FLOAT_EQ(computeValueNoise(c, glm::vec3(1.0f, 0.5f, 0.5f)),
                                computeValueNoise(c + glm::ivec3(1, 0, 0), glm::vec3(0.0f, 0.5f, 0.5f)));
            }
    EXPECT_LT(lo, 0.2f);
    EXPECT_GT(hi, 0.8f);
}

TEST(Cascades, TheLevelNoiseMovesTheBlendButKeepsTheFurnace)
{
    // The noise only moves which level a pixel's samples blend toward: in the furnace every level
    // holds the same light, so the closed form and its tolerance hold.
    CascadeSettings s = furnaceSettings();
    s.levelNoise = 0.5;
    const double expected = glm::pi<double>() * 0.75;
    for (const auto& p : runFurnace(s, glm::dvec3(0.0)).pixels)
        EXPECT_NEAR(p.x, expected, 0.035 * expected);
    // In the open room it changes the answer (it does something), by less than the blend could.
    const scene::RenderScene room = makeOpenRoom(glm::vec3(0.0f));
    std::vector<glm::vec3> plain, noisy;
    for (auto [noise, out] : {std::pair{0.0, &plain}, std::pair{0.5, &noisy}}) {
        CascadeSettings settings = openRoomSettings();
        settings.levelNoise = noise;
        CascadeVolume volume(settings);
        volume.voxelize(room, "room", glm::dvec3(0.0), 0, false);
        volume.injectLight(room, "lights", 0, false);
        volume.gatherCones(makeOpenRoomFloor(), *out);
    }
    double changed = 0.0, total = 0.0;
    for (std::size_t i = 0; i < plain.size(); ++i) {
        changed += std::abs(double(noisy[i].x) - double(plain[i].x));
        total += plain[i].x;
    }
    EXPECT_GT(changed, 0.0);
    EXPECT_LT(changed, 0.5 * total);
}

TEST(Cascades, DeterministicForAnyThreadCount)
{
    Image<glm::vec3> one, two;
    CascadeSettings s = furnaceSettings();
    s.onePass = true;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = runFurnace(s, glm::dvec3(0.0), 2);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = runFurnace(s, glm::dvec3(0.0), 2);
    }
    EXPECT_EQ(one.pixels, two.pixels);
}

} // namespace
