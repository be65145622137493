// The Cornell box, from the measured data published by the Cornell Program of Computer Graphics
// (dimensions in millimetres, converted to metres here): a 0.55 m room, red left wall, green
// right wall, two white blocks, and the light in the ceiling. RGB albedos and the light's
// radiance are the values renderers commonly use for this scene (pbrt-v3 and Mitsuba's
// versions): white 0.73, red (0.65, 0.05, 0.05), green (0.12, 0.45, 0.15), light (17, 12, 4).

#include "scene/procedural.h"

namespace rtlab::scene {

Scene makeCornellBox()
{
    Scene s;
    s.materials = {
        {"white", glm::vec3(0.73f), glm::vec3(0.0f)},
        {"red", glm::vec3(0.65f, 0.05f, 0.05f), glm::vec3(0.0f)},
        {"green", glm::vec3(0.12f, 0.45f, 0.15f), glm::vec3(0.0f)},
        {"light", glm::vec3(0.78f), glm::vec3(17.0f, 12.0f, 4.0f)},
    };
    constexpr std::uint32_t kWhite = 0, kRed = 1, kGreen = 2, kLight = 3;
    const float mm = 0.001f;
    auto P = [&](float x, float y, float z) { return glm::vec3(x, y, z) * mm; };
    const glm::vec3 room = P(278, 274, 280);

    MeshInstance box{.name = "room"};
    appendQuad(box, P(552.8f, 0, 0), P(0, 0, 0), P(0, 0, 559.2f), P(549.6f, 0, 559.2f), kWhite, room);        // floor
    appendQuad(box, P(556, 548.8f, 0), P(556, 548.8f, 559.2f), P(0, 548.8f, 559.2f), P(0, 548.8f, 0), kWhite, room);  // ceiling
    appendQuad(box, P(549.6f, 0, 559.2f), P(0, 0, 559.2f), P(0, 548.8f, 559.2f), P(556, 548.8f, 559.2f), kWhite, room);  // back
    appendQuad(box, P(0, 0, 559.2f), P(0, 0, 0), P(0, 548.8f, 0), P(0, 548.8f, 559.2f), kGreen, room);        // right
    appendQuad(box, P(552.8f, 0, 0), P(549.6f, 0, 559.2f), P(556, 548.8f, 559.2f), P(556, 548.8f, 0), kRed, room);  // left
    // The light sits 0.1 mm below the ceiling, facing down.
    appendQuad(box, P(343, 548.7f, 227), P(343, 548.7f, 332), P(213, 548.7f, 332), P(213, 548.7f, 227), kLight, room);
    s.meshes.push_back(std::move(box));

    // The blocks: each face faces away from the block's centre.
    auto block = [&](const char* name, const std::vector<glm::vec3>& top, float height) {
        MeshInstance m{.name = name};
        glm::vec3 centre(0.0f);
        for (const auto& t : top)
            centre += t;
        centre = centre / 4.0f * mm;
        centre.y = height * 0.5f * mm;
        const float h = height * mm;
        std::vector<glm::vec3> t, b;
        for (const auto& v : top) {
            t.push_back(glm::vec3(v.x, height, v.z) * mm);
            b.push_back(glm::vec3(v.x, 0, v.z) * mm);
        }
        appendQuad(m, t[0], t[1], t[2], t[3], kWhite, t[0] + glm::vec3(0, h, 0));
        for (int i = 0; i < 4; ++i) {
            const int j = (i + 1) % 4;
            const glm::vec3 mid = 0.5f * (b[i] + b[j]);
            appendQuad(m, b[i], t[i], t[j], b[j], kWhite, mid + (mid - glm::vec3(centre.x, 0, centre.z)));
        }
        s.meshes.push_back(std::move(m));
    };
    block("short_block", {{130, 0, 65}, {82, 0, 225}, {240, 0, 272}, {290, 0, 114}}, 165);
    block("tall_block", {{423, 0, 247}, {265, 0, 296}, {314, 0, 456}, {472, 0, 406}}, 330);

    // The published camera: at (278, 273, -800) mm looking down +z, 35 mm lens on a 25 mm film:
    // vertical field of view 2 atan(12.5 / 35) = 39.3 degrees.
    s.camera.position = P(278, 273, -800);
    s.camera.target = P(278, 273, 0);
    s.camera.up = {0, 1, 0};
    s.camera.verticalFovDegrees = 39.3f;
    s.camera.nearPlane = 0.01f;
    s.camera.farPlane = 3.0f;
    return s;
}

} // namespace rtlab::scene
