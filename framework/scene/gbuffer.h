#pragma once
// The G-buffer of one frame: what screen-space techniques read and the points ground truth is
// traced from. Row 0 is the top of the image.

#include "core/image.h"
#include "scene/camera.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <limits>

namespace rtlab::scene {

constexpr std::uint32_t kNoMaterial = std::numeric_limits<std::uint32_t>::max();

struct GBuffer {
    int width = 0;
    int height = 0;
    Camera camera;
    glm::vec2 jitter{0.0f};     //!< sub-pixel offset of the sample position, pixels, in [-0.5, 0.5]
    glm::mat4 view{1.0f};       //!< world -> view
    glm::mat4 projection{1.0f}; //!< view -> clip (Vulkan conventions), jitter included

    Image<float> depth;             //!< linear view-space depth (distance along -z), inf = no surface
    Image<glm::vec3> position;      //!< world position of the surface seen through the pixel sample
    Image<glm::vec3> normal;        //!< world-space unit shading normal, zero where no surface
    Image<glm::vec3> albedo;        //!< diffuse albedo
    Image<glm::vec3> emission;      //!< emitted radiance
    Image<std::uint32_t> materialId;  //!< index into RenderScene::materials, kNoMaterial for sky

    bool hasSurface(int x, int y) const { return materialId.at(x, y) != kNoMaterial; }
};

} // namespace rtlab::scene
