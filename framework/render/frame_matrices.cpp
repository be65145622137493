#include "render/frame_matrices.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

namespace rtlab::render {

FrameMatrices computeFrameMatrices(const scene::Camera& camera, int width, int height,
                                   glm::vec2 jitterPixels)
{
    FrameMatrices m;
    m.view = camera.viewMatrix();
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    // Samples at pixel centre + jitter (the image moves by -jitter).
    m.projection = camera.projectionMatrix(aspect, jitterPixels, glm::ivec2(width, height));
    m.cameraPosition = camera.position;
    // Row 2 of the view rotation is view-space +z in world coordinates.
    m.viewForward = -glm::vec3(m.view[0][2], m.view[1][2], m.view[2][2]);
    return m;
}

glm::vec3 computePixelRayDirection(const scene::Camera& camera, int width, int height,
                                   glm::vec2 pixel)
{
    const float aspect = static_cast<float>(width) / static_cast<float>(height);
    const glm::mat4 p = camera.projectionMatrix(aspect);
    // Vulkan NDC: x right, y down, both in [-1, 1] across the image.
    const float ndcX = 2.0f * pixel.x / static_cast<float>(width) - 1.0f;
    const float ndcY = 2.0f * pixel.y / static_cast<float>(height) - 1.0f;
    // A view-space point (x, y, -1) lands at NDC (p00 x, p11 y) (p11 < 0 flips y).
    const glm::vec3 viewDir(ndcX / p[0][0], ndcY / p[1][1], -1.0f);
    const glm::mat3 viewToWorld = glm::transpose(glm::mat3(camera.viewMatrix()));
    return viewToWorld * viewDir;
}

} // namespace rtlab::render
