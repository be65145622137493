// Recording indexed draws: checks against the pipeline and target, then one render pass.

#include "gpu/commands.h"

#include <array>

#include "core/error.h"
#include "gpu/graphics.h"
#include "gpu/graphics_internal.h"

namespace rtlab::gpu {

namespace {

void checkDraw(const detail::GraphicsPipelineState& pipe, const detail::RenderTargetState& target,
               const IndexedDraw& draw, std::size_t pushConstantSize,
               const detail::DeviceState* device)
{
    auto fail = [&](const std::string& why) {
        throw Error("draw of '" + pipe.name + "' into '" + target.desc.name + "': " + why);
    };
    if (pipe.device.get() != device)
        fail("pipeline belongs to another context");
    if (target.device.get() != device)
        fail("render target belongs to another context");
    if (pushConstantSize != pipe.pushConstantSize)
        fail(std::to_string(pushConstantSize) +
             " bytes of push constants given, the pipeline "
             "declares " +
             std::to_string(pipe.pushConstantSize));
    if (target.desc.colors.size() != pipe.colorFormats.size())
        fail("the target has " + std::to_string(target.desc.colors.size()) +
             " colour attachments, the pipeline writes " +
             std::to_string(pipe.colorFormats.size()));
    for (std::size_t i = 0; i < pipe.colorFormats.size(); ++i) {
        if (target.desc.colors[i].format != pipe.colorFormats[i])
            fail("colour attachment " + std::to_string(i) + " is " +
                 std::string(getFormatName(target.desc.colors[i].format)) +
                 ", the pipeline writes " + std::string(getFormatName(pipe.colorFormats[i])));
    }
    if (pipe.depthTest != target.desc.depth)
        fail(pipe.depthTest ? "the pipeline tests depth but the target has no depth attachment"
                            : "the target has a depth attachment the pipeline does not use");
    if (draw.vertexBuffers.size() != pipe.vertexBindings.size())
        fail(std::to_string(draw.vertexBuffers.size()) +
             " vertex buffers given, the pipeline has " +
             std::to_string(pipe.vertexBindings.size()) + " vertex bindings");
    auto checkBuffer = [&](const Buffer* buffer, const std::string& what) {
        if (buffer == nullptr || !buffer->isValid())
            fail(what + " is empty");
        const detail::BufferState& state = buffer->getState();
        if (state.device.get() != device)
            fail(what + " belongs to another context");
        if (!state.vertexIndexUsage)
            fail(what + " '" + state.name + "' was not created with vertexIndexUsage");
    };
    for (std::size_t i = 0; i < draw.vertexBuffers.size(); ++i)
        checkBuffer(draw.vertexBuffers[i], "vertex buffer " + std::to_string(i));
    checkBuffer(draw.indexBuffer, "the index buffer");
    if (draw.indexCount % 3 != 0)
        fail("index count " + std::to_string(draw.indexCount) + " is not a multiple of 3");
    const std::uint64_t end =
        (std::uint64_t{draw.firstIndex} + draw.indexCount) * sizeof(std::uint32_t);
    if (end > draw.indexBuffer->getSize())
        fail("indices " + std::to_string(draw.firstIndex) + " to " +
             std::to_string(std::uint64_t{draw.firstIndex} + draw.indexCount) +
             " exceed the index buffer of " + std::to_string(draw.indexBuffer->getSize()) +
             " bytes");
}

// What the encoder needs, copied when the draw is recorded.
struct EncodedDraw {
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkRenderPass renderPass = VK_NULL_HANDLE;
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    VkExtent2D extent{};
    std::vector<VkClearValue> clearValues; // empty when loading
    std::vector<VkBuffer> vertexBuffers;
    VkBuffer indexBuffer = VK_NULL_HANDLE;
    IndexedDraw draw;
    std::vector<std::byte> pushConstants;
};

std::vector<VkClearValue> makeClearValues(const RenderTargetDesc& desc)
{
    std::vector<VkClearValue> values;
    for (const ColorAttachmentDesc& c : desc.colors) {
        VkClearValue v{};
        if (c.format == Format::R32Uint) {
            for (int k = 0; k < 4; ++k)
                v.color.uint32[k] = c.clearUint[k];
        } else {
            for (int k = 0; k < 4; ++k)
                v.color.float32[k] = c.clearFloat[k];
        }
        values.push_back(v);
    }
    if (desc.depth) {
        VkClearValue v{};
        v.depthStencil = {desc.depthClear, 0};
        values.push_back(v);
    }
    return values;
}

void encodeDraw(VkCommandBuffer cb, const EncodedDraw& d)
{
    VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    begin.renderPass = d.renderPass;
    begin.framebuffer = d.framebuffer;
    begin.renderArea = {{0, 0}, d.extent};
    begin.clearValueCount = static_cast<std::uint32_t>(d.clearValues.size());
    begin.pClearValues = d.clearValues.empty() ? nullptr : d.clearValues.data();
    vkCmdBeginRenderPass(cb, &begin, VK_SUBPASS_CONTENTS_INLINE);
    if (d.draw.indexCount > 0) {
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, d.pipeline);
        const VkViewport viewport{
            0.0f, 0.0f, static_cast<float>(d.extent.width), static_cast<float>(d.extent.height),
            0.0f, 1.0f};
        vkCmdSetViewport(cb, 0, 1, &viewport);
        const VkRect2D scissor{{0, 0}, d.extent};
        vkCmdSetScissor(cb, 0, 1, &scissor);
        if (!d.pushConstants.empty())
            vkCmdPushConstants(
                cb, d.layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                static_cast<std::uint32_t>(d.pushConstants.size()), d.pushConstants.data());
        if (!d.vertexBuffers.empty()) {
            const std::vector<VkDeviceSize> offsets(d.vertexBuffers.size(), 0);
            vkCmdBindVertexBuffers(cb, 0, static_cast<std::uint32_t>(d.vertexBuffers.size()),
                                   d.vertexBuffers.data(), offsets.data());
        }
        vkCmdBindIndexBuffer(cb, d.indexBuffer, 0, VK_INDEX_TYPE_UINT32);
        vkCmdDrawIndexed(cb, d.draw.indexCount, 1, d.draw.firstIndex, d.draw.vertexOffset, 0);
    }
    vkCmdEndRenderPass(cb);
}

} // namespace

void CommandList::drawIndexed(const GraphicsPipeline& pipeline, const RenderTarget& target,
                              const IndexedDraw& draw, PushConstants pushConstants,
                              std::string_view label)
{
    const detail::GraphicsPipelineState& pipe = pipeline.getState();
    const detail::RenderTargetState& tgt = target.getState();
    checkDraw(pipe, tgt, draw, pushConstants.getSize(), detail::getRecordingDevice(*this).get());

    auto encoded = std::make_shared<EncodedDraw>();
    encoded->pipeline = pipe.pipeline;
    encoded->layout = pipe.layout;
    encoded->renderPass = draw.clear ? tgt.clearPass : tgt.loadPass;
    encoded->framebuffer = tgt.framebuffer;
    encoded->extent = {tgt.desc.width, tgt.desc.height};
    if (draw.clear)
        encoded->clearValues = makeClearValues(tgt.desc);
    for (const Buffer* b : draw.vertexBuffers)
        encoded->vertexBuffers.push_back(b->getState().raw.buffer);
    encoded->indexBuffer = draw.indexBuffer->getState().raw.buffer;
    encoded->draw = draw;
    encoded->pushConstants.assign(pushConstants.getData(),
                                  pushConstants.getData() + pushConstants.getSize());
    detail::appendEncodedCommand(*this, label.empty() ? pipe.name : std::string(label),
                                 [encoded](VkCommandBuffer cb) { encodeDraw(cb, *encoded); });
}

} // namespace rtlab::gpu
