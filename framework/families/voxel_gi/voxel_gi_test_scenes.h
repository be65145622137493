#pragma once
// Small scenes for the voxel_gi tests: boxes (outward or inward facing), quads, rooms; and a
// technique made from its own registration function (a technique's test links only itself).

#include "core/error.h"
#include "core/image.h"
#include "families/voxel_gi/voxel_gi.h"
#include "plugin/technique.h"
#include "scene/gbuffer.h"
#include "scene/render_scene.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace rtlab::voxelgi::testing {

//! Appends a material and returns its index.
inline std::uint32_t addMaterial(scene::RenderScene& s, glm::vec3 albedo, glm::vec3 emission = {})
{
    s.materials.push_back({"m" + std::to_string(s.materials.size()), albedo, emission});
    return std::uint32_t(s.materials.size() - 1);
}

//! Appends the axis-aligned box [lo, hi] as 12 triangles, normals outward (`inward` flips them).
inline void addBox(scene::RenderScene& s, glm::vec3 lo, glm::vec3 hi, std::uint32_t material,
                   bool inward = false)
{
    const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {lo.x, hi.y, lo.z},
                            {hi.x, hi.y, lo.z}, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z},
                            {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}};
    // Quads (counter-clockwise seen from outside) with their outward normals.
    const int quads[6][4] = {{1, 3, 7, 5}, {0, 4, 6, 2}, {2, 6, 7, 3},
                             {0, 1, 5, 4}, {4, 5, 7, 6}, {0, 2, 3, 1}};
    const glm::vec3 normals[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int q = 0; q < 6; ++q) {
        const std::uint32_t base = std::uint32_t(s.positions.size());
        for (int k = 0; k < 4; ++k) {
            s.positions.push_back(c[quads[q][k]]);
            s.normals.push_back(inward ? -normals[q] : normals[q]);
        }
        const std::uint32_t tri[2][3] = {{0, 1, 2}, {0, 2, 3}};
        for (const auto& t : tri) {
            if (inward) {
                s.indices.insert(s.indices.end(), {base + t[0], base + t[2], base + t[1]});
            } else {
                s.indices.insert(s.indices.end(), {base + t[0], base + t[1], base + t[2]});
            }
            s.triangleMaterial.push_back(material);
        }
    }
    s.updateBounds();
}

//! A horizontal quad at height y over [x0, x1] x [z0, z1], normal +y.
inline void addFloor(scene::RenderScene& s, float y, float x0, float x1, float z0, float z1,
                     std::uint32_t material)
{
    const std::uint32_t base = std::uint32_t(s.positions.size());
    s.positions.insert(s.positions.end(), {{x0, y, z0}, {x0, y, z1}, {x1, y, z1}, {x1, y, z0}});
    for (int k = 0; k < 4; ++k)
        s.normals.push_back({0, 1, 0});
    s.indices.insert(s.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    s.triangleMaterial.insert(s.triangleMaterial.end(), {material, material});
    s.updateBounds();
}

//! A closed room: the inside of [lo, hi] with walls `thickness` thick (solid: an outer box and
//! an inner box facing inward).
inline void addRoom(scene::RenderScene& s, glm::vec3 lo, glm::vec3 hi, float thickness,
                    std::uint32_t material)
{
    addBox(s, lo - thickness, hi + thickness, material, false);
    addBox(s, lo, hi, material, true);
}

//! A closed room [-0.4, 0.4]^3 (walls 0.1) with a box on its floor at x in [x, x + 0.13]: moving
//! `x` is an edit (triangles removed and added), as a dig is.
inline scene::RenderScene makeRoomWithBox(float x, glm::vec3 emission = {})
{
    scene::RenderScene s;
    const auto m = addMaterial(s, {0.6f, 0.5f, 0.4f}, emission);
    addRoom(s, glm::vec3(-0.4f), glm::vec3(0.4f), 0.1f, m);
    addBox(s, glm::vec3(x, -0.4f, -0.2f), glm::vec3(x + 0.13f, -0.27f, -0.05f), m);
    return s;
}

//! A room open to the sky on two sides around `offset`, a box inside, a point light: sky, point
//! light and both bounces all contribute (the Vulkan gathers' parity scene).
inline scene::RenderScene makeOpenRoom(glm::vec3 offset)
{
    scene::RenderScene s;
    const auto white = addMaterial(s, glm::vec3(0.7f));
    const auto red = addMaterial(s, {0.7f, 0.1f, 0.1f});
    addBox(s, offset + glm::vec3(-1.2f, -1.2f, -1.2f), offset + glm::vec3(1.2f, -1.0f, 1.2f), white);
    addBox(s, offset + glm::vec3(-1.2f, -1.0f, -1.2f), offset + glm::vec3(-1.0f, 1.0f, 1.2f), red);
    addBox(s, offset + glm::vec3(-1.0f, -1.0f, -1.2f), offset + glm::vec3(1.2f, 1.0f, -1.0f), white);
    addBox(s, offset + glm::vec3(-0.3f, -1.0f, -0.4f), offset + glm::vec3(0.2f, -0.3f, 0.1f), white);
    s.pointLights.push_back({offset + glm::vec3(0.5f, 0.6f, 0.3f), glm::vec3(2.0f)});
    s.sky.kind = scene::Sky::Kind::Constant;
    s.sky.constant = glm::vec3(0.5f, 0.6f, 0.8f);
    return s;
}

using ParamOverrides = std::vector<std::pair<std::string, config::ParamValue>>;

//! The voxel_gi technique `name` registered by `registerTechnique`, at its defaults changed by
//! `overrides`.
inline std::unique_ptr<plugin::Technique> createTechnique(void (*registerTechnique)(plugin::Registry&),
                                                          const std::string& name,
                                                          const ParamOverrides& overrides = {})
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    registerTechnique(registry);
    const auto* entry = registry.findTechnique("voxel_gi", name);
    if (entry == nullptr)
        throw Error("createTechnique: no voxel_gi technique " + name);
    auto params = config::ParamSet::defaultsOf(entry->schema);
    for (const auto& [key, value] : overrides)
        params.set(key, value);
    return entry->create(params);
}

//! One frame of a voxel_gi technique: voxelize and inject `frame` (its geometry the scene), then
//! gather at the G-buffer's pixels.
inline Image<glm::vec3> runVoxelGiFrame(plugin::VoxelGiTechnique& gi,
                                        const plugin::VoxelGiFrame& frame, const scene::GBuffer& g)
{
    gi.voxelize(frame);
    gi.injectLight(frame);
    plugin::VoxelGiInput input;
    input.gbuffer = &g;
    input.scene = frame.geometry;
    Image<glm::vec3> e;
    gi.gather(input, e);
    return e;
}

} // namespace rtlab::voxelgi::testing
