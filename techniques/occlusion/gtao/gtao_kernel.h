#pragma once
// What one GTAO frame needs besides the G-buffer images: the constants shared by the C++ estimator
// and the compute shader (the shader's push-constant block has this exact layout), and the C++
// estimator itself.

#include "gtao.h"

#include "core/image.h"
#include "families/occlusion/occlusion.h"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstdint>

namespace rtlab::occlusion {

//! Flag bits of GtaoFrameConstants::flags.
inline constexpr std::uint32_t kGtaoFlagNormalize = 1u;    //!< GtaoSettings::normalize
inline constexpr std::uint32_t kGtaoFlagSphereExtent = 2u; //!< GtaoSearchExtent::Sphere

//! Per-frame constants; layout = the push-constant block of shaders/gtao.comp (std430).
struct GtaoFrameConstants {
    glm::vec2 projScale{1.0f};       //!< (p[0][0], p[1][1]) of the projection
    glm::vec2 projOffset{0.0f};      //!< (p[2][0], p[2][1]): jitter
    glm::vec2 size{1.0f};            //!< image size, px
    float radius = 1.0f;             //!< world units; may be +inf
    float falloffStart = 1.0f;       //!< world units: full weight up to here; +inf for radius +inf
    float falloffScale = 0.0f;       //!< 1 / (falloff_fraction * radius); 0 for a hard cutoff
    float maxPixelRadius = 256.0f;   //!< px
    float sliceAngle = 1.0f;         //!< pi / slices, radians
    float temporalRotation = 0.0f;   //!< kTemporalRotations entry of this frame
    float temporalStepOffset = 0.0f; //!< kTemporalStepOffsets entry of this frame
    std::int32_t slices = 2;
    std::int32_t steps = 8;
    std::uint32_t flags = 0; //!< kGtaoFlag* bits
};
static_assert(sizeof(GtaoFrameConstants) == 64, "must match the push constants of gtao.comp");

//! The constants of one frame of an image of `width` x `height` pixels.
GtaoFrameConstants makeGtaoFrameConstants(const GtaoSettings& settings,
                                          const plugin::OcclusionInput& input, int width,
                                          int height);

//! The C++ estimator (TBB over rows): fills out.ambient, out.bentNormal, out.coneAperture.
//! Each pixel depends only on the inputs, so the result does not depend on the thread count.
void computeGtaoCpu(const GtaoFrameConstants& constants, const Image<float>& depth,
                    const Image<glm::vec3>& normal, plugin::OcclusionOutput& out);

} // namespace rtlab::occlusion
