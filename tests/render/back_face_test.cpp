// Downloaded models come with one-sided faces wound either way. Both G-buffers (the rasteriser's
// and the Embree ray cast the ground truth can use) must turn a face's normal toward the camera,
// whichever way it is wound, or every technique and the ground truth see a back face as the inside
// of a solid (ambient occlusion 0). scenes/imported_room.yaml is such a model: no vertex normals,
// the back wall, the right wall and three faces of a pillar wound away from the room.

#include "render_test_support.h"

#include "reference/reference.h"
#include "scene/scene_file.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <filesystem>

namespace rtlab::render::test {
namespace {

using BackFaceTest = RenderTest;

TEST_F(BackFaceTest, BothGBuffersTurnEveryNormalTowardTheCamera)
{
    const scene::Scene scene = scene::loadScene(
        (std::filesystem::path(RTLAB_SOURCE_DIR) / "scenes" / "imported_room.yaml").string());
    const scene::RenderScene frame = scene.buildRenderScene(0);
    constexpr int kW = 96, kH = 54;
    getPass().setScene(frame);
    const scene::GBuffer raster = getPass().render(scene.camera, kW, kH);
    const scene::GBuffer cast = reference::castGBuffer(frame, scene.camera, kW, kH);

    // Faces wound away from the camera must be in view, or the test proves nothing: count the
    // pixels whose triangle's own winding faces away.
    int surface = 0, backFacing = 0, agreeing = 0, both = 0;
    for (const scene::GBuffer* g : {&raster, &cast})
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) {
                if (!g->hasSurface(x, y))
                    continue;
                const glm::vec3 toCamera = glm::normalize(scene.camera.position - g->position.at(x, y));
                const glm::vec3 n = g->normal.at(x, y);
                EXPECT_NEAR(glm::length(n), 1.0f, 1e-4f) << x << ", " << y;
                // Every face of this room is flat, so a normal toward the camera has a positive
                // cosine with the view direction (the pillar's top, 0.1 below the camera, is seen
                // at a grazing 0.02; a wrongly turned normal gives a negative cosine).
                EXPECT_GT(glm::dot(n, toCamera), 0.0f) << (g == &raster ? "raster " : "cast ") << x
                                                         << ", " << y;
                ++surface;
            }
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            if (!raster.hasSurface(x, y) || !cast.hasSurface(x, y))
                continue;
            ++both;
            agreeing += glm::dot(raster.normal.at(x, y), cast.normal.at(x, y)) > 0.99f;
        }
    // The triangles whose winding faces away from the camera position.
    for (std::size_t t = 0; t + 2 < frame.indices.size(); t += 3) {
        const glm::vec3 a = frame.positions[frame.indices[t]];
        const glm::vec3 b = frame.positions[frame.indices[t + 1]];
        const glm::vec3 c = frame.positions[frame.indices[t + 2]];
        backFacing += glm::dot(glm::cross(b - a, c - a), scene.camera.position - a) < 0.0f;
    }
    EXPECT_GE(backFacing, 6) << "the scene should show faces wound away from the camera";
    EXPECT_GT(surface, kW * kH); // both images mostly covered
    // Silhouette pixels may hit different faces in the two; everywhere else the normals agree.
    EXPECT_GT(agreeing, int(0.97 * both)) << agreeing << " of " << both;
}

} // namespace
} // namespace rtlab::render::test
