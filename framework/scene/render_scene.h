#pragma once
// The scene flattened for rendering at one frame: world-space triangles with a material per
// triangle, the lights and the sky. The rasteriser (G-buffer) and the Embree ground truth both
// consume exactly this, so a technique's error is its own and not a difference of geometry.

#include "scene/sky.h"

#include <glm/vec3.hpp>

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

    std::size_t triangleCount() const { return indices.size() / 3; }
    //! Hash of everything above: the key of ground-truth caches.
    std::string computeContentHash() const;
    //! Recomputes boundsMin/boundsMax from positions.
    void updateBounds();
};

} // namespace rtlab::scene
