#pragma once
// Shared helpers of the render tests: small scenes built from quads, boxes and spheres, a CPU
// ray caster over a RenderScene (double precision, brute force) that derives its rays from the
// camera's parameters rather than from its matrices, and a fixture with a GBufferPass.

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

#include "gpu_test_support.h"
#include "render/gbuffer_pass.h"
#include "scene/camera.h"
#include "scene/render_scene.h"

namespace rtlab::render::test {

//! tests/render/shaders ($RTLAB_SOURCE_DIR/tests/render/shaders when that variable is set).
std::filesystem::path getRenderTestShaderDir();

//! Builds a RenderScene from parts; every part is one object (an id for silhouette tests).
class SceneBuilder {
public:
    //! Adds a material and returns its index.
    std::uint32_t addMaterial(glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f));
    //! A planar quad a-b-c-d (counter-clockwise seen from the front) as triangles (a, b, c) and
    //! (a, c, d), with the flat normal of that winding. `secondMaterial` (if given) is used for
    //! the second triangle.
    void addQuad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t material,
                 std::optional<std::uint32_t> secondMaterial = std::nullopt);
    //! An axis-aligned box rotated by `yawRadians` about the y axis through its centre, faces
    //! outward with flat normals.
    void addBox(glm::vec3 center, glm::vec3 halfExtents, float yawRadians, std::uint32_t material);
    //! A UV sphere with smooth normals (`segments` around, `rings` from pole to pole).
    void addSphere(glm::vec3 center, float radius, int segments, int rings, std::uint32_t material);
    //! A planar n x n grid of quads spanning corner + s*u + t*v (s, t in [0, 1]) with shared
    //! vertices; quads alternate between materials a and b like a checkerboard, and the two
    //! triangles of a quad differ too, so most vertices are corners of both materials.
    void addCheckerGrid(glm::vec3 corner, glm::vec3 u, glm::vec3 v, int n, std::uint32_t a,
                        std::uint32_t b);

    const scene::RenderScene& getScene() const { return mScene; }
    //! Object id of each triangle (in the order of RenderScene::indices).
    const std::vector<int>& getTriangleObjects() const { return mTriangleObject; }

private:
    std::uint32_t addVertex(glm::vec3 position, glm::vec3 normal);
    void addTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t material);

    scene::RenderScene mScene;
    std::vector<int> mTriangleObject;
    int mObject = -1;
};

//! The camera ray through pixel coordinates `pixel` (x right, y down; pixel centres at +0.5),
//! from the camera's position, target, up, field of view and the image aspect.
glm::dvec3 computeReferenceRayDirection(const scene::Camera& camera, int width, int height,
                                        glm::dvec2 pixel);

//! The nearest hit of a ray.
struct RayHit {
    double t = 0.0;             //!< along the (unnormalised) direction
    std::int64_t triangle = -1; //!< -1: no hit
    double b1 = 0.0;            //!< barycentric weight of the second corner
    double b2 = 0.0;            //!< of the third corner
};

//! Brute-force nearest intersection with t > 0 (two-sided, Moller-Trumbore in double).
RayHit intersectScene(const scene::RenderScene& scene, glm::dvec3 origin, glm::dvec3 direction);

//! What the CPU ray caster finds through one pixel sample.
struct CpuSample {
    bool hit = false;
    double depth = 0.0;       //!< along the view direction
    glm::dvec3 position{0.0}; //!< world
    glm::dvec3 normal{0.0};   //!< interpolated, normalised, facing the camera's side
    std::uint32_t material = 0;
    int object = -1;
};

//! Ray casts the sample at pixel coordinates `pixel` (x right, y down; pixel centres at +0.5)
//! of a `width` x `height` image, keeping hits between the near and far planes (by view depth).
CpuSample castSample(const SceneBuilder& builder, const scene::Camera& camera, int width,
                     int height, glm::dvec2 pixel);

//! A GpuTest (validation on, any message fails the test) with a GBufferPass whose shaders are
//! cached in the test's private cache directory.
class RenderTest : public gpu::test::GpuTest {
protected:
    void SetUp() override;
    void TearDown() override;
    GBufferPass& getPass() { return *mPass; }
    //! 2^-subPixelPrecisionBits: how far the rasteriser may move a vertex, in pixels.
    double getSnapPixels();

private:
    std::optional<GBufferPass> mPass;
};

} // namespace rtlab::render::test
