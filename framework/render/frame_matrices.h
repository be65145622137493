#pragma once
// View and projection of one frame, with sub-pixel jitter, in the convention of scene::GBuffer:
// the sample of pixel (x, y) lies at (x + 0.5 + jitter.x, y + 0.5 + jitter.y) in pixel
// coordinates (x right, y down, row 0 at the top).

#include "scene/camera.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace rtlab::render {

//! The matrices of one frame.
struct FrameMatrices {
    glm::mat4 view{1.0f};           //!< world -> view (camera at the origin looking down -z)
    glm::mat4 projection{1.0f};     //!< view -> Vulkan clip space, jitter included
    glm::vec3 cameraPosition{0.0f}; //!< world units
    glm::vec3 viewForward{0.0f, 0.0f, -1.0f}; //!< unit world direction of view-space -z
};

//! The matrices for `camera` at `width` x `height` pixels with the sample offset `jitterPixels`.
FrameMatrices computeFrameMatrices(const scene::Camera& camera, int width, int height,
                                   glm::vec2 jitterPixels);

//! The world-space direction (not normalised) of the ray through pixel coordinates `pixel`
//! (x right, y down, in pixels; a pixel centre is at +0.5) of an unjittered frame.
glm::vec3 computePixelRayDirection(const scene::Camera& camera, int width, int height,
                                   glm::vec2 pixel);

} // namespace rtlab::render
