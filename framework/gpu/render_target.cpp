// Render targets: colour and depth attachments, their render passes and framebuffer, readback.

#include "gpu/graphics.h"

#include "core/error.h"
#include "gpu/context.h"
#include "gpu/graphics_internal.h"

namespace rtlab::gpu {

namespace detail {

namespace {

void destroyAttachment(VkDevice device, AttachmentImage& a)
{
    if (a.view != VK_NULL_HANDLE)
        vkDestroyImageView(device, a.view, nullptr);
    if (a.image != VK_NULL_HANDLE)
        vkDestroyImage(device, a.image, nullptr);
    if (a.memory != VK_NULL_HANDLE)
        vkFreeMemory(device, a.memory, nullptr);
    a = AttachmentImage{};
}

// Creates a 2D image with device-local memory and a view. `a` belongs to a RenderTargetState,
// whose destructor frees what was created when this throws.
void createAttachmentImage(DeviceState& device, AttachmentImage& a, VkFormat format,
                           VkImageUsageFlags usage, VkImageAspectFlags aspect,
                           const RenderTargetDesc& desc, const std::string& name)
{
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {desc.width, desc.height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    checkResult(vkCreateImage(device.device, &info, nullptr, &a.image), "vkCreateImage");

    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device.device, a.image, &req);
    std::uint32_t type =
        device.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (type == UINT32_MAX)
        type = device.findMemoryType(req.memoryTypeBits, 0);
    if (type == UINT32_MAX)
        throw Error("no suitable Vulkan memory type for attachment '" + name + "'");
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    checkResult(vkAllocateMemory(device.device, &alloc, nullptr, &a.memory),
                ("allocating attachment '" + name + "'").c_str());
    checkResult(vkBindImageMemory(device.device, a.image, a.memory, 0), "vkBindImageMemory");

    VkImageViewCreateInfo viewInfo{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    viewInfo.image = a.image;
    viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = format;
    viewInfo.subresourceRange = {aspect, 0, 1, 0, 1};
    checkResult(vkCreateImageView(device.device, &viewInfo, nullptr, &a.view), "vkCreateImageView");
    device.setObjectName(VK_OBJECT_TYPE_IMAGE, reinterpret_cast<std::uint64_t>(a.image), name);
}

void recordLayoutChange(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                        VkImageLayout from, VkImageLayout to)
{
    VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.oldLayout = from;
    barrier.newLayout = to;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                         VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr, 1,
                         &barrier);
}

// Copies a whole attachment (kept in GENERAL) to host memory.
void downloadAttachment(DeviceState& device, const RenderTargetDesc& desc, VkImage image,
                        VkImageAspectFlags aspect, void* data, std::size_t size)
{
    VkBufferImageCopy region{};
    region.imageSubresource.aspectMask = aspect;
    region.imageSubresource.layerCount = 1;
    region.imageExtent = {desc.width, desc.height, 1};
    downloadThroughStaging(device, data, size, [&](VkCommandBuffer cmd, VkBuffer dst) {
        recordLayoutChange(cmd, image, aspect, VK_IMAGE_LAYOUT_GENERAL,
                           VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
        vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst, 1, &region);
        recordLayoutChange(cmd, image, aspect, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           VK_IMAGE_LAYOUT_GENERAL);
    });
}

} // namespace

RenderTargetState::~RenderTargetState()
{
    if (!device)
        return;
    VkDevice d = device->device;
    if (framebuffer != VK_NULL_HANDLE)
        vkDestroyFramebuffer(d, framebuffer, nullptr);
    if (clearPass != VK_NULL_HANDLE)
        vkDestroyRenderPass(d, clearPass, nullptr);
    if (loadPass != VK_NULL_HANDLE)
        vkDestroyRenderPass(d, loadPass, nullptr);
    for (AttachmentImage& a : colors)
        destroyAttachment(d, a);
    destroyAttachment(d, depth);
}

} // namespace detail

// ---- RenderTarget ------------------------------------------------------------------------------

RenderTarget::RenderTarget() = default;
RenderTarget::~RenderTarget() = default;
RenderTarget::RenderTarget(RenderTarget&&) noexcept = default;
RenderTarget& RenderTarget::operator=(RenderTarget&&) noexcept = default;
RenderTarget::RenderTarget(std::unique_ptr<detail::RenderTargetState> state)
    : mState(std::move(state))
{
}

detail::RenderTargetState& RenderTarget::getState() const
{
    if (!mState)
        throw Error("use of an empty gpu::RenderTarget");
    return *mState;
}

const RenderTargetDesc& RenderTarget::getDesc() const
{
    return getState().desc;
}

std::uint32_t RenderTarget::getWidth() const
{
    return getDesc().width;
}

std::uint32_t RenderTarget::getHeight() const
{
    return getDesc().height;
}

std::size_t RenderTarget::getColorByteSize(std::size_t index) const
{
    const RenderTargetDesc& desc = getDesc();
    if (index >= desc.colors.size())
        throw Error("render target '" + desc.name + "' has no colour attachment " +
                    std::to_string(index));
    return std::size_t{desc.width} * desc.height * getTexelSize(desc.colors[index].format);
}

void RenderTarget::downloadColor(std::size_t index, void* data, std::size_t size) const
{
    detail::RenderTargetState& state = getState();
    const std::size_t needed = getColorByteSize(index);
    if (size != needed)
        throw Error("download of attachment '" + state.desc.colors[index].name + "' needs " +
                    std::to_string(needed) + " bytes, got " + std::to_string(size));
    detail::downloadAttachment(*state.device, state.desc, state.colors[index].image,
                               VK_IMAGE_ASPECT_COLOR_BIT, data, size);
}

std::vector<float> RenderTarget::downloadDepth() const
{
    detail::RenderTargetState& state = getState();
    if (!state.desc.depth)
        throw Error("render target '" + state.desc.name + "' has no depth attachment");
    std::vector<float> values(std::size_t{state.desc.width} * state.desc.height);
    detail::downloadAttachment(*state.device, state.desc, state.depth.image,
                               VK_IMAGE_ASPECT_DEPTH_BIT, values.data(),
                               values.size() * sizeof(float));
    return values;
}

RenderTarget Context::createRenderTarget(const RenderTargetDesc& desc)
{
    const std::string name = desc.name.empty() ? std::string("render target") : desc.name;
    const std::string what = "render target '" + name + "'";
    detail::DeviceState& device = *mDevice;
    detail::requireGraphicsQueue(device, what);
    const VkPhysicalDeviceLimits& limits = device.limits;
    if (desc.width == 0 || desc.height == 0)
        throw Error(what + " has invalid size " + std::to_string(desc.width) + "x" +
                    std::to_string(desc.height));
    if (desc.width > limits.maxFramebufferWidth || desc.height > limits.maxFramebufferHeight)
        throw Error(what + " exceeds the device's framebuffer limit of " +
                    std::to_string(limits.maxFramebufferWidth) + "x" +
                    std::to_string(limits.maxFramebufferHeight));
    if (desc.colors.empty() && !desc.depth)
        throw Error(what + " has no attachment");
    if (desc.colors.size() > limits.maxColorAttachments)
        throw Error(what + ": " + std::to_string(desc.colors.size()) +
                    " colour attachments exceed the device limit of " +
                    std::to_string(limits.maxColorAttachments));

    auto state = std::make_unique<detail::RenderTargetState>();
    state->device = mDevice;
    state->desc = desc;
    state->desc.name = name;
    std::vector<Format> formats;
    for (std::size_t i = 0; i < desc.colors.size(); ++i) {
        ColorAttachmentDesc& color = state->desc.colors[i];
        if (color.name.empty())
            color.name = name + " colour " + std::to_string(i);
        detail::requireColorAttachmentFormat(device, color.format, what);
        formats.push_back(color.format);
    }
    if (desc.depth)
        detail::requireDepthAttachmentFormat(device, what);

    state->colors.resize(desc.colors.size());
    for (std::size_t i = 0; i < desc.colors.size(); ++i)
        detail::createAttachmentImage(
            device, state->colors[i], detail::toVkFormat(desc.colors[i].format),
            VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_IMAGE_ASPECT_COLOR_BIT, state->desc,
            state->desc.colors[i].name);
    if (desc.depth)
        detail::createAttachmentImage(device, state->depth, VK_FORMAT_D32_SFLOAT,
                                      VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                                      VK_IMAGE_ASPECT_DEPTH_BIT, state->desc, name + " depth");

    state->clearPass = detail::createRenderPass(device, formats, desc.depth, true);
    state->loadPass = detail::createRenderPass(device, formats, desc.depth, false);
    std::vector<VkImageView> views;
    for (const detail::AttachmentImage& a : state->colors)
        views.push_back(a.view);
    if (desc.depth)
        views.push_back(state->depth.view);
    VkFramebufferCreateInfo fbInfo{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fbInfo.renderPass = state->clearPass;
    fbInfo.attachmentCount = static_cast<std::uint32_t>(views.size());
    fbInfo.pAttachments = views.data();
    fbInfo.width = desc.width;
    fbInfo.height = desc.height;
    fbInfo.layers = 1;
    detail::checkResult(vkCreateFramebuffer(device.device, &fbInfo, nullptr, &state->framebuffer),
                        "vkCreateFramebuffer");

    // Attachments live in GENERAL between commands, like images.
    const detail::RenderTargetState& s = *state;
    device.submitAndWait([&s](VkCommandBuffer cmd) {
        for (const detail::AttachmentImage& a : s.colors)
            detail::recordLayoutChange(cmd, a.image, VK_IMAGE_ASPECT_COLOR_BIT,
                                       VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
        if (s.desc.depth)
            detail::recordLayoutChange(cmd, s.depth.image, VK_IMAGE_ASPECT_DEPTH_BIT,
                                       VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    });
    return RenderTarget(std::move(state));
}

} // namespace rtlab::gpu
