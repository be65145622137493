#include "scene/procedural.h"

#include "core/error.h"
#include "core/strings.h"

#include <glm/geometric.hpp>

namespace rtlab::scene {

const std::vector<ProceduralScene>& getProceduralScenes()
{
    static const std::vector<ProceduralScene> scenes = {
        {"cornell_box", "the Cornell box with its measured dimensions and colours, lit by its ceiling light",
         &makeCornellBox},
        {"tomorrow_town", "an SDF landscape with overhangs and a tunnel, buildings, emissive signs, lamps, sky, "
                          "walking capsule characters, digs over frames and a camera path",
         &makeTomorrowTown},
        {"csg_gallery", "sharp-feature CSG shapes for isosurface studies, one SDF model each", &makeCsgGallery},
        {"ao_testbed", "creases, thin occluders, depth discontinuities and a closed-form wall case for AO",
         &makeAoTestbed},
    };
    return scenes;
}

std::vector<std::string> getProceduralSceneNames()
{
    std::vector<std::string> names;
    for (const auto& s : getProceduralScenes())
        names.push_back(s.name);
    return names;
}

Scene makeProceduralScene(const std::string& name)
{
    for (const auto& s : getProceduralScenes())
        if (s.name == name) {
            Scene scene = s.build();
            scene.name = name;
            scene.source = "procedural";
            return scene;
        }
    const auto close = closestNames(name, getProceduralSceneNames());
    throw Error("unknown procedural scene '" + name + "'" +
                (close.empty() ? "" : "; did you mean " + joinList(close, "or") + "?") +
                " Valid: " + joinList(getProceduralSceneNames()) + ".");
}

void appendQuad(MeshInstance& mesh, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                const glm::vec3& d, std::uint32_t material, const glm::vec3& facing)
{
    glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const glm::vec3 centre = 0.25f * (a + b + c + d);
    const bool flip = glm::dot(n, facing - centre) < 0.0f;
    if (flip)
        n = -n;
    const auto base = std::uint32_t(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), {a, b, c, d});
    mesh.normals.insert(mesh.normals.end(), {n, n, n, n});
    if (flip)
        mesh.indices.insert(mesh.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    else
        mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    mesh.triangleMaterial.insert(mesh.triangleMaterial.end(), {material, material});
}

void appendBox(MeshInstance& mesh, const glm::vec3& lo, const glm::vec3& hi, std::uint32_t material)
{
    const glm::vec3 c = 0.5f * (lo + hi);
    const glm::vec3 e = hi - lo;
    // Each face faces a point outside it along its normal.
    appendQuad(mesh, {lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {lo.x, lo.y, hi.z}, material, c - glm::vec3(e.x, 0, 0));
    appendQuad(mesh, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}, material, c + glm::vec3(e.x, 0, 0));
    appendQuad(mesh, {lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}, material, c - glm::vec3(0, e.y, 0));
    appendQuad(mesh, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, material, c + glm::vec3(0, e.y, 0));
    appendQuad(mesh, {lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z}, material, c - glm::vec3(0, 0, e.z));
    appendQuad(mesh, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, material, c + glm::vec3(0, 0, e.z));
}

} // namespace rtlab::scene
