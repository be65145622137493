#include "render/view_inputs_pass.h"

#include "core/error.h"
#include "gpu/format.h"
#include "gpu/shader_compiler.h"
#include "render/gbuffer_pass.h"

namespace rtlab::render {

namespace {

struct Push {
    glm::mat4 view{1.0f};
    std::uint32_t size[4] = {0, 0, 0, 0};
};
static_assert(sizeof(Push) == 80, "must match view_inputs.comp");

constexpr std::uint32_t kGroupSize = 8;

} // namespace

struct ViewInputsPass::State {
    gpu::Context* context = nullptr;
    gpu::ComputePipeline pipeline;
};

ViewInputsPass::ViewInputsPass(gpu::Context& context) : mState(std::make_unique<State>())
{
    mState->context = &context;
    gpu::ShaderCompilerOptions options;
    options.includeDirs.push_back(getRenderShaderDir());
    const gpu::ShaderCompiler compiler(options);
    gpu::ComputePipelineDesc desc;
    desc.name = std::string(kLabel);
    desc.spirv = compiler.compileFile(getRenderShaderDir() / "view_inputs.comp").spirv;
    desc.bindings = {{0, gpu::BindingType::StorageImage},
                     {1, gpu::BindingType::StorageImage},
                     {2, gpu::BindingType::StorageImage},
                     {3, gpu::BindingType::StorageImage}};
    desc.pushConstantSize = sizeof(Push);
    mState->pipeline = context.createPipeline(desc);
}

ViewInputsPass::~ViewInputsPass() = default;

gpu::RunResult ViewInputsPass::run(const gpu::RenderTarget& gbuffer, const glm::mat4& view,
                                   const gpu::Image& positionDepth, const gpu::Image& worldNormal,
                                   const gpu::Image& depth, const gpu::Image& normal)
{
    State& s = *mState;
    const std::uint32_t w = gbuffer.getDesc().width, h = gbuffer.getDesc().height;
    const auto check = [&](const gpu::Image& image, gpu::Format format, const char* what) {
        const gpu::ImageDesc& d = image.getDesc();
        if (d.width != w || d.height != h || d.format != format)
            throw Error(std::string("view inputs: expected ") + what + " of " + std::to_string(w) +
                        "x" + std::to_string(h) + ", found '" + d.name + "' (" +
                        std::to_string(d.width) + "x" + std::to_string(d.height) + ", " +
                        std::string(gpu::getFormatName(d.format)) + ")");
    };
    check(positionDepth, gpu::Format::RGBA32Float, "an RGBA32Float position + depth image");
    check(worldNormal, gpu::Format::RGBA32Float, "an RGBA32Float world normal image");
    check(depth, gpu::Format::R32Float, "an R32Float depth image");
    check(normal, gpu::Format::RGBA32Float, "an RGBA32Float normal image");
    Push push;
    push.view = view;
    push.size[0] = w;
    push.size[1] = h;
    return s.context->run([&](gpu::CommandList& cmd) {
        gpu::copyAttachmentToImage(cmd, gbuffer, 0, positionDepth, 0, "view_inputs copy");
        gpu::copyAttachmentToImage(cmd, gbuffer, 1, worldNormal, 0, "view_inputs copy");
        cmd.dispatch(s.pipeline,
                     {gpu::Binding::storageImage(0, positionDepth),
                      gpu::Binding::storageImage(1, worldNormal), gpu::Binding::storageImage(2, depth),
                      gpu::Binding::storageImage(3, normal)},
                     gpu::PushConstants(push),
                     gpu::GroupCount{gpu::computeGroupCount(w, kGroupSize),
                                     gpu::computeGroupCount(h, kGroupSize), 1},
                     std::string(kLabel));
    });
}

} // namespace rtlab::render
