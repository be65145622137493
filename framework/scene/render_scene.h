#pragma once
// The scene flattened for rendering at one frame: world-space triangles with a material per
// triangle, the lights and the sky. The rasteriser (G-buffer) and the Embree ground truth both
// consume exactly this, so a technique's error is its own and not a difference of geometry.

#include "scene/sky.h"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace rtlab::scene {

struct Material {
    std::string name;
    glm::vec3 albedo{0.8f};    //!< diffuse reflectance in [0, 1) per channel
    glm::vec3 emission{0.0f};  //!< emitted radiance (same on both sides)
};

struct PointLight {
    glm::vec3 position{0.0f};   //!< world units
    glm::vec3 intensity{1.0f};  //!< radiant intensity (radiance units x area / steradian), isotropic
};

//! A capsule as Scene::appendCharacters meshed it into a RenderScene (scene.cpp appendCapsule):
//! its ends, radius and frame, and where its vertices start, so that a renderer can mesh it again
//! on the device from these few numbers (render/capsule_mesh_gpu.h) instead of uploading its
//! vertices. Vertex i of the capsule (i < getCapsuleVertexCount()) is, with the template entry
//! e of getCapsuleTemplate(): n = e.x * (e.y * t0 + e.z * t1) + e.w * up, at (i below half the
//! vertices ? a : b) + radius * n.
struct CapsuleMesh {
    glm::vec3 a{0.0f}, b{0.0f};
    float radius = 0.0f;
    glm::vec3 t0{0.0f}, t1{0.0f}, up{0.0f};
    std::uint32_t firstVertex = 0;
    std::uint32_t material = 0;

    bool operator==(const CapsuleMesh&) const = default;
};

struct RenderScene {
    std::vector<glm::vec3> positions;           //!< world units
    std::vector<glm::vec3> normals;             //!< per vertex, unit length (shading normals)
    std::vector<std::uint32_t> indices;         //!< three per triangle, CCW seen from the front
    std::vector<std::uint32_t> triangleMaterial;  //!< index into materials, one per triangle
    std::vector<Material> materials;
    std::vector<PointLight> pointLights;
    Sky sky;
    glm::vec3 boundsMin{0.0f};  //!< of the triangles, world units
    glm::vec3 boundsMax{0.0f};
    //! The characters' capsules among the triangles (Scene::appendCharacters), in order; their
    //! vertices are the last ones of `positions`. Not part of the content hash: the triangles are.
    std::vector<CapsuleMesh> capsules;
    //! The content hash of the triangles before the characters' (FrameStart's
    //! assemble_geometry keeps it), or empty: a pass that keeps what it uploaded of the static
    //! part compares this instead of the triangles. Not part of the content hash.
    std::string staticKey;

    std::size_t triangleCount() const { return indices.size() / 3; }
    //! Hash of everything above: the key of ground-truth caches.
    std::string computeContentHash() const;
    //! Recomputes boundsMin/boundsMax from positions.
    void updateBounds();
};

//! The unit sphere's latitude rows and longitudes a capsule is meshed with (scene.cpp
//! appendCapsule: 16 segments, 6 rings per half, the equator row once per half): per vertex
//! (cos lat, cos lon, sin lon, sin lat), rows from the bottom pole to the top one.
const std::vector<glm::vec4>& getCapsuleTemplate();
//! Vertices per capsule: getCapsuleTemplate().size().
std::size_t getCapsuleVertexCount();

} // namespace rtlab::scene
