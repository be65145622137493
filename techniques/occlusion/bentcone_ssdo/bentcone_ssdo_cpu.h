#pragma once
// The plain C++ path of bentcone_ssdo and the per-frame constants that both paths share.

#include "bentcone_ssdo_math.h"

#include "core/image.h"
#include "families/occlusion/occlusion.h"
#include "plugin/screen_space.h"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <vector>

namespace rtlab::bentcone_ssdo {

//! The technique's parameters after clamping.
struct Settings {
    float radius = 0.5f;      //!< world units, [0, kMaxRadius]
    int sampleCount = 16;     //!< [kMinSamples, kMaxSamples]
    float depthBias = 0.002f; //!< fraction of the sample's linear depth
    ConeIntersection coneIntersection = ConeIntersection::Exact;
};

//! Largest radius: samples 1e9 world units away are off screen for any camera in rtlab.
constexpr double kMaxRadius = 1.0e9;

//! What one frame's pixels share, computed once on the CPU in float and given to both paths
//! (the GPU gets it through a storage buffer and push constants) so that they agree bit for bit.
struct FrameSetup {
    Settings settings;
    plugin::ScreenProjection projection;
    int width = 0;
    int height = 0;
    std::vector<glm::vec4> pattern;                     //!< makeSamplePattern(sampleCount)
    std::vector<glm::vec4> apertureTable;               //!< makeApertureTable(sampleCount)
    std::array<glm::vec2, kCellCount> rotations{};      //!< makeCellRotations(frameIndex)
    std::array<glm::vec3, kConeCount> coneDirections{}; //!< getConeDirections() in view space
};

//! Builds the frame's constants from the input (size, projection, view, frame index).
FrameSetup makeFrameSetup(const Settings& settings, const std::vector<glm::vec4>& pattern,
                          const std::vector<glm::vec4>& apertureTable,
                          const plugin::OcclusionInput& input);

//! Everything the technique computes for one pixel.
struct PixelResult {
    glm::vec4 sh{0.0f};         //!< (L00, L1-1, L10, L11) of V(w) max(cos, 0), view space
    float ambient = 1.0f;       //!< cosine-weighted visible fraction A
    glm::vec3 bentNormal{0.0f}; //!< view space, unit; zero where there is no surface
    float aperture = 0.0f;      //!< radians, sin^2 = A; 0 where there is no surface
    std::array<float, kConeCount> coneVisibility{}; //!< 1 where there is no surface
    int visibleSamples = 0;
    bool hasSurface = false;
};

//! Whether a depth value is a surface: finite and > 0 (inf and NaN are sky).
bool isSurfaceDepth(float depth);

//! The estimator at pixel (x, y). Exposed for the tests.
PixelResult shadePixel(const FrameSetup& frame, const Image<float>& depth,
                       const Image<glm::vec3>& normal, int x, int y);

//! The whole image, TBB-parallel over rows; fills every field of `out`.
void computeOnCpu(const FrameSetup& frame, const plugin::OcclusionInput& input,
                  plugin::OcclusionOutput& out);

} // namespace rtlab::bentcone_ssdo
