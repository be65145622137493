// A scene of the configurations screen-space occlusion gets wrong, plus one with a closed form.
//  - creases: a floor meeting a wall at 90 degrees, and a 60-degree V groove;
//  - thin occluders: a 2 cm plate floating 0.3 m above the floor, and a thin pole;
//  - depth discontinuities: a box standing 2 m in front of the back wall;
//  - closed form: the floor in front of the tall wall at x = 4. For a floor point at distance d
//    from an infinitely high and long wall, cosine-weighted AO with radius r is
//      1 - (acos(t) - t sqrt(1 - t^2)) / pi,  t = min(1, d / r),
//    because cosine-weighted directions project to a uniform disk and the wall blocks the part
//    of the disk with x > t. The wall here is 40 m high and 60 m long, so for d, r << 20 m the
//    formula holds to well under the reference's noise.

#include "scene/procedural.h"

#include <glm/gtc/constants.hpp>

namespace rtlab::scene {

Scene makeAoTestbed()
{
    Scene s;
    s.materials = {{"grey", glm::vec3(0.6f), glm::vec3(0.0f)}};
    MeshInstance m{.name = "testbed"};
    // Floor and the closed-form wall (facing -x, toward the floor).
    appendQuad(m, {-30, 0, -30}, {4, 0, -30}, {4, 0, 30}, {-30, 0, 30}, 0, {0, 1, 0});
    appendQuad(m, {4, 0, -30}, {4, 40, -30}, {4, 40, 30}, {4, 0, 30}, 0, {3, 1, 0});
    // 90-degree crease: a back wall.
    appendQuad(m, {-30, 0, -6}, {4, 0, -6}, {4, 6, -6}, {-30, 6, -6}, 0, {0, 1, 0});
    // 60-degree V groove cut as two slanted quads rising from a line on the floor at x = -6.
    const float s60 = std::sin(glm::radians(60.0f)), c60 = std::cos(glm::radians(60.0f));
    appendQuad(m, {-6, 0, -2}, {-6, 0, 2}, {-6 - c60, s60, 2}, {-6 - c60, s60, -2}, 0, {-5, 1, 0});
    appendQuad(m, {-6, 0, -2}, {-6, 0, 2}, {-6 + c60, s60, 2}, {-6 + c60, s60, -2}, 0, {-7, 1, 0});
    // Thin occluders: a floating plate and a pole.
    appendBox(m, {-2.0f, 0.3f, -1.0f}, {-1.0f, 0.32f, 0.0f}, 0);
    appendBox(m, {0.0f, 0.0f, 1.0f}, {0.03f, 2.0f, 1.03f}, 0);
    // Depth discontinuity: a box 2 m in front of the back wall.
    appendBox(m, {-3.0f, 0.0f, -4.0f}, {-2.0f, 1.0f, -3.0f}, 0);
    s.meshes.push_back(std::move(m));
    s.sky.kind = Sky::Kind::Constant;
    s.sky.constant = glm::vec3(1.0f);
    s.camera.position = {-2.0f, 3.0f, 6.0f};
    s.camera.target = {-1.0f, 0.3f, -2.0f};
    s.camera.verticalFovDegrees = 60.0f;
    s.camera.farPlane = 100.0f;
    return s;
}

} // namespace rtlab::scene
