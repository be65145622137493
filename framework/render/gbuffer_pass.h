#pragma once
// The G-buffer, rasterised with Vulkan. A GBufferPass keeps the uploaded scene, the pipeline and
// the render target between frames, so repeated frames only record, submit and read back.
//
//   render::GBufferPass pass(ctx);
//   pass.setScene(renderScene);
//   scene::GBuffer g = pass.render(camera, 1280, 720, jitter);
//   std::optional<double> ms = pass.getLastGpuMs(); // the draw, from GPU timestamps
//
// What each pixel holds (evaluated at its sample, the pixel centre moved by the jitter, see
// render/frame_matrices.h; single sample, no anti-aliasing):
//   depth      linear view-space depth (distance along the view direction), +inf without surface
//   position   world position; zero without surface
//   normal     interpolated shading normal, normalised, negated on triangles seen from their back
//              (clockwise on screen; the scene's triangles are counter-clockwise seen from the
//              front), so it faces the viewer's side of the surface; zero without surface
//   albedo, emission   of the triangle's material; zero without surface
//   materialId index into RenderScene::materials, scene::kNoMaterial without surface
// Triangles are drawn from both sides (no culling). Geometry closer than Camera::nearPlane or
// farther than Camera::farPlane is clipped away.

#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "render/frame_matrices.h"
#include "scene/camera.h"
#include "scene/gbuffer.h"
#include "scene/render_scene.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <filesystem>
#include <memory>
#include <optional>
#include <string_view>

namespace rtlab::render {

//! The push constants of gbuffer.vert/.frag (shaders/gbuffer_frame.glsl).
struct GBufferFrameConstants {
    glm::mat4 relativeViewProjection{1.0f}; //!< projection * view rotation
    glm::vec4 cameraPosition{0.0f};         //!< xyz: world units
    glm::vec4 viewForward{0.0f};            //!< xyz: unit world direction of view-space -z
};
static_assert(sizeof(GBufferFrameConstants) == 96, "must match gbuffer_frame.glsl");

//! Settings of a GBufferPass.
struct GBufferPassOptions {
    gpu::ShaderCompilerOptions compiler; //!< SPIR-V cache etc.; the shader dir is searched too
};

//! Directory of the pass's shaders: $RTLAB_SOURCE_DIR/framework/render/shaders when that
//! variable is set, otherwise the one of the source tree the library was built from.
std::filesystem::path getRenderShaderDir();

//! Renders G-buffers of one scene on one Context. Move-only; the Context must outlive it.
class GBufferPass {
public:
    //! Label of the draw in gpu::RunResult.
    static constexpr std::string_view kDrawLabel = "gbuffer";

    //! Compiles the shaders (through the SPIR-V cache) and creates the pipeline. Throws
    //! rtlab::Error when the device cannot draw.
    explicit GBufferPass(gpu::Context& context, GBufferPassOptions options = {});
    ~GBufferPass();
    GBufferPass(GBufferPass&&) noexcept;
    GBufferPass& operator=(GBufferPass&&) noexcept;

    //! Validates and uploads `scene` (see render/gbuffer_geometry.h); replaces any earlier
    //! scene. A scene with as many vertices and indices as the last one (a character moved)
    //! uploads only the span of them that differs (gpu/bus_counters.h counts it), unless
    //! `patch` is false (new buffers, everything uploaded). Throws rtlab::Error for an
    //! inconsistent scene.
    void setScene(const scene::RenderScene& scene, bool patch = true);
    bool hasScene() const;
    //! Vertices uploaded for the scene (its vertices plus those split off for materials).
    std::size_t getVertexCount() const;

    //! Draws a frame into the GPU render target (created or resized as needed) and returns the
    //! run's timings. Throws rtlab::Error without a scene or for a size < 1.
    gpu::RunResult draw(const scene::Camera& camera, int width, int height,
                        glm::vec2 jitterPixels = glm::vec2(0.0f));
    //! Draws a frame into `target`, a render target the caller owns (e.g. the frame graph's,
    //! pipeline/frame_start.h), made from makeTargetDesc(); it must outlive its use by readBack()
    //! and getTarget(). Throws rtlab::Error without a scene or for another kind of target.
    gpu::RunResult draw(const gpu::RenderTarget& target, const scene::Camera& camera,
                        glm::vec2 jitterPixels = glm::vec2(0.0f));
    //! The attachments (see getTarget()) of a G-buffer of width x height. Throws rtlab::Error for
    //! a size < 1.
    static gpu::RenderTargetDesc makeTargetDesc(int width, int height);
    //! Reads back the frame of the last draw(). Throws rtlab::Error before the first.
    scene::GBuffer readBack() const;
    //! draw() then readBack().
    scene::GBuffer render(const scene::Camera& camera, int width, int height,
                          glm::vec2 jitterPixels = glm::vec2(0.0f));

    //! GPU time of the last draw in milliseconds; empty before the first or without timestamps.
    std::optional<double> getLastGpuMs() const;
    //! The render target of the last draw: attachments 0 (world position, linear depth),
    //! 1 (normal), 2 (albedo), 3 (emission) RGBA32F, 4 (material id) R32Uint, and D32 depth.
    const gpu::RenderTarget& getTarget() const;

private:
    struct State;
    std::unique_ptr<State> mState;
};

//! One-off convenience: a GBufferPass for `scene` rendering one frame.
scene::GBuffer renderGBuffer(gpu::Context& context, const scene::RenderScene& scene,
                             const scene::Camera& camera, int width, int height,
                             glm::vec2 jitterPixels = glm::vec2(0.0f),
                             const GBufferPassOptions& options = {});

} // namespace rtlab::render
