#pragma once
// The view-space inputs of screen-space techniques made on the GPU from the G-buffer that
// GBufferPass leaves there: an R32Float linear depth and an RGBA32Float view-space normal image
// (zero where there is no surface), the layout Vulkan occlusion techniques bind
// (plugin::OcclusionInput::gpuLinearDepth, gpuNormal). No CPU copy of the G-buffer is made.
//
//   render::ViewInputsPass pass(ctx);
//   pass.run(gbufferPass.getTarget(), viewMatrix);
//   bind pass.getDepth() and pass.getNormal()

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

    //! Copies attachments 0 (position + linear depth) and 1 (normal) of `gbuffer` and writes the
    //! two images (created or resized to the target's size). `view` is world -> view.
    gpu::RunResult run(const gpu::RenderTarget& gbuffer, const glm::mat4& view);
    const gpu::Image& getDepth() const;
    const gpu::Image& getNormal() const;

private:
    struct State;
    std::unique_ptr<State> mState;
};

} // namespace rtlab::render
