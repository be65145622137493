// A game-like scene after the Tomorrow Children talk (shared/seeds/000_3da000e866ebc485.txt):
// a diggable SDF landscape with hills, an overhanging rock arch and a tunnel through a hill; box
// buildings and sign posts with emissive signs; street lamps as point lights; a sky of 16 SRBF
// lobes; three capsule characters walking; digs (CSG subtractions) applied over the frames; and a
// camera path through the town. World units are metres; +y is up.

#include "scene/procedural.h"

#include <glm/gtc/quaternion.hpp>

namespace rtlab::scene {

Scene makeTomorrowTown()
{
    Scene s;
    s.materials = {
        {"ground", glm::vec3(0.45f, 0.42f, 0.36f), glm::vec3(0.0f)},
        {"rock", glm::vec3(0.35f, 0.33f, 0.32f), glm::vec3(0.0f)},
        {"building", glm::vec3(0.7f, 0.68f, 0.62f), glm::vec3(0.0f)},
        {"roof", glm::vec3(0.55f, 0.2f, 0.15f), glm::vec3(0.0f)},
        {"post", glm::vec3(0.2f, 0.2f, 0.22f), glm::vec3(0.0f)},
        {"sign_cyan", glm::vec3(0.1f), glm::vec3(0.2f, 2.5f, 3.0f)},
        {"sign_pink", glm::vec3(0.1f), glm::vec3(3.0f, 0.4f, 1.6f)},
        {"character", glm::vec3(0.6f, 0.55f, 0.5f), glm::vec3(0.0f)},
    };
    constexpr std::uint32_t kGround = 0, kRock = 1, kBuilding = 2, kRoof = 3, kPost = 4, kCyan = 5,
                            kPink = 6, kCharacter = 7;

    // The landscape: a slab of ground, soft-blended hills, an arch (overhang) and a tunnel.
    SdfModel land{.name = "landscape"};
    land.boundsMin = {-16.0, -3.0, -16.0};
    land.boundsMax = {16.0, 7.0, 16.0};
    land.resolution = 128;
    auto edit = [](CsgShape shape, CsgOp op, glm::dvec3 c, glm::dvec3 size, double blend,
                   std::uint32_t material, int frame = 0) {
        CsgEdit e;
        e.shape = shape;
        e.op = op;
        e.center = c;
        e.size = size;
        e.blend = blend;
        e.material = material;
        e.frame = frame;
        return e;
    };
    land.edits.push_back(edit(CsgShape::Box, CsgOp::Add, {0, -1.5, 0}, {15.5, 1.5, 15.5}, 0.0, kGround));
    land.edits.push_back(edit(CsgShape::Ellipsoid, CsgOp::Add, {-8, 0, -7}, {6, 4.5, 5}, 1.5, kGround));
    land.edits.push_back(edit(CsgShape::Ellipsoid, CsgOp::Add, {9, 0, -9}, {5, 3, 4}, 1.5, kGround));
    // The tunnel: a capsule through the big hill along x.
    CsgEdit tunnel = edit(CsgShape::Capsule, CsgOp::Subtract, {-8, 1.2, -7}, {1.3, 7.0, 0}, 0.3, kRock);
    tunnel.rotation = glm::angleAxis(glm::radians(90.0), glm::dvec3(0, 0, 1));
    land.edits.push_back(tunnel);
    // The arch: a rounded rock slab with a hole carved out of its lower part -> an overhang.
    CsgEdit slab = edit(CsgShape::RoundedBox, CsgOp::Add, {6, 2.5, 5}, {3.5, 2.5, 1.2}, 0.5, kRock);
    slab.rounding = 0.4;
    land.edits.push_back(slab);
    CsgEdit hole = edit(CsgShape::Cylinder, CsgOp::Subtract, {6, 0.0, 5}, {2.2, 3.0, 0}, 0.2, kRock);
    hole.rotation = glm::angleAxis(glm::radians(90.0), glm::dvec3(1, 0, 0));
    land.edits.push_back(hole);
    // Digs over frames: craters appear at frames 2, 4 and 6.
    land.edits.push_back(edit(CsgShape::Sphere, CsgOp::Subtract, {-2, 0.2, 6}, {1.6, 0, 0}, 0.3, kGround, 2));
    land.edits.push_back(edit(CsgShape::Sphere, CsgOp::Subtract, {1, 0.2, 8}, {1.2, 0, 0}, 0.3, kGround, 4));
    land.edits.push_back(edit(CsgShape::Sphere, CsgOp::Subtract, {-6.5, 2.5, -3}, {1.4, 0, 0}, 0.3, kGround, 6));
    s.sdfModels.push_back(std::move(land));

    // Buildings and sign posts as triangle meshes.
    MeshInstance town{.name = "town"};
    const glm::vec3 buildings[][2] = {{{-3, 0, -3}, {0, 3.5, 0}}, {{1, 0, -4}, {4, 5, -1}},
                                      {{-12, 0, 4}, {-9, 2.5, 8}}, {{10, 0, 2}, {13, 4, 6}}};
    for (const auto& b : buildings) {
        appendBox(town, b[0], b[1], kBuilding);
        appendBox(town, b[0] + glm::vec3(-0.2f, b[1].y - b[0].y, -0.2f), b[1] + glm::vec3(0.2f, 0.3f, 0.2f), kRoof);
    }
    const glm::vec3 posts[] = {{-4.5f, 0, 1.5f}, {4.5f, 0, 0.5f}, {0, 0, 4}};
    for (int i = 0; i < 3; ++i) {
        const glm::vec3 p = posts[i];
        appendBox(town, p + glm::vec3(-0.08f, 0, -0.08f), p + glm::vec3(0.08f, 2.6f, 0.08f), kPost);
        appendBox(town, p + glm::vec3(-0.7f, 2.2f, -0.05f), p + glm::vec3(0.7f, 2.9f, 0.05f), i % 2 ? kPink : kCyan);
    }
    s.meshes.push_back(std::move(town));

    // Street lamps.
    s.pointLights = {{{-4.0f, 3.0f, 2.5f}, glm::vec3(6.0f, 5.0f, 3.5f)},
                     {{4.0f, 3.0f, 1.5f}, glm::vec3(6.0f, 5.0f, 3.5f)},
                     {{-8.0f, 1.8f, -3.0f}, glm::vec3(3.0f, 3.5f, 5.0f)}};

    // Sky: 16 SRBF lobes, brighter toward the zenith and a warm side (the talk's sky model).
    s.sky.kind = Sky::Kind::Srbf;
    s.sky.sharpness = 3.0f;
    for (int i = 0; i < kConeDirectionCount; ++i) {
        const glm::dvec3 d = getConeDirections()[i];
        const float up = float(std::max(0.0, d.y));
        const float warm = float(std::max(0.0, d.x));
        s.sky.lobes[i] = d.y < -0.2 ? glm::vec3(0.05f) : glm::vec3(0.25f, 0.35f, 0.55f) * (0.4f + up) +
                                                          glm::vec3(0.3f, 0.18f, 0.05f) * warm;
    }

    // Three capsule characters (legs, body, head) walking.
    auto character = [&](const char* name, std::vector<CharacterKey> path) {
        Character c{.name = name, .material = kCharacter};
        c.capsules = {{{-0.12f, 0.15f, 0}, {-0.12f, 0.75f, 0}, 0.1f},
                      {{0.12f, 0.15f, 0}, {0.12f, 0.75f, 0}, 0.1f},
                      {{0, 0.95f, 0}, {0, 1.35f, 0}, 0.25f},
                      {{0, 1.7f, 0}, {0, 1.72f, 0}, 0.2f}};
        c.path = std::move(path);
        s.characters.push_back(std::move(c));
    };
    character("walker_a", {{0.0f, {-5, 0, 3}, 90}, {0.25f, {-3, 0, 3}, 90}});
    character("walker_b", {{0.0f, {3, 0, 2.5f}, -90}, {0.25f, {1.5f, 0, 3}, -70}});
    character("walker_c", {{0.0f, {-1, 0, 6.5f}, 180}, {0.25f, {-1, 0, 5}, 180}});

    s.frameCount = 8;
    s.frameRate = 30.0f;
    s.camera.position = {0.0f, 2.2f, 14.0f};
    s.camera.target = {0.0f, 1.2f, 0.0f};
    s.camera.verticalFovDegrees = 55.0f;
    s.camera.nearPlane = 0.05f;
    s.camera.farPlane = 80.0f;
    std::vector<CameraKeyframe> keys(3);
    keys[0] = {0.0f, s.camera};
    keys[1] = {0.12f, s.camera};
    keys[1].camera.position = {-3.0f, 2.5f, 12.0f};
    keys[2] = {0.25f, s.camera};
    keys[2].camera.position = {-6.0f, 2.8f, 10.0f};
    keys[2].camera.target = {-3.0f, 1.0f, 0.0f};
    s.cameraPath = CameraPath(keys);
    return s;
}

} // namespace rtlab::scene
