// The shadow pass: cube-map faces against the distance to an enclosing box, rendering only the
// chosen lights, an atlas the caller owns, the faces a box touches (never missing one), and
// re-rendering only the faces a change touches.

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <vector>

#include "core/error.h"
#include "gpu/bus_counters.h"
#include "render/gbuffer_geometry.h"
#include "scene/scene.h"
#include "lighting_test_support.h"

namespace rtlab::render::test {
namespace {

TEST_F(ShadowPassTest, FacesStoreTheDistanceToAnEnclosingBox)
{
    // A light at the centre of an axis-aligned cube of half size a: the texel at face
    // coordinates (s, t) sees the wall at distance a * sqrt(1 + s^2 + t^2).
    SceneBuilder b;
    const float a = 0.5f;
    b.addBox({1.0f, 2.0f, 3.0f}, glm::vec3(a), 0.0f, b.addMaterial(kAlbedo));
    scene::RenderScene s = b.getScene();
    s.pointLights.push_back({{1.0f, 2.0f, 3.0f}, glm::vec3(1.0f)});
    getShadows().render(s);
    const int n = getShadows().getFaceSize();
    EXPECT_EQ(n, 256);
    for (int face = 0; face < kCubeFaceCount; ++face) {
        const Image<float> map = getShadows().readBackFace(0, face);
        for (const glm::ivec2 texel : {glm::ivec2(0, 0), glm::ivec2(n / 2, n / 2),
                                       glm::ivec2(n - 1, 7), glm::ivec2(31, n - 2)}) {
            const glm::vec2 st = (glm::vec2(texel) + 0.5f) / float(n) * 2.0f - 1.0f;
            const double expected = a * std::sqrt(1.0 + st.x * st.x + st.y * st.y);
            // 1e-5 relative: float32 interpolation of the light-relative position.
            EXPECT_NEAR(map.at(texel.x, texel.y), expected, 1e-5 * expected)
                << "face " << face << " texel " << texel.x << "," << texel.y;
        }
        // The face mapping and its inverse agree.
        const glm::vec3 dir = computeCubeFaceDirection(face, {0.3f, -0.7f});
        EXPECT_EQ(computeCubeFace(dir), face);
        const glm::vec2 st = computeCubeFaceCoords(dir, face);
        EXPECT_NEAR(st.x, 0.3f, 1e-6f);
        EXPECT_NEAR(st.y, -0.7f, 1e-6f);
    }
}

TEST_F(ShadowPassTest, RendersOnlyTheChosenLights)
{
    SceneBuilder b;
    addFloor(b, 2.0f, b.addMaterial(kAlbedo));
    scene::RenderScene s = b.getScene();
    s.pointLights.push_back({{0.0f, 1.0f, 0.0f}, glm::vec3(1.0f)});
    s.pointLights.push_back({{0.5f, 2.0f, 0.0f}, glm::vec3(1.0f)});
    getShadows().render(s);
    ASSERT_EQ(getShadows().getLightCount(), 2u);
    const Image<float> before = getShadows().readBackFace(0, 3); // -y: the floor below light 0

    // Light 0 moves but only light 1 is re-rendered: light 0 keeps its old map and position.
    s.pointLights[0].position.y = 1.5f;
    const std::size_t chosen[] = {1};
    const gpu::RunResult r = getShadows().render(s, chosen);
    EXPECT_EQ(r.commands.size(), 2u * kCubeFaceCount); // a draw and a copy per face
    EXPECT_TRUE(r.sumGpuMs(ShadowPass::kDrawLabel).has_value() || !getContext().hasGpuTimestamps());
    EXPECT_EQ(getShadows().getLightState(0).renderCount, 1u);
    EXPECT_EQ(getShadows().getLightState(1).renderCount, 2u);
    EXPECT_EQ(getShadows().getLightState(0).position.y, 1.0f);
    EXPECT_EQ(getShadows().readBackFace(0, 3).pixels, before.pixels);

    // Re-rendering light 0 updates its map (the floor is now 1.5 away below it).
    const std::size_t first[] = {0};
    getShadows().render(s, first);
    const int n = getShadows().getFaceSize();
    EXPECT_NEAR(getShadows().readBackFace(0, 3).at(n / 2, n / 2), 1.5f, 1e-3f);
    const std::size_t bad[] = {2};
    EXPECT_THROW(getShadows().render(s, bad), Error);

    // A third light reallocates the atlas and renders every light.
    s.pointLights.push_back({{-0.5f, 1.0f, 0.5f}, glm::vec3(1.0f)});
    getShadows().render(s, first);
    EXPECT_EQ(getShadows().getLightCount(), 3u);
    for (std::size_t i = 0; i < 3; ++i)
        EXPECT_TRUE(getShadows().getLightState(i).rendered) << i;
}

TEST_F(ShadowPassTest, AnAtlasTheCallerOwnsHoldsTheSameMapsAsTheOwnOne)
{
    // The frame graph owns the atlas (pipeline/compose.h): a pass rendering into it must give
    // bit for bit the maps of a pass with its own atlas; an atlas too small for the scene's
    // lights, or of another kind, is refused.
    SceneBuilder b;
    const std::uint32_t m = b.addMaterial(kAlbedo);
    addFloor(b, 2.0f, m);
    b.addBox({-0.5f, 0.3f, 0.2f}, {0.3f, 0.3f, 0.3f}, 0.4f, m);
    scene::RenderScene s = b.getScene();
    s.pointLights.push_back({{0.0f, 1.2f, 0.0f}, glm::vec3(1.0f)});
    s.pointLights.push_back({{1.0f, 0.8f, -0.6f}, glm::vec3(1.0f)});
    ShadowPassOptions options;
    options.compiler = getCompiler().getOptions();
    options.faceSize = 32;
    ShadowPass own(getContext(), options);
    own.render(s);
    const gpu::Image atlas =
        getContext().createImage(ShadowPass::makeAtlasDesc(options.faceSize, 2));
    ShadowPass external(getContext(), options);
    external.useAtlas(atlas);
    external.render(s);
    EXPECT_EQ(&external.getAtlas(), &atlas);
    for (std::size_t light = 0; light < 2; ++light)
        for (int face = 0; face < kCubeFaceCount; ++face) {
            const Image<float> a = own.readBackFace(light, face);
            const Image<float> c = external.readBackFace(light, face);
            ASSERT_EQ(a.pixels.size(), c.pixels.size());
            EXPECT_EQ(std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(float)),
                      0)
                << "light " << light << " face " << face;
        }
    const gpu::Image small = getContext().createImage(ShadowPass::makeAtlasDesc(options.faceSize, 1));
    ShadowPass tooSmall(getContext(), options);
    tooSmall.useAtlas(small);
    EXPECT_THROW(tooSmall.render(s), Error);
    const gpu::Image wrongSize = getContext().createImage(ShadowPass::makeAtlasDesc(16, 2));
    EXPECT_THROW(tooSmall.useAtlas(wrongSize), Error);
}

TEST(ShadowFaces, ABoxInsideOneFacesPyramidTouchesThatFaceOnly)
{
    const glm::vec3 light(1.0f, 2.0f, 3.0f);
    const glm::vec3 half(0.5f);
    // Centred on each face's axis at distance 2.5: every point has that major axis.
    for (int face = 0; face < kCubeFaceCount; ++face) {
        const glm::vec3 centre = light + 2.5f * computeCubeFaceDirection(face, {0.0f, 0.0f});
        EXPECT_EQ(computeCubeFacesTouching(light, centre - half, centre + half), 1u << face)
            << "face " << face;
    }
    // Across the +x / +y edge: both, and none of the opposite faces.
    const std::uint8_t edge = computeCubeFacesTouching(light, light + glm::vec3(1.5f, 1.5f, -0.1f),
                                                       light + glm::vec3(2.5f, 2.5f, 0.1f));
    EXPECT_EQ(edge & 0x0F, 0x05) << "+x and +y, not -x or -y: " << int(edge);
    // The light inside the box or on its boundary: every face.
    EXPECT_EQ(computeCubeFacesTouching(light, light - half, light + half), kAllCubeFaces);
    EXPECT_EQ(computeCubeFacesTouching(light, light, light + half), kAllCubeFaces);
    // An empty box: none.
    EXPECT_EQ(computeCubeFacesTouching(light, light + half, light - half), 0u);
    EXPECT_EQ(computeCubeFacesTouching(light, {4, 0, 0}, {5, 0, -1}), 0u);
}

TEST(ShadowFaces, NeverMissesAFaceThatSeesAPointOfTheBox)
{
    // Random boxes around a light, random points in them: the face of every point is in the
    // mask (conservative), checked for 2000 boxes x 64 points.
    std::uint64_t state = 12345;
    auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return float((state >> 40) & 0xFFFFFF) / float(0x1000000);
    };
    const glm::vec3 light(0.25f, -0.5f, 1.0f);
    int partial = 0;
    for (int box = 0; box < 2000; ++box) {
        const glm::vec3 centre =
            light + glm::vec3(next() - 0.5f, next() - 0.5f, next() - 0.5f) * 8.0f;
        const glm::vec3 half = glm::vec3(next(), next(), next()) * 0.7f;
        const std::uint8_t mask = computeCubeFacesTouching(light, centre - half, centre + half);
        partial += mask != kAllCubeFaces ? 1 : 0;
        for (int i = 0; i < 64; ++i) {
            const glm::vec3 p = centre + (glm::vec3(next(), next(), next()) * 2.0f - 1.0f) * half;
            if (p == light)
                continue;
            const int face = computeCubeFace(p - light);
            ASSERT_TRUE(mask & (1u << face))
                << "box " << box << " point " << i << " face " << face << " mask " << int(mask);
        }
    }
    EXPECT_GT(partial, 1000) << "most boxes miss some face";
}

TEST_F(ShadowPassTest, RenderingTheFacesAChangeTouchesGivesTheFullRendering)
{
    // A floor, a still box and a small box beside light 0 on its +x side. The small box moves;
    // the faces computeCubeFacesTouching reports for the box of its old and new triangles are
    // re-rendered, the others kept. Every face of both lights must equal, bit for bit, a full
    // rendering of the new scene by a second pass. The scene's bounds stay the same (the floor
    // and the still box set them), so the planes do too.
    const glm::vec3 half(0.1f);
    auto makeScene = [&](glm::vec3 smallBox) {
        SceneBuilder b;
        const std::uint32_t m = b.addMaterial(kAlbedo);
        addFloor(b, 2.0f, m);
        b.addBox({-1.0f, 0.5f, -1.0f}, {0.3f, 0.5f, 0.3f}, 0.3f, m);
        b.addBox(smallBox, half, 0.0f, m);
        scene::RenderScene s = b.getScene();
        s.pointLights.push_back({{0.0f, 0.6f, 0.0f}, glm::vec3(1.0f)});
        s.pointLights.push_back({{1.2f, 1.8f, 1.5f}, glm::vec3(1.0f)});
        return s;
    };
    const glm::vec3 before(0.6f, 0.6f, 0.0f), after(0.6f, 0.6f, 0.15f);
    const scene::RenderScene s0 = makeScene(before);
    const scene::RenderScene s1 = makeScene(after);
    getShadows().render(s0);
    const Image<float> oldPlusX = getShadows().readBackFace(0, 0);

    const glm::vec3 changedMin = glm::min(before, after) - half;
    const glm::vec3 changedMax = glm::max(before, after) + half;
    std::vector<std::uint8_t> masks;
    for (const scene::PointLight& l : s1.pointLights)
        masks.push_back(computeCubeFacesTouching(l.position, changedMin, changedMax));
    EXPECT_EQ(masks[0], 0x01) << "the small box lies in light 0's +x pyramid";
    const gpu::RunResult r = getShadows().renderFaces(s1, masks);
    std::size_t drawn = 0;
    for (std::size_t light = 0; light < 2; ++light) {
        const ShadowLightState& state = getShadows().getLightState(light);
        EXPECT_EQ(state.lastFaceMask, masks[light]) << light;
        for (int face = 0; face < kCubeFaceCount; ++face) {
            const bool chosen = (masks[light] & (1u << face)) != 0;
            EXPECT_EQ(state.faceRenderCounts[std::size_t(face)], chosen ? 2u : 1u)
                << "light " << light << " face " << face;
            drawn += chosen ? 1 : 0;
        }
    }
    EXPECT_LT(drawn, 2u * kCubeFaceCount);
    EXPECT_EQ(r.commands.size(), 2 * drawn); // a draw and a copy per face
    EXPECT_NE(getShadows().readBackFace(0, 0).pixels, oldPlusX.pixels)
        << "the move changes face +x of light 0";

    ShadowPassOptions options;
    options.compiler = getCompiler().getOptions();
    ShadowPass fresh(getContext(), options);
    fresh.render(s1);
    for (std::size_t light = 0; light < 2; ++light) {
        EXPECT_EQ(getShadows().getLightState(light).nearPlane,
                  fresh.getLightState(light).nearPlane);
        EXPECT_EQ(getShadows().getLightState(light).farPlane, fresh.getLightState(light).farPlane);
        for (int face = 0; face < kCubeFaceCount; ++face) {
            const Image<float> kept = getShadows().readBackFace(light, face);
            const Image<float> full = fresh.readBackFace(light, face);
            ASSERT_EQ(kept.pixels.size(), full.pixels.size());
            EXPECT_EQ(std::memcmp(kept.pixels.data(), full.pixels.data(),
                                  kept.pixels.size() * sizeof(float)),
                      0)
                << "light " << light << " face " << face;
        }
    }

    // A partial mask of a light that moved is widened to every face: one projection per cube.
    scene::RenderScene s2 = s1;
    s2.pointLights[0].position.y += 0.1f;
    const std::uint8_t one[] = {0x01, 0x00};
    getShadows().renderFaces(s2, one);
    EXPECT_EQ(getShadows().getLightState(0).lastFaceMask, kAllCubeFaces);
    EXPECT_EQ(getShadows().getLightState(1).lastFaceMask, 0u);
    const std::uint8_t wrongCount[] = {0x01};
    EXPECT_THROW(getShadows().renderFaces(s2, wrongCount), Error);
    const std::uint8_t badBits[] = {0x40, 0x00};
    EXPECT_THROW(getShadows().renderFaces(s2, badBits), Error);
}

// The characters meshed on the device: a frame where only they moved sends their poses to the
// G-buffer and shadow passes (80 bytes a capsule) instead of their vertices, and both passes
// draw exactly what they draw from the uploaded vertices: the G-buffer's attachments and the
// shadow faces bit for bit equal to passes given the moved scene whole. Both ways of knowing
// that only they moved: the vertices compared (a scene without a static key) and the static
// part's key (RenderScene::staticKey, as the frame's assembled geometry has it: nothing of the
// static part rebuilt or compared).
void expectCharactersMeshedOnTheDevice(ShadowPassTest& test, ShadowPass& shadows, GBufferPass& pass,
                                       const std::string& staticKey)
{
    SceneBuilder b;
    const std::uint32_t wall = b.addMaterial(kAlbedo);
    b.addBox({0.0f, 0.0f, -3.0f}, glm::vec3(2.0f, 2.0f, 0.1f), 0.0f, wall);
    scene::RenderScene base = b.getScene();
    base.materials.push_back({"skin", glm::vec3(0.8f, 0.6f, 0.5f), glm::vec3(0.0f)});
    base.pointLights.push_back({{0.5f, 1.5f, 0.0f}, glm::vec3(1.0f)});
    base.staticKey = staticKey;
    const auto posed = [&](float t) {
        std::vector<scene::PosedCapsule> capsules;
        for (int i = 0; i < 3; ++i) {
            const glm::vec3 foot(-1.0f + float(i) + 0.3f * t, -0.8f, -1.5f - 0.2f * t * float(i));
            capsules.push_back({{foot, foot + glm::vec3(0.1f * t, 0.9f, 0.05f), 0.2f + 0.01f * float(i)},
                                std::uint32_t(base.materials.size() - 1), "walker"});
        }
        scene::RenderScene s = base;
        scene::Scene().appendCharacters(s, capsules);
        return s;
    };
    const scene::RenderScene before = posed(0.0f), after = posed(1.0f);
    ASSERT_EQ(after.capsules.size(), 3u);
    ASSERT_EQ(before.positions.size(), after.positions.size());
    const scene::Camera camera = makeCamera({0.0f, 0.5f, 2.0f}, {0.0f, 0.0f, -2.0f});
    pass.setScene(before);
    shadows.render(before);
    const gpu::BusCounters start = gpu::getBusCounters();
    pass.setScene(after);
    shadows.render(after);
    const std::uint64_t bytes = (gpu::getBusCounters() - start).uploadBytes;
    // Per pass the poses (3 x 80 bytes) and, once per context, the template (238 x 16 bytes):
    // no vertex.
    EXPECT_LE(bytes, 2u * (3u * 80u + scene::getCapsuleVertexCount() * 16u)) << staticKey;
    pass.draw(camera, 64, 48);
    const scene::GBuffer patched = pass.readBack();
    GBufferPass whole(test.getContextForTest());
    whole.setScene(after, false);
    whole.draw(camera, 64, 48);
    const scene::GBuffer uploaded = whole.readBack();
    ASSERT_EQ(patched.position.pixels.size(), uploaded.position.pixels.size());
    std::size_t characterPixels = 0, differ = 0;
    for (std::size_t i = 0; i < patched.position.pixels.size(); ++i) {
        differ += std::memcmp(&patched.position.pixels[i], &uploaded.position.pixels[i], sizeof(glm::vec3)) != 0;
        differ += std::memcmp(&patched.normal.pixels[i], &uploaded.normal.pixels[i], sizeof(glm::vec3)) != 0;
        characterPixels += patched.materialId.pixels[i] == base.materials.size() - 1 ? 1 : 0;
    }
    EXPECT_EQ(differ, 0u) << staticKey;
    EXPECT_GT(characterPixels, 100u);
    ShadowPass fresh(test.getContextForTest(), ShadowPassOptions{});
    fresh.render(after);
    for (int face = 0; face < kCubeFaceCount; ++face)
        EXPECT_EQ(shadows.readBackFace(0, face).pixels, fresh.readBackFace(0, face).pixels)
            << "face " << face << ", static key '" << staticKey << "'";
}

TEST_F(ShadowPassTest, CharactersMeshedOnTheDeviceDrawTheUploadedVerticesBits)
{
    expectCharactersMeshedOnTheDevice(*this, getShadows(), getPass(), "");
    ShadowPass shadows(getContext(), ShadowPassOptions{});
    GBufferPass pass(getContext());
    expectCharactersMeshedOnTheDevice(*this, shadows, pass, "the walls");
}

} // namespace
} // namespace rtlab::render::test
