#pragma once
// Shared screen-space geometry for techniques that read a G-buffer: pixel <-> view-space
// conversions that honour the projection's jitter, so every technique reconstructs the very
// positions the rasteriser produced. The GLSL twin is framework/render/shaders/screen_space.glsl.
//
// Conventions (scene/gbuffer.h): pixel (x, y) covers [x, x+1) x [y, y+1), row 0 at the top; its
// sample is at (x + 0.5, y + 0.5) + jitter, which the projection matrix already encodes. View space
// looks down -z; linear depth d = -z.

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace rtlab::plugin {

//! The four projection terms screen-space code needs (Vulkan clip space, y flipped in p11).
struct ScreenProjection {
    glm::vec2 scale{1.0f};   //!< (p[0][0], p[1][1])
    glm::vec2 offset{0.0f};  //!< (p[2][0], p[2][1]): jitter (and any off-centre shift)
    glm::vec2 size{1.0f};    //!< image size in pixels

    static ScreenProjection fromMatrix(const glm::mat4& projection, int width, int height)
    {
        return {{projection[0][0], projection[1][1]}, {projection[2][0], projection[2][1]},
                {float(width), float(height)}};
    }

    //! View-space position of the point at continuous pixel coordinate `pixel` (pixel centres are
    //! at +0.5) with linear depth `depth`: ndc = (x_view * scale + z_view * offset) / -z_view.
    glm::vec3 toView(glm::vec2 pixel, float depth) const
    {
        const glm::vec2 ndc = 2.0f * pixel / size - 1.0f;
        return {depth * (ndc.x + offset.x) / scale.x, depth * (ndc.y + offset.y) / scale.y, -depth};
    }

    //! Continuous pixel coordinate where view-space point `p` (p.z < 0) projects.
    glm::vec2 toPixel(const glm::vec3& p) const
    {
        const float depth = -p.z;
        const glm::vec2 ndc(p.x * scale.x / depth - offset.x, p.y * scale.y / depth - offset.y);
        return (ndc + 1.0f) * 0.5f * size;
    }

    //! Pixels covered by a world-space length `worldLength` seen at linear depth `depth`
    //! (horizontally): the screen-space radius of a sphere of that radius.
    float toPixelLength(float worldLength, float depth) const
    {
        return worldLength * scale.x * 0.5f * size.x / depth;
    }
};

} // namespace rtlab::plugin
