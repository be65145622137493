#include "scene/scene.h"

#include "core/error.h"
#include "scene/sdf_mesher.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtx/rotate_vector.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace rtlab::scene {

namespace {
constexpr int kCapsuleSegments = 16; // a capsule's longitudes
constexpr int kCapsuleRings = 6;     // its latitude rows per half, pole to equator
} // namespace

const std::vector<SceneFeature>& FeatureSet::getAll()
{
    static const std::vector<SceneFeature> all = {
        SceneFeature::Triangles,  SceneFeature::PointLights,   SceneFeature::Emissive,
        SceneFeature::Sky,        SceneFeature::Characters,    SceneFeature::SdfModels,
        SceneFeature::EditsOverTime, SceneFeature::MovingCamera};
    return all;
}

const char* FeatureSet::getName(SceneFeature f)
{
    switch (f) {
    case SceneFeature::Triangles: return "triangles";
    case SceneFeature::PointLights: return "point_lights";
    case SceneFeature::Emissive: return "emissive";
    case SceneFeature::Sky: return "sky";
    case SceneFeature::Characters: return "characters";
    case SceneFeature::SdfModels: return "sdf_models";
    case SceneFeature::EditsOverTime: return "edits_over_time";
    case SceneFeature::MovingCamera: return "moving_camera";
    }
    return "?";
}

std::string FeatureSet::toString() const
{
    std::string s;
    for (SceneFeature f : getAll())
        if (has(f))
            s += (s.empty() ? "" : ", ") + std::string(getName(f));
    return s.empty() ? "none" : s;
}

std::vector<Capsule> Character::getCapsulesAt(float time) const
{
    CharacterKey key;
    if (!path.empty()) {
        if (time <= path.front().time || path.size() == 1) {
            key = path.front();
        } else if (time >= path.back().time) {
            key = path.back();
        } else {
            std::size_t i = 0;
            while (path[i + 1].time <= time)
                ++i;
            const float t = (time - path[i].time) / std::max(path[i + 1].time - path[i].time, 1e-9f);
            key.position = glm::mix(path[i].position, path[i + 1].position, t);
            key.headingDegrees = glm::mix(path[i].headingDegrees, path[i + 1].headingDegrees, t);
        }
    }
    const float angle = glm::radians(key.headingDegrees);
    std::vector<Capsule> out = capsules;
    for (auto& c : out) {
        c.a = key.position + glm::rotateY(c.a, angle);
        c.b = key.position + glm::rotateY(c.b, angle);
    }
    return out;
}

FeatureSet Scene::computeFeatures() const
{
    FeatureSet f;
    if (!meshes.empty() || !sdfModels.empty() || !characters.empty())
        f.add(SceneFeature::Triangles);
    if (!pointLights.empty())
        f.add(SceneFeature::PointLights);
    if (std::any_of(materials.begin(), materials.end(),
                    [](const Material& m) { return glm::dot(m.emission, m.emission) > 0.0f; }))
        f.add(SceneFeature::Emissive);
    if (sky.emits())
        f.add(SceneFeature::Sky);
    if (!characters.empty())
        f.add(SceneFeature::Characters);
    if (!sdfModels.empty())
        f.add(SceneFeature::SdfModels);
    if (std::any_of(sdfModels.begin(), sdfModels.end(), [](const SdfModel& m) { return m.changesOverTime(); }))
        f.add(SceneFeature::EditsOverTime);
    if (cameraPath.moves())
        f.add(SceneFeature::MovingCamera);
    return f;
}

Camera Scene::getCameraAt(int frame) const
{
    return cameraPath.empty() ? camera : cameraPath.evaluate(getFrameTime(frame));
}

const std::vector<glm::vec4>& getCapsuleTemplate()
{
    static const std::vector<glm::vec4> unit = [] {
        std::vector<glm::vec4> v;
        for (int half = 0; half < 2; ++half)
            for (int r = 0; r <= kCapsuleRings; ++r) {
                const float lat =
                    -glm::half_pi<float>() + glm::half_pi<float>() * (float(r) / kCapsuleRings + half);
                for (int s = 0; s <= kCapsuleSegments; ++s) {
                    const float lon = glm::two_pi<float>() * float(s) / kCapsuleSegments;
                    v.emplace_back(std::cos(lat), std::cos(lon), std::sin(lon), std::sin(lat));
                }
            }
        return v;
    }();
    return unit;
}

std::size_t getCapsuleVertexCount()
{
    return getCapsuleTemplate().size();
}

namespace {

// A capsule as a UV sphere split at its equator with a cylinder between the halves.
void appendCapsule(RenderScene& out, const Capsule& c, std::uint32_t material)
{
    const int segments = kCapsuleSegments, rings = kCapsuleRings;
    const glm::vec3 axis = c.b - c.a;
    const float length = glm::length(axis);
    const glm::vec3 up = length > 0.0f ? axis / length : glm::vec3(0, 1, 0);
    const glm::vec3 t0 = glm::normalize(std::abs(up.y) < 0.9f ? glm::cross(up, glm::vec3(0, 1, 0))
                                                              : glm::cross(up, glm::vec3(1, 0, 0)));
    const glm::vec3 t1 = glm::cross(up, t0);
    const auto base = std::uint32_t(out.positions.size());
    out.capsules.push_back({c.a, c.b, c.radius, t0, t1, up, base, material});
    // Latitude rows from the bottom pole (-pi/2) to the top pole (+pi/2); the equator row is
    // duplicated so the lower half sits on c.a and the upper half on c.b.
    const std::vector<glm::vec4>& unit = getCapsuleTemplate();
    const int rows = 2 * (rings + 1);
    for (std::size_t i = 0; i < unit.size(); ++i) {
        const glm::vec4& e = unit[i];
        const glm::vec3 centre = i < unit.size() / 2 ? c.a : c.b;
        const glm::vec3 n = e.x * (e.y * t0 + e.z * t1) + e.w * up;
        out.positions.push_back(centre + c.radius * n);
        out.normals.push_back(n);
    }
    for (int r = 0; r + 1 < rows; ++r)
        for (int s = 0; s < segments; ++s) {
            const std::uint32_t i0 = base + r * (segments + 1) + s, i1 = i0 + 1;
            const std::uint32_t j0 = i0 + (segments + 1), j1 = j0 + 1;
            // Counter-clockwise seen from outside (longitude increases counter-clockwise about up).
            // The pole rows collapse to a point: their triangles are left out by where they lie
            // (not by their area, which rounding makes 0 or not with the pose, so that every pose
            // has the same triangles and a renderer can mesh it again: render/capsule_mesh_gpu.h).
            // Elsewhere a triangle of no area (a capsule whose ends meet) is left out.
            const bool bottomPole = r == 0, topPole = r + 2 == rows;
            for (const auto& tri : {std::array<std::uint32_t, 3>{i0, i1, j1}, std::array<std::uint32_t, 3>{i0, j1, j0}}) {
                if ((bottomPole && tri[1] == i1) || (topPole && tri[1] == j1 && tri[2] == j0))
                    continue;
                const glm::vec3 e = glm::cross(out.positions[tri[1]] - out.positions[tri[0]],
                                               out.positions[tri[2]] - out.positions[tri[0]]);
                if (glm::dot(e, e) <= 0.0f)
                    continue;
                out.indices.insert(out.indices.end(), tri.begin(), tri.end());
                out.triangleMaterial.push_back(material);
            }
        }
}

void computeMissingNormals(const MeshInstance& mesh, std::vector<glm::vec3>& normals)
{
    normals.assign(mesh.positions.size(), glm::vec3(0.0f));
    for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
        const auto a = mesh.indices[t], b = mesh.indices[t + 1], c = mesh.indices[t + 2];
        // Area-weighted: the cross product's length is twice the area.
        const glm::vec3 n = glm::cross(mesh.positions[b] - mesh.positions[a], mesh.positions[c] - mesh.positions[a]);
        normals[a] += n;
        normals[b] += n;
        normals[c] += n;
    }
    for (auto& n : normals) {
        const float len = glm::length(n);
        n = len > 0.0f ? n / len : glm::vec3(0, 1, 0);
    }
}

} // namespace

std::vector<SdfMesh> Scene::meshSdfModels(int frame) const
{
    std::vector<SdfMesh> out;
    out.reserve(sdfModels.size());
    for (const auto& model : sdfModels)
        out.push_back(meshSdfModel(model, {.resolution = model.resolution, .frame = frame}));
    return out;
}

std::vector<PosedCapsule> Scene::poseCharacters(int frame) const
{
    std::vector<PosedCapsule> out;
    const float time = getFrameTime(frame);
    for (const auto& character : characters)
        for (const auto& capsule : character.getCapsulesAt(time))
            out.push_back({capsule, character.material, character.name});
    return out;
}

std::uint64_t Scene::getEditStateKey(int frame) const
{
    std::uint64_t key = 0;
    for (const auto& model : sdfModels)
        for (const auto& edit : model.edits)
            key += edit.frame <= frame ? 1 : 0;
    return key;
}

RenderScene Scene::buildRenderScene(int frame) const
{
    const std::vector<SdfMesh> sdf = meshSdfModels(frame);
    const std::vector<PosedCapsule> capsules = poseCharacters(frame);
    return assembleRenderScene(sdf, capsules, frame);
}

RenderScene Scene::assembleRenderScene(const std::vector<SdfMesh>& sdfMeshes, const std::vector<PosedCapsule>& capsules,
                                       int frame) const
{
    RenderScene out = assembleStaticGeometry(sdfMeshes);
    appendCharacters(out, capsules);
    if (out.indices.empty())
        throw Error("scene '" + name + "' has no triangles at frame " + std::to_string(frame) +
                    "; a scene needs at least one mesh, SDF model or character");
    return out;
}

namespace {

// `owner()` names what uses material m, built only for the error.
template <class Owner>
std::uint32_t checkMaterial(const RenderScene& out, const std::string& scene, std::uint32_t m, const Owner& owner)
{
    if (m >= out.materials.size())
        throw Error("scene '" + scene + "': " + owner() + " uses material " + std::to_string(m) +
                    " but the scene has " + std::to_string(out.materials.size()));
    return m;
}

} // namespace

RenderScene Scene::assembleStaticGeometry(const std::vector<SdfMesh>& sdfMeshes) const
{
    RenderScene out;
    out.materials = materials;
    if (out.materials.empty())
        out.materials.push_back(Material{"default"});
    out.pointLights = pointLights;
    out.sky = sky;
    for (const auto& mesh : meshes) {
        const auto base = std::uint32_t(out.positions.size());
        out.positions.insert(out.positions.end(), mesh.positions.begin(), mesh.positions.end());
        if (mesh.normals.size() == mesh.positions.size()) {
            out.normals.insert(out.normals.end(), mesh.normals.begin(), mesh.normals.end());
        } else {
            std::vector<glm::vec3> n;
            computeMissingNormals(mesh, n);
            out.normals.insert(out.normals.end(), n.begin(), n.end());
        }
        for (auto i : mesh.indices)
            out.indices.push_back(base + i);
        for (std::size_t t = 0; t < mesh.indices.size() / 3; ++t)
            out.triangleMaterial.push_back(checkMaterial(out, name,
                                                         t < mesh.triangleMaterial.size() ? mesh.triangleMaterial[t] : 0,
                                                         [&] { return "mesh '" + mesh.name + "'"; }));
    }
    for (std::size_t k = 0; k < sdfMeshes.size(); ++k) {
        const SdfMesh& m = sdfMeshes[k];
        const auto owner = [&] {
            return "SDF model '" + (k < sdfModels.size() ? sdfModels[k].name : std::string("?")) + "'";
        };
        const auto base = std::uint32_t(out.positions.size());
        out.positions.insert(out.positions.end(), m.mesh.positions.begin(), m.mesh.positions.end());
        out.normals.insert(out.normals.end(), m.mesh.normals.begin(), m.mesh.normals.end());
        for (auto i : m.mesh.indices)
            out.indices.push_back(base + i);
        for (auto mat : m.triangleMaterial)
            out.triangleMaterial.push_back(checkMaterial(out, name, mat, owner));
    }
    out.updateBounds();
    return out;
}

void Scene::appendCharacters(RenderScene& out, const std::vector<PosedCapsule>& capsules) const
{
    const std::size_t first = out.positions.size();
    for (const auto& c : capsules)
        appendCapsule(out, c.capsule,
                      checkMaterial(out, name, c.material, [&] { return "character '" + c.character + "'"; }));
    // The bounds are a min and max: extending them over the new vertices is what recomputing
    // them over all gives.
    if (first == 0) {
        out.updateBounds();
        return;
    }
    for (std::size_t i = first; i < out.positions.size(); ++i) {
        out.boundsMin = glm::min(out.boundsMin, out.positions[i]);
        out.boundsMax = glm::max(out.boundsMax, out.positions[i]);
    }
}

} // namespace rtlab::scene
