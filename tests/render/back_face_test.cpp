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

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <vector>

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

//! A faceted UV sphere (10 segments, 6 rings) whose quads are wound either way (every third
//! flipped), with vertex normals summed across the faces around each vertex as wound: where
//! windings disagree the sum points anywhere, into the surface too, as a downloaded model
//! smoothed without regard to winding. `flat`: each face its own normal, as wound.
scene::RenderScene makeFacetedSphere(bool flat)
{
    scene::RenderScene s;
    s.materials.push_back({"grey", glm::vec3(0.6f), glm::vec3(0.0f)});
    constexpr int kRings = 6, kSegments = 10;
    const auto at = [](int i, int j) {
        const double th = 3.14159265358979 * i / kRings, ph = 2.0 * 3.14159265358979 * j / kSegments;
        return glm::vec3(glm::dvec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
    };
    std::vector<std::array<glm::vec3, 3>> triangles;
    for (int i = 0; i < kRings; ++i)
        for (int j = 0; j < kSegments; ++j) {
            const glm::vec3 a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
            std::array<std::array<glm::vec3, 3>, 2> quad{{{a, b, c}, {a, c, d}}};
            if ((i * kSegments + j) % 3 == 0)
                for (auto& t : quad)
                    std::swap(t[1], t[2]);
            for (const auto& t : quad)
                if (glm::length(glm::cross(t[1] - t[0], t[2] - t[0])) > 1e-6f)
                    triangles.push_back(t);
        }
    // Shared vertices by position (smooth) or per face (flat).
    std::vector<glm::vec3> sums;
    const auto vertex = [&](const glm::vec3& p) -> std::uint32_t {
        if (!flat)
            for (std::size_t v = 0; v < s.positions.size(); ++v)
                if (glm::length(s.positions[v] - p) < 1e-5f)
                    return std::uint32_t(v);
        s.positions.push_back(p);
        sums.push_back(glm::vec3(0.0f));
        return std::uint32_t(s.positions.size() - 1);
    };
    for (const auto& t : triangles) {
        const glm::vec3 cross = glm::cross(t[1] - t[0], t[2] - t[0]);
        for (const glm::vec3& p : t) {
            const std::uint32_t v = vertex(p);
            s.indices.push_back(v);
            sums[v] += cross;
        }
        s.triangleMaterial.push_back(0);
    }
    for (const glm::vec3& n : sums)
        s.normals.push_back(glm::length(n) > 0.0f ? glm::normalize(n) : glm::vec3(0.0f, 1.0f, 0.0f));
    s.sky.kind = scene::Sky::Kind::Constant;
    s.sky.constant = glm::vec3(1.0f);
    s.updateBounds();
    return s;
}

TEST_F(BackFaceTest, AFacetedSphereHasNoBlackAmbientOcclusionFlatOrSmooth)
{
    // A lone convex sphere: a point on it sees its whole hemisphere when the hemisphere faces
    // out of the sphere (AO 1 with flat normals), and at least half of it with a smoothed normal
    // tilted up to half a facet's angle. A shading normal that points into the surface gives a
    // hemisphere inside the solid: every ray hits the sphere's far side (unbounded radius), AO
    // 0, the black streaks of smoothed downloaded models. Both G-buffers turn normals to the camera side of
    // the triangle's own plane, and the ground truth is traced from the rasterised one.
    scene::Camera camera;
    camera.position = {0.4f, 1.2f, 3.0f};
    camera.target = {0.0f, 0.0f, 0.0f};
    camera.verticalFovDegrees = 45.0f;
    constexpr int kW = 64, kH = 48;
    for (const bool flat : {true, false}) {
        const scene::RenderScene sphere = makeFacetedSphere(flat);
        getPass().setScene(sphere);
        const scene::GBuffer raster = getPass().render(camera, kW, kH);
        const scene::GBuffer cast = reference::castGBuffer(sphere, camera, kW, kH);
        reference::ReferenceSettings settings =
            reference::makeFixedSampleSettings(reference::Quantity::Ao, 1, 256, 7);
        for (const scene::GBuffer* g : {&raster, &cast}) {
            const Image<float> ao = reference::computeReference(sphere, *g, settings).occlusion;
            int surface = 0, black = 0;
            float lowest = 1.0f;
            for (int y = 0; y < kH; ++y)
                for (int x = 0; x < kW; ++x) {
                    if (!g->hasSurface(x, y))
                        continue;
                    ++surface;
                    lowest = std::min(lowest, ao.at(x, y));
                    black += ao.at(x, y) < 0.02f;
                }
            EXPECT_GT(surface, kW * kH / 8);
            // 256 rays: the AO of a pixel that sees half its hemisphere is below 0.02 with
            // probability far below 1e-30; 0.02 only catches a hemisphere inside the surface.
            EXPECT_EQ(black, 0) << (flat ? "flat" : "smooth") << (g == &raster ? " raster" : " cast")
                                << ": lowest AO " << lowest;
        }
    }
}

} // namespace
} // namespace rtlab::render::test
