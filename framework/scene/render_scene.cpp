#include "scene/render_scene.h"

#include "core/hash.h"

#include <glm/common.hpp>

namespace rtlab::scene {

void RenderScene::updateBounds()
{
    if (positions.empty()) {
        boundsMin = boundsMax = glm::vec3(0.0f);
        return;
    }
    boundsMin = boundsMax = positions.front();
    for (const auto& p : positions) {
        boundsMin = glm::min(boundsMin, p);
        boundsMax = glm::max(boundsMax, p);
    }
}

std::string RenderScene::computeContentHash() const
{
    Hasher h;
    h.add("RenderScene v1");
    h.addValue(positions.size()).addBytes(positions.data(), positions.size() * sizeof(glm::vec3));
    h.addValue(normals.size()).addBytes(normals.data(), normals.size() * sizeof(glm::vec3));
    h.addValue(indices.size()).addBytes(indices.data(), indices.size() * sizeof(std::uint32_t));
    h.addValue(triangleMaterial.size())
        .addBytes(triangleMaterial.data(), triangleMaterial.size() * sizeof(std::uint32_t));
    h.addValue(materials.size());
    for (const auto& m : materials)
        h.addValue(m.albedo).addValue(m.emission);
    h.addValue(pointLights.size());
    for (const auto& l : pointLights)
        h.addValue(l.position).addValue(l.intensity);
    h.addValue(int(sky.kind)).addValue(sky.constant).addValue(sky.zenith).addValue(sky.horizon);
    h.addValue(sky.ground).addValue(sky.lobes).addValue(sky.sharpness);
    return h.hexDigest();
}

} // namespace rtlab::scene
