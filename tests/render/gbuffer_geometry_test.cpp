// The scene as the G-buffer pass draws it: every triangle's first vertex carries its material,
// triangles keep their corners, winding and order, vertices are split only where materials
// meet, and inconsistent scenes are rejected.

#include <gtest/gtest.h>

#include <array>
#include <string>

#include "core/error.h"
#include "render/gbuffer_geometry.h"
#include "render_test_support.h"

namespace rtlab::render::test {
namespace {

// The rotation r with b[k] == a[(k + r) % 3] (same corners, same cyclic order and so the same
// winding), or -1.
int findRotation(const std::array<glm::vec3, 3>& a, const std::array<glm::vec3, 3>& b)
{
    for (int r = 0; r < 3; ++r) {
        if (b[0] == a[r] && b[1] == a[(r + 1) % 3] && b[2] == a[(r + 2) % 3])
            return r;
    }
    return -1;
}

void expectFaithful(const scene::RenderScene& scene, const GBufferGeometry& g)
{
    ASSERT_EQ(g.indices.size(), scene.indices.size());
    for (std::size_t t = 0; t < scene.triangleCount(); ++t) {
        const std::array<glm::vec3, 3> original = {scene.positions[scene.indices[3 * t]],
                                                   scene.positions[scene.indices[3 * t + 1]],
                                                   scene.positions[scene.indices[3 * t + 2]]};
        std::array<glm::vec3, 3> drawn;
        for (int k = 0; k < 3; ++k) {
            ASSERT_LT(g.indices[3 * t + k], g.vertices.size());
            drawn[k] = g.vertices[g.indices[3 * t + k]].position;
        }
        const int r = findRotation(original, drawn);
        ASSERT_GE(r, 0) << "triangle " << t << " lost its corners or winding";
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(g.vertices[g.indices[3 * t + k]].normal,
                      scene.normals[scene.indices[3 * t + (k + r) % 3]])
                << "triangle " << t;
        const GBufferVertex& first = g.vertices[g.indices[3 * t]];
        const scene::Material& m = scene.materials[scene.triangleMaterial[t]];
        EXPECT_EQ(first.material, scene.triangleMaterial[t]) << "triangle " << t;
        EXPECT_EQ(first.albedo, m.albedo) << "triangle " << t;
        EXPECT_EQ(first.emission, m.emission) << "triangle " << t;
    }
}

TEST(GBufferGeometryTest, OneMaterialPerObjectNeedsNoExtraVertices)
{
    SceneBuilder b;
    const std::uint32_t red = b.addMaterial({0.9f, 0.1f, 0.1f});
    const std::uint32_t lamp = b.addMaterial({0.5f, 0.5f, 0.5f}, {4.0f, 3.0f, 2.0f});
    b.addSphere({0, 0, 0}, 1.0f, 16, 8, red);
    b.addBox({3, 0, 0}, {0.5f, 0.5f, 0.5f}, 0.3f, lamp);
    const GBufferGeometry g = buildGBufferGeometry(b.getScene());
    EXPECT_EQ(g.duplicatedVertices, 0u);
    EXPECT_EQ(g.vertices.size(), b.getScene().positions.size());
    expectFaithful(b.getScene(), g);
}

TEST(GBufferGeometryTest, SharedVerticesBetweenMaterialsAreSplitOnlyWhereNeeded)
{
    SceneBuilder b;
    const std::uint32_t m0 = b.addMaterial({0.2f, 0.3f, 0.4f});
    const std::uint32_t m1 = b.addMaterial({0.7f, 0.6f, 0.5f}, {1.0f, 0.0f, 0.0f});
    b.addCheckerGrid({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 6, m0, m1);
    const GBufferGeometry g = buildGBufferGeometry(b.getScene());
    expectFaithful(b.getScene(), g);
    EXPECT_LE(g.duplicatedVertices, 72u); // at most one per triangle
    EXPECT_EQ(g.vertices.size(), 49u + g.duplicatedVertices);
}

TEST(GBufferGeometryTest, TriangleWhoseCornersAllStartOtherMaterialsGetsACopy)
{
    // Four triangles over the same three corners with four materials: the first three claim
    // one corner each, the fourth needs a copy of a corner.
    scene::RenderScene s;
    s.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    s.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
    s.indices = {0, 1, 2, 0, 1, 2, 0, 1, 2, 0, 1, 2};
    s.triangleMaterial = {0, 1, 2, 3};
    for (int m = 0; m < 4; ++m)
        s.materials.push_back({"m" + std::to_string(m), glm::vec3(0.1f * float(m)), glm::vec3(m)});
    const GBufferGeometry g = buildGBufferGeometry(s);
    EXPECT_EQ(g.duplicatedVertices, 1u);
    EXPECT_EQ(g.vertices.size(), 4u);
    expectFaithful(s, g);
}

TEST(GBufferGeometryTest, EmptySceneGivesNoGeometry)
{
    const GBufferGeometry g = buildGBufferGeometry(scene::RenderScene{});
    EXPECT_TRUE(g.vertices.empty());
    EXPECT_TRUE(g.indices.empty());
}

TEST(GBufferGeometryTest, InconsistentScenesAreRejected)
{
    SceneBuilder b;
    b.addQuad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, b.addMaterial({0.5f, 0.5f, 0.5f}));
    const scene::RenderScene good = b.getScene();
    EXPECT_NO_THROW(validateRenderScene(good));
    auto expectRejected = [](const scene::RenderScene& s, const std::string& fragment) {
        try {
            validateRenderScene(s);
            ADD_FAILURE() << "accepted; expected: " << fragment;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    };
    scene::RenderScene s = good;
    s.normals.pop_back();
    expectRejected(s, "normals");
    s = good;
    s.indices.push_back(0);
    expectRejected(s, "multiple of 3");
    s = good;
    s.indices[4] = 4;
    expectRejected(s, "index 4 is 4");
    s = good;
    s.triangleMaterial.pop_back();
    expectRejected(s, "triangle materials");
    s = good;
    s.triangleMaterial[1] = 1;
    expectRejected(s, "uses material 1");
}

} // namespace
} // namespace rtlab::render::test
