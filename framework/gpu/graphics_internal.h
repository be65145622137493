#pragma once
// Private to the gpu module: the Vulkan objects behind graphics pipelines and render targets.

#include "gpu/graphics.h"
#include "gpu/vulkan_internal.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace rtlab::gpu::detail {

//! Throws rtlab::Error unless the context's queue family supports graphics.
void requireGraphicsQueue(const DeviceState& device, const std::string& what);

//! Throws rtlab::Error unless `format` can be a colour attachment on this device.
void requireColorAttachmentFormat(const DeviceState& device, Format format,
                                  const std::string& what);

//! Throws rtlab::Error unless D32_SFLOAT can be a depth attachment on this device.
void requireDepthAttachmentFormat(const DeviceState& device, const std::string& what);

//! A render pass with one subpass writing `colorFormats` (and D32_SFLOAT depth when `depth`).
//! `clear`: attachments start cleared (from an undefined layout); otherwise they are loaded from
//! VK_IMAGE_LAYOUT_GENERAL. Either way they end in VK_IMAGE_LAYOUT_GENERAL. Render passes that
//! differ only in `clear` are compatible.
VkRenderPass createRenderPass(DeviceState& device, const std::vector<Format>& colorFormats,
                              bool depth, bool clear);

struct GraphicsPipelineState {
    std::shared_ptr<DeviceState> device;
    VkRenderPass renderPass = VK_NULL_HANDLE; //!< defines compatible render targets
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    std::string name;
    std::vector<Format> colorFormats;
    std::vector<VertexBinding> vertexBindings;
    bool depthTest = true;
    std::uint32_t pushConstantSize = 0;
    ~GraphicsPipelineState();
};

//! One image with its memory and view.
struct AttachmentImage {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
};

struct RenderTargetState {
    std::shared_ptr<DeviceState> device;
    RenderTargetDesc desc;
    std::vector<AttachmentImage> colors;
    AttachmentImage depth; //!< null handles without depth
    VkRenderPass clearPass = VK_NULL_HANDLE;
    VkRenderPass loadPass = VK_NULL_HANDLE;
    VkFramebuffer framebuffer = VK_NULL_HANDLE; //!< made with clearPass, compatible with both
    ~RenderTargetState();
};

} // namespace rtlab::gpu::detail
