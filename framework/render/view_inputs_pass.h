#pragma once
// The view-space inputs of screen-space techniques made on the GPU from the G-buffer that
// GBufferPass leaves there: an R32Float linear depth and an RGBA32Float view-space normal image
// (zero where there is no surface), the layout Vulkan occlusion techniques bind
// (plugin::OcclusionInput::gpuLinearDepth, gpuNormal), and the world-space attachments copied
// into storage images (position + linear depth, normal) for the techniques that work in world
// space (plugin::VoxelGiInput::gpuGBuffer). No CPU copy of the G-buffer is made.
//
//   render::ViewInputsPass pass(ctx);
//   pass.run(gbufferPass.getTarget(), viewMatrix, positionDepth, worldNormal, depth, normal);

#include "gpu/context.h"

#include <glm/mat4x4.hpp>

#include <memory>
#include <string_view>

namespace rtlab::render {

class ViewInputsPass {
public:
    static constexpr std::string_view kLabel = "view_inputs";

    explicit ViewInputsPass(gpu::Context& context);
    ~ViewInputsPass();

    //! Copies attachments 0 (world position + linear depth, inf where no surface) and 1 (world
    //! normal) of `gbuffer` into `positionDepth` and `worldNormal` (RGBA32Float) and writes
    //! `depth` (R32Float) and `normal` (RGBA32Float, view space) from them; all storage images
    //! of the target's size. `view` is world -> view. Throws rtlab::Error for another size or
    //! format.
    gpu::RunResult run(const gpu::RenderTarget& gbuffer, const glm::mat4& view,
                       const gpu::Image& positionDepth, const gpu::Image& worldNormal,
                       const gpu::Image& depth, const gpu::Image& normal);

private:
    struct State;
    std::unique_ptr<State> mState;
};

} // namespace rtlab::render
