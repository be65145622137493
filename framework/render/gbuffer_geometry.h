#pragma once
// The RenderScene as the G-buffer pass draws it: one interleaved vertex stream and 32-bit
// indices. The material of each triangle travels on its first vertex (the provoking vertex,
// read by flat-interpolated fragment inputs): triangles are rotated so that their first vertex
// carries their material, and a vertex is duplicated only where triangles of different materials
// would otherwise need the same one. Winding and triangle order are preserved.

#include "scene/render_scene.h"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rtlab::render {

//! One vertex as gbuffer.vert reads it (52 bytes, tightly packed).
struct GBufferVertex {
    glm::vec3 position{0.0f};   //!< world units
    glm::vec3 normal{0.0f};     //!< world-space shading normal
    std::uint32_t material = 0; //!< material of the triangles that start at this vertex
    glm::vec3 albedo{0.0f};     //!< of `material`
    glm::vec3 emission{0.0f};   //!< of `material`
};
static_assert(sizeof(GBufferVertex) == 52, "GBufferVertex must match the vertex layout");

//! Vertex and index data for drawing a RenderScene.
struct GBufferGeometry {
    std::vector<GBufferVertex> vertices;
    std::vector<std::uint32_t> indices; //!< three per triangle, same order as the scene
    std::size_t duplicatedVertices = 0; //!< vertices added to separate materials
};

//! Throws rtlab::Error describing the first inconsistency: normals not one per position,
//! an index count that is not a multiple of 3, an index out of range, triangleMaterial not one
//! per triangle, or a material index out of range.
void validateRenderScene(const scene::RenderScene& scene);

//! Builds the vertex and index data (validates the scene first).
GBufferGeometry buildGBufferGeometry(const scene::RenderScene& scene);

} // namespace rtlab::render
