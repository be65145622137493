// Sharp-feature shapes for isosurface studies: each is its own SDF model (so a study can pick one
// by name), laid out on a grid for rendering. Every shape fits a 1.6 m box around its centre.

#include "scene/procedural.h"

#include <glm/gtc/quaternion.hpp>

#include <cmath>

namespace rtlab::scene {

Scene makeCsgGallery()
{
    Scene s;
    s.materials = {{"clay", glm::vec3(0.7f), glm::vec3(0.0f)}, {"floor", glm::vec3(0.5f), glm::vec3(0.0f)}};
    auto model = [&](const char* name, int slot, std::vector<CsgEdit> edits) {
        const glm::dvec3 c(3.0 * (slot % 4) - 4.5, 0.8, 3.0 * (slot / 4) - 1.5);
        SdfModel m{.name = name};
        for (auto& e : edits) {
            e.center += c;
            m.edits.push_back(e);
        }
        m.boundsMin = c - glm::dvec3(0.8);
        m.boundsMax = c + glm::dvec3(0.8);
        m.resolution = 64;
        s.sdfModels.push_back(std::move(m));
    };
    // Spelled out: a value-initialised glm quaternion is all zeros, not the identity.
    const glm::dquat kNoRotation(1.0, 0.0, 0.0, 0.0);
    auto edit = [](CsgShape shape, CsgOp op, glm::dvec3 size, glm::dquat rot = glm::dquat(1, 0, 0, 0),
                   glm::dvec3 offset = glm::dvec3(0.0), double blend = 0.0) {
        CsgEdit e;
        e.shape = shape;
        e.op = op;
        e.size = size;
        e.rotation = rot;
        e.center = offset;
        e.blend = blend;
        return e;
    };
    const glm::dquat tilt = glm::angleAxis(glm::radians(30.0), glm::normalize(glm::dvec3(1, 1, 0))) *
                            glm::angleAxis(glm::radians(20.0), glm::dvec3(0, 0, 1));
    model("cube", 0, {edit(CsgShape::Box, CsgOp::Add, glm::dvec3(0.5))});
    model("rotated_cube", 1, {edit(CsgShape::Box, CsgOp::Add, glm::dvec3(0.45), tilt)});
    model("cylinder", 2, {edit(CsgShape::Cylinder, CsgOp::Add, {0.45, 0.6, 0})});
    model("box_minus_sphere", 3, {edit(CsgShape::Box, CsgOp::Add, glm::dvec3(0.5)),
                                  edit(CsgShape::Sphere, CsgOp::Subtract, {0.6, 0, 0}, kNoRotation, {0.35, 0.35, 0.35})});
    model("thin_wall", 4, {edit(CsgShape::Box, CsgOp::Add, {0.6, 0.6, 0.02})});  // 4 cm thick
    model("soft_spheres", 5, {edit(CsgShape::Sphere, CsgOp::Add, {0.35, 0, 0}, kNoRotation, {-0.25, 0, 0}),
                              edit(CsgShape::Sphere, CsgOp::Add, {0.3, 0, 0}, kNoRotation, {0.3, 0.1, 0}, 0.25)});
    model("torus", 6, {edit(CsgShape::Torus, CsgOp::Add, {0.5, 0.18, 0})});
    // Chamfered cube: a cube intersected with three slabs rotated 45 degrees about x, y and z,
    // which cut its twelve edges into 45-degree chamfers of width 0.15 on each face.
    const double h = 0.5, chamfer = 0.15;
    const double a = (2.0 * h - chamfer) / std::sqrt(2.0);
    std::vector<CsgEdit> chamfered = {edit(CsgShape::Box, CsgOp::Add, glm::dvec3(h))};
    chamfered.push_back(edit(CsgShape::Box, CsgOp::Intersect, {1.0, a, a}, glm::angleAxis(glm::radians(45.0), glm::dvec3(1, 0, 0))));
    chamfered.push_back(edit(CsgShape::Box, CsgOp::Intersect, {a, 1.0, a}, glm::angleAxis(glm::radians(45.0), glm::dvec3(0, 1, 0))));
    chamfered.push_back(edit(CsgShape::Box, CsgOp::Intersect, {a, a, 1.0}, glm::angleAxis(glm::radians(45.0), glm::dvec3(0, 0, 1))));
    model("chamfered_cube", 7, chamfered);

    MeshInstance floor{.name = "floor"};
    appendQuad(floor, {-7, 0, -4}, {7, 0, -4}, {7, 0, 4}, {-7, 0, 4}, 1, {0, 1, 0});
    s.meshes.push_back(std::move(floor));
    s.sky.kind = Sky::Kind::Gradient;
    s.sky.zenith = glm::vec3(1.0f);
    s.sky.horizon = glm::vec3(0.6f);
    s.sky.ground = glm::vec3(0.2f);
    s.camera.position = {0.0f, 4.5f, 9.0f};
    s.camera.target = {0.0f, 0.6f, 0.0f};
    s.camera.verticalFovDegrees = 45.0f;
    s.camera.farPlane = 40.0f;
    return s;
}

} // namespace rtlab::scene
