#include "render/view_inputs_pass.h"

#include "core/error.h"
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
    gpu::Image positionDepth, normal; // copies of the attachments (storage-bindable)
    std::uint32_t width = 0, height = 0;
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
                                   const gpu::Image& depth, const gpu::Image& normal)
{
    State& s = *mState;
    const std::uint32_t w = gbuffer.getDesc().width, h = gbuffer.getDesc().height;
    const gpu::ImageDesc& d = depth.getDesc();
    const gpu::ImageDesc& n = normal.getDesc();
    if (d.width != w || d.height != h || n.width != w || n.height != h ||
        d.format != gpu::Format::R32Float || n.format != gpu::Format::RGBA32Float)
        throw Error("view inputs: expected an R32Float depth and an RGBA32Float normal image of " +
                    std::to_string(w) + "x" + std::to_string(h) + ", found '" + d.name + "' and '" +
                    n.name + "'");
    if (w != s.width || h != s.height || !s.positionDepth.isValid()) {
        auto make = [&](const char* name) {
            return s.context->createImage({gpu::ImageDimension::Image2D, gpu::Format::RGBA32Float,
                                           w, h, 1, gpu::ImageUsage::StorageAndSampled, name});
        };
        s.positionDepth = make("view_inputs.position_depth");
        s.normal = make("view_inputs.world_normal");
        s.width = w;
        s.height = h;
    }
    Push push;
    push.view = view;
    push.size[0] = w;
    push.size[1] = h;
    return s.context->run([&](gpu::CommandList& cmd) {
        gpu::copyAttachmentToImage(cmd, gbuffer, 0, s.positionDepth, 0, "view_inputs copy");
        gpu::copyAttachmentToImage(cmd, gbuffer, 1, s.normal, 0, "view_inputs copy");
        cmd.dispatch(s.pipeline,
                     {gpu::Binding::storageImage(0, s.positionDepth),
                      gpu::Binding::storageImage(1, s.normal), gpu::Binding::storageImage(2, depth),
                      gpu::Binding::storageImage(3, normal)},
                     gpu::PushConstants(push),
                     gpu::GroupCount{gpu::computeGroupCount(w, kGroupSize),
                                     gpu::computeGroupCount(h, kGroupSize), 1},
                     std::string(kLabel));
    });
}

} // namespace rtlab::render
