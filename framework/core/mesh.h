#pragma once
// Indexed triangle meshes: what isosurface techniques produce and mesh metrics consume.

#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace rtlab {

struct TriangleMesh {
    std::vector<glm::vec3> positions;  //!< world units
    std::vector<glm::vec3> normals;    //!< unit length, one per position; may be empty
    std::vector<std::uint32_t> indices;  //!< three per triangle, counter-clockwise seen from outside

    std::size_t vertexCount() const { return positions.size(); }
    std::size_t triangleCount() const { return indices.size() / 3; }
    void clear()
    {
        positions.clear();
        normals.clear();
        indices.clear();
    }
};

} // namespace rtlab

namespace rtlab {
//! Writes Wavefront OBJ (positions, normals when present, 1-based faces). Throws rtlab::Error
//! naming the path when it cannot be written.
void writeObj(const TriangleMesh& mesh, const std::string& path);
} // namespace rtlab
