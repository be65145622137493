#include "render/gbuffer_geometry.h"

#include <limits>
#include <string>

#include "core/error.h"

namespace rtlab::render {

void validateRenderScene(const scene::RenderScene& scene)
{
    const std::string prefix = "render scene: ";
    if (scene.normals.size() != scene.positions.size())
        throw Error(prefix + std::to_string(scene.normals.size()) + " normals for " +
                    std::to_string(scene.positions.size()) + " positions");
    if (scene.indices.size() % 3 != 0)
        throw Error(prefix + std::to_string(scene.indices.size()) +
                    " indices, not a multiple of 3");
    if (scene.positions.size() >= std::numeric_limits<std::uint32_t>::max())
        throw Error(prefix + "too many vertices for 32-bit indices");
    for (std::size_t i = 0; i < scene.indices.size(); ++i) {
        if (scene.indices[i] >= scene.positions.size())
            throw Error(prefix + "index " + std::to_string(i) + " is " +
                        std::to_string(scene.indices[i]) + ", but there are only " +
                        std::to_string(scene.positions.size()) + " vertices");
    }
    if (scene.triangleMaterial.size() != scene.triangleCount())
        throw Error(prefix + std::to_string(scene.triangleMaterial.size()) +
                    " triangle materials for " + std::to_string(scene.triangleCount()) +
                    " triangles");
    for (std::size_t t = 0; t < scene.triangleMaterial.size(); ++t) {
        if (scene.triangleMaterial[t] >= scene.materials.size())
            throw Error(prefix + "triangle " + std::to_string(t) + " uses material " +
                        std::to_string(scene.triangleMaterial[t]) + ", but there are only " +
                        std::to_string(scene.materials.size()) + " materials");
    }
}

GBufferGeometry buildGBufferGeometry(const scene::RenderScene& scene)
{
    validateRenderScene(scene);
    constexpr std::uint32_t kUnassigned = std::numeric_limits<std::uint32_t>::max();

    GBufferGeometry g;
    g.vertices.resize(scene.positions.size());
    std::vector<std::uint32_t> assigned(scene.positions.size(), kUnassigned);
    for (std::size_t v = 0; v < scene.positions.size(); ++v) {
        g.vertices[v].position = scene.positions[v];
        g.vertices[v].normal = scene.normals[v];
    }

    g.indices.resize(scene.indices.size());
    for (std::size_t t = 0; t < scene.triangleCount(); ++t) {
        const std::uint32_t material = scene.triangleMaterial[t];
        const std::uint32_t* corners = &scene.indices[3 * t];
        // A corner that already carries this material, else one that carries none yet.
        int chosen = -1;
        for (int k = 0; k < 3 && chosen < 0; ++k) {
            if (assigned[corners[k]] == material)
                chosen = k;
        }
        for (int k = 0; k < 3 && chosen < 0; ++k) {
            if (assigned[corners[k]] == kUnassigned)
                chosen = k;
        }
        std::uint32_t first = 0;
        if (chosen >= 0) {
            first = corners[chosen];
            assigned[first] = material;
        } else {
            // Every corner starts triangles of other materials: start from a copy.
            chosen = 0;
            first = static_cast<std::uint32_t>(g.vertices.size());
            g.vertices.push_back(g.vertices[corners[0]]);
            assigned.push_back(material);
            ++g.duplicatedVertices;
        }
        // Rotating (a, b, c) keeps the winding.
        g.indices[3 * t + 0] = first;
        g.indices[3 * t + 1] = corners[(chosen + 1) % 3];
        g.indices[3 * t + 2] = corners[(chosen + 2) % 3];
    }

    for (std::size_t v = 0; v < g.vertices.size(); ++v) {
        if (assigned[v] == kUnassigned)
            continue; // starts no triangle: its material is never read
        const scene::Material& m = scene.materials[assigned[v]];
        g.vertices[v].material = assigned[v];
        g.vertices[v].albedo = m.albedo;
        g.vertices[v].emission = m.emission;
    }
    return g;
}

} // namespace rtlab::render
