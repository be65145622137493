#pragma once
// The lit HDR frame, composed on the GPU from the G-buffer that GBufferPass leaves there (no
// read-back to the CPU): point lights with cube shadow maps, the sky through 16 lobes with an
// optional per-pixel visibility, emission, and an optional indirect irradiance, then exposure,
// a tonemapper and sRGB encoding.
// Seed: shared/seeds/000_3da000e866ebc485.txt (The Tomorrow Children, GDC 2015): sky light as
// 16 SRBFs on the 16 cone directions; screen-space directional occlusion as a visibility per
// cone direction that "modulate[s] the incoming light" of each cone in the final combine.
//
//   render::LightingPass lighting(ctx);
//   gbufferPass.draw(camera, w, h, jitter);
//   shadowPass.render(scene);
//   render::LightingInputs in{&gbufferPass.getTarget(), camera, jitter, &shadowPass};
//   gpu::RunResult r = lighting.draw(scene, in);
//   Image<glm::vec3> hdr = lighting.readBackHdr();
//
// Per pixel with a surface (x = G-buffer position, n = its normal as stored, rho = albedo):
//   E_lights = Sum_i I_i max(0, n . l_i) / max(d_i, minLightDistance)^2 * shadow_i
//   E_sky    = Sum_k V_k L_k I(n . a_k)           (render/sky_irradiance.h)
//              or, with LightingInputs::coneSkyIrradiance, that image: the sky and the emissive
//              surfaces seen through a voxel GI technique's 16 cones (Sum_k w_k(n) V_k
//              (T_k Lsky_k + Le_k), families/voxel_gi/pixel_cones.h), as the Tomorrow Children
//              lit pixels ("Sky Light": the sky gathered along the cones through the cascades)
//   direct   = rho / pi * (E_lights + E_sky)
//   hdr      = Le + direct + rho / pi * E_ind
// V_k is 1 without a visibility input, the pixel's ambient occlusion for every k with
// LightingInputs::ambientOcclusion, and the pixel's cone visibility k with
// LightingInputs::coneVisibility. E_ind comes from LightingInputs::indirectIrradiance and is 0
// without it. Pixels without a surface get hdr = the sky's radiance along the camera ray
// through the pixel's sample and direct = 0 (the conventions of reference/reference.h).
//
// Against the Embree ground truth: reference "direct" also contains light from emissive
// triangles. Without a cone sky this pass does not compute it; with one, the cones' emitters are
// part of E_sky and so of `direct`.
//
// Shadows (shaders/lighting.comp): the receiver moves along n by
//   d * (2 / faceSize) * (normalOffsetTexels + slopeOffsetTexels * sin(theta))
// (d the light distance, 2 / faceSize the largest angle a shadow texel subtends, theta the angle
// between n and the light) and is compared against 3 x 3 texels of the cube map, tent-weighted,
// pcfSpacingTexels apart in face coordinates; each tap chooses its own face, so the filter
// crosses cube edges.
//
// Tonemapping: c = 2^exposureEv * hdr per channel, then either the ACES filmic fit of Narkowicz
// 2015, (c (2.51 c + 0.03)) / (c (2.43 c + 0.59) + 0.14), or Reinhard's c / (1 + c) applied per
// channel (not on luminance), clamped to [0, 1], then the sRGB transfer function. Stored as
// RGBA8Unorm (alpha 1). computeTonemappedColor is the CPU twin.

#include "core/image.h"
#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "render/shadow_pass.h"
#include "render/sky_irradiance.h"
#include "scene/camera.h"
#include "scene/render_scene.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <memory>
#include <optional>
#include <string_view>

namespace rtlab::render {

//! The curve that maps exposed HDR values to [0, 1].
enum class Tonemapper {
    Aces,     //!< Narkowicz 2015 ACES filmic fit, per channel
    Reinhard, //!< x / (1 + x), per channel
};

//! "aces", "reinhard".
const char* getTonemapperName(Tonemapper tonemapper);
//! Inverse of getTonemapperName; throws rtlab::Error naming the valid names.
Tonemapper parseTonemapper(std::string_view name);

//! Exposure and tonemapper.
struct TonemapSettings {
    float exposureEv = 0.0f;                  //!< stops: HDR values are scaled by 2^exposureEv
    Tonemapper tonemapper = Tonemapper::Aces; //!< curve after exposure
};

//! The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
float encodeSrgb(float linear);
//! What the tonemap dispatch writes for `hdr` (before 8-bit quantisation), each channel in
//! [0, 1]; negative and NaN inputs give 0.
glm::vec3 computeTonemappedColor(glm::vec3 hdr, const TonemapSettings& settings);

//! Settings of a LightingPass.
struct LightingPassOptions {
    TonemapSettings tonemap;             //!< used by draw()
    float minLightDistance = 1e-3f;      //!< world units, > 0: 1/d^2 uses max(d, this)
    float pcfSpacingTexels = 1.0f;       //!< between PCF taps, shadow texels, >= 0
    float normalOffsetTexels = 0.5f;     //!< constant part of the normal offset, texels, >= 0
    float slopeOffsetTexels = 2.5f;      //!< part scaled by sin(theta), texels, >= 0
    int skyTableSize = 256;              //!< entries of the lobe-irradiance table, 2..65536
    gpu::ShaderCompilerOptions compiler; //!< SPIR-V cache etc.; the shader dir is searched too
};

//! Where the per-lobe sky visibility V_k comes from.
enum class SkyVisibility {
    None,             //!< V_k = 1
    AmbientOcclusion, //!< V_k = ao of the pixel
    Cones,            //!< V_k = the pixel's visibility of cone k
};

//! What one frame reads. Every pointer must stay valid during draw().
struct LightingInputs {
    const gpu::RenderTarget* gbuffer = nullptr; //!< GBufferPass::getTarget() after its draw()
    scene::Camera camera;                       //!< the camera of that draw
    glm::vec2 jitterPixels{0.0f};               //!< the jitter of that draw
    const ShadowPass* shadows = nullptr; //!< null: no shadows; lights it has not rendered: none
    //! R32Float image of the G-buffer's size: V_k = ao for every k. Null: no occlusion.
    const gpu::Image* ambientOcclusion = nullptr;
    //! Four RGBA32Float images of the G-buffer's size, cone k (in the order of
    //! scene::getConeDirections()) in channel k % 4 of image k / 4: V_k. All null: no occlusion.
    //! Not with ambientOcclusion.
    std::array<const gpu::Image*, 4> coneVisibility{};
    //! RGBA32Float image of the G-buffer's size: incident indirect irradiance (rgb). Null: none.
    const gpu::Image* indirectIrradiance = nullptr;
    //! RGBA32Float image of the G-buffer's size: the irradiance from the sky and from emissive
    //! surfaces that a voxel GI technique's 16 cones gathered past its voxels (rgb), already
    //! multiplied per cone by the visibilities it was given. When set it replaces E_sky (the lobes
    //! and V_k are not used for the sky). Null: E_sky from the lobes as above.
    const gpu::Image* coneSkyIrradiance = nullptr;
    //! Where to write the frame: RGBA32Float images of the G-buffer's size, e.g. created by the
    //! frame graph (pipeline/gpu_resources.h). Null: the pass's own images (getHdr(), getDirect()),
    //! which draw() also tonemaps into getLdr(); with outputs given, call tonemap() yourself.
    const gpu::Image* outHdr = nullptr;
    const gpu::Image* outDirect = nullptr;
};

//! The push constants of lighting.comp.
struct LightingConstants {
    glm::mat4 inverseRelativeViewProjection{1.0f}; //!< clip -> camera-relative world
    glm::vec4 cameraPosition{0.0f};                //!< xyz world units, w: minLightDistance
    glm::uvec4 sizeLightsVisibility{0u};           //!< width, height, light count, SkyVisibility
    glm::uvec4 flags{0u}; //!< x: has indirect, y: shadow face size, z: has cone sky
    glm::vec4 shadowParameters{0.0f};              //!< pcf spacing, normal, slope offsets (texels)
};
static_assert(sizeof(LightingConstants) == 128, "must match lighting.comp");

//! The push constants of tonemap.comp.
struct TonemapConstants {
    float exposureScale = 1.0f; //!< 2^ev
    std::uint32_t tonemapper = 0;
    std::uint32_t width = 0;
    std::uint32_t height = 0;
};
static_assert(sizeof(TonemapConstants) == 16, "must match tonemap.comp");

//! Composes lit frames. Move-only; the Context must outlive it.
class LightingPass {
public:
    //! Label of the copies of the G-buffer attachments into images the dispatch can read.
    static constexpr std::string_view kCopyLabel = "lighting gbuffer copy";
    //! Label of the lighting dispatch (hdr and direct).
    static constexpr std::string_view kLightingLabel = "lighting";
    //! Label of the tonemap dispatch (ldr).
    static constexpr std::string_view kTonemapLabel = "tonemap";

    //! Compiles the shaders and creates the pipelines. Throws rtlab::Error for a bad option.
    explicit LightingPass(gpu::Context& context, LightingPassOptions options = {});
    ~LightingPass();
    LightingPass(LightingPass&&) noexcept;
    LightingPass& operator=(LightingPass&&) noexcept;

    //! Lights the G-buffer of `inputs` with the point lights and sky of `scene` and tonemaps
    //! it, in one submission (copies, lighting, tonemap). The sky's lobes and table are
    //! recomputed only when the sky changed. Throws rtlab::Error without a G-buffer, for inputs
    //! of the wrong size or format, or with both visibility inputs.
    gpu::RunResult draw(const scene::RenderScene& scene, const LightingInputs& inputs);
    //! Tonemaps the hdr image of the last draw() again with other settings.
    gpu::RunResult tonemap(const TonemapSettings& settings);
    //! Tonemaps any 2D RGBA32Float image into getLdr() (resized to it).
    gpu::RunResult tonemap(const gpu::Image& hdr, const TonemapSettings& settings);
    //! The same into `ldr`, an RGBA8Unorm image of hdr's size (not the pass's own getLdr()).
    gpu::RunResult tonemap(const gpu::Image& hdr, const TonemapSettings& settings,
                           const gpu::Image& ldr);

    //! RGBA32Float: emission + direct + sky + indirect (alpha 1). Valid after draw().
    const gpu::Image& getHdr() const;
    //! RGBA32Float: albedo / pi * (point lights + sky), 0 without surface; alpha the luminance
    //! (Rec. 709) of the sky's part, albedo / pi * E_sky.
    const gpu::Image& getDirect() const;
    //! RGBA8Unorm: the tonemapped, sRGB-encoded frame.
    const gpu::Image& getLdr() const;
    Image<glm::vec3> readBackHdr() const;
    Image<glm::vec3> readBackDirect() const;
    //! In [0, 1] (texel / 255).
    Image<glm::vec3> readBackLdr() const;

    //! The sky's lobes of the last draw().
    const SkyLobes& getSkyLobes() const;
    //! The visibility mode and whether an indirect input was used in the last draw().
    SkyVisibility getLastVisibility() const;
    bool hadIndirect() const;
    //! Whether the last draw() took its sky from LightingInputs::coneSkyIrradiance.
    bool hadConeSky() const;
    //! GPU time of the last draw() (copies, lighting, tonemap) or tonemap() in milliseconds;
    //! empty before the first or without timestamps.
    std::optional<double> getLastGpuMs() const;

private:
    struct State;
    std::unique_ptr<State> mState;
};

} // namespace rtlab::render
