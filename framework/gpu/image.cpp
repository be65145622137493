// 2D/3D images (in VK_IMAGE_LAYOUT_GENERAL between commands) and samplers.

#include "gpu/resources.h"

#include "core/error.h"
#include "gpu/vulkan_internal.h"

namespace rtlab::gpu {

namespace detail {

ImageState::~ImageState()
{
    if (!device)
        return;
    if (view != VK_NULL_HANDLE)
        vkDestroyImageView(device->device, view, nullptr);
    if (image != VK_NULL_HANDLE)
        vkDestroyImage(device->device, image, nullptr);
    if (memory != VK_NULL_HANDLE)
        vkFreeMemory(device->device, memory, nullptr);
}

SamplerState::~SamplerState()
{
    if (device && sampler != VK_NULL_HANDLE)
        vkDestroySampler(device->device, sampler, nullptr);
}

} // namespace detail

// ---- Image -------------------------------------------------------------------------------------

Image::Image() = default;
Image::~Image() = default;
Image::Image(Image&&) noexcept = default;
Image& Image::operator=(Image&&) noexcept = default;
Image::Image(std::unique_ptr<detail::ImageState> state) : mState(std::move(state)) {}

detail::ImageState& Image::getState() const
{
    if (!mState)
        throw Error("use of an empty gpu::Image");
    return *mState;
}

const ImageDesc& Image::getDesc() const
{
    return getState().desc;
}

std::size_t Image::getByteSize() const
{
    const ImageDesc& d = getDesc();
    return std::size_t{d.width} * d.height * d.depth * getTexelSize(d.format);
}

namespace {

VkBufferImageCopy makeWholeImageCopy(const ImageDesc& desc)
{
    VkBufferImageCopy region{};
    region.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    region.imageSubresource.layerCount = 1;
    region.imageExtent = {desc.width, desc.height, desc.depth};
    return region;
}

// Moves the image between GENERAL (where it lives) and a transfer layout around a copy.
void recordLayoutChange(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to)
{
    VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.oldLayout = from;
    barrier.newLayout = to;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image;
    barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                         VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr, 1,
                         &barrier);
}

void checkImageSize(const Image& image, std::size_t size, const char* what)
{
    if (size != image.getByteSize())
        throw Error(std::string(what) + " of image '" + image.getDesc().name + "' needs " +
                    std::to_string(image.getByteSize()) + " bytes, got " + std::to_string(size));
}

} // namespace

void Image::upload(const void* data, std::size_t size)
{
    checkImageSize(*this, size, "upload");
    detail::ImageState& state = getState();
    const VkBufferImageCopy region = makeWholeImageCopy(state.desc);
    detail::uploadThroughStaging(*state.device, data, size, [&](VkCommandBuffer cmd, VkBuffer src) {
        // Every texel is overwritten, so the old contents need not be kept (UNDEFINED).
        recordLayoutChange(cmd, state.image, VK_IMAGE_LAYOUT_UNDEFINED,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
        vkCmdCopyBufferToImage(cmd, src, state.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                               &region);
        recordLayoutChange(cmd, state.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           VK_IMAGE_LAYOUT_GENERAL);
    });
}

void Image::download(void* data, std::size_t size) const
{
    checkImageSize(*this, size, "download");
    detail::ImageState& state = getState();
    const VkBufferImageCopy region = makeWholeImageCopy(state.desc);
    detail::downloadThroughStaging(
        *state.device, data, size, [&](VkCommandBuffer cmd, VkBuffer dst) {
            recordLayoutChange(cmd, state.image, VK_IMAGE_LAYOUT_GENERAL,
                               VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
            vkCmdCopyImageToBuffer(cmd, state.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst, 1,
                                   &region);
            recordLayoutChange(cmd, state.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               VK_IMAGE_LAYOUT_GENERAL);
        });
}

Image Context::createImage(const ImageDesc& desc)
{
    const std::string name = desc.name.empty() ? std::string("image") : desc.name;
    const bool is3d = desc.dimension == ImageDimension::Image3D;
    const std::uint32_t maxDim =
        is3d ? mDevice->limits.maxImageDimension3D : mDevice->limits.maxImageDimension2D;
    if (desc.width == 0 || desc.height == 0 || desc.depth == 0 || (!is3d && desc.depth != 1))
        throw Error("gpu image '" + name + "' has invalid extent " + std::to_string(desc.width) +
                    "x" + std::to_string(desc.height) + "x" + std::to_string(desc.depth) +
                    (is3d ? "" : " (2D images need depth 1)"));
    if (desc.width > maxDim || desc.height > maxDim || desc.depth > maxDim)
        throw Error("gpu image '" + name + "' exceeds the device limit of " +
                    std::to_string(maxDim) + " texels per side");

    const VkFormat format = detail::toVkFormat(desc.format);
    VkFormatProperties formatProps;
    vkGetPhysicalDeviceFormatProperties(mDevice->physicalDevice, format, &formatProps);
    const VkFormatFeatureFlags features = formatProps.optimalTilingFeatures;
    const auto usageBits = static_cast<std::uint32_t>(desc.usage);
    const bool storage = usageBits & static_cast<std::uint32_t>(ImageUsage::Storage);
    const bool sampled = usageBits & static_cast<std::uint32_t>(ImageUsage::Sampled);
    auto requireFeature = [&](VkFormatFeatureFlags bit, const char* use) {
        if (!(features & bit))
            throw Error("gpu image '" + name + "': this device does not support " + use +
                        " with format " + std::string(getFormatName(desc.format)));
    };
    if (!storage && !sampled)
        throw Error("gpu image '" + name + "' has neither storage nor sampled usage");
    if (storage)
        requireFeature(VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT, "storage images");
    if (sampled)
        requireFeature(VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT, "sampled images");
    requireFeature(VK_FORMAT_FEATURE_TRANSFER_SRC_BIT, "transfers from images");
    requireFeature(VK_FORMAT_FEATURE_TRANSFER_DST_BIT, "transfers to images");

    auto state = std::make_unique<detail::ImageState>();
    state->device = mDevice;
    state->desc = desc;
    state->desc.name = name;
    state->features = features;
    VkDevice device = mDevice->device;

    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = is3d ? VK_IMAGE_TYPE_3D : VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {desc.width, desc.height, desc.depth};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                 (storage ? VK_IMAGE_USAGE_STORAGE_BIT : 0) |
                 (sampled ? VK_IMAGE_USAGE_SAMPLED_BIT : 0);
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    detail::checkResult(vkCreateImage(device, &info, nullptr, &state->image), "vkCreateImage");

    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, state->image, &req);
    std::uint32_t type =
        mDevice->findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (type == UINT32_MAX)
        type = mDevice->findMemoryType(req.memoryTypeBits, 0);
    if (type == UINT32_MAX)
        throw Error("no suitable Vulkan memory type for image '" + name + "'");
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    detail::checkResult(vkAllocateMemory(device, &alloc, nullptr, &state->memory),
                        "allocating image memory");
    detail::checkResult(vkBindImageMemory(device, state->image, state->memory, 0),
                        "vkBindImageMemory");

    VkImageViewCreateInfo viewInfo{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    viewInfo.image = state->image;
    viewInfo.viewType = is3d ? VK_IMAGE_VIEW_TYPE_3D : VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = format;
    viewInfo.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    detail::checkResult(vkCreateImageView(device, &viewInfo, nullptr, &state->view),
                        "vkCreateImageView");
    mDevice->setObjectName(VK_OBJECT_TYPE_IMAGE, reinterpret_cast<std::uint64_t>(state->image),
                           name);

    VkImage image = state->image;
    mDevice->submitAndWait([image](VkCommandBuffer cmd) {
        VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
        barrier.srcAccessMask = 0;
        barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
        barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
        barrier.newLayout = VK_IMAGE_LAYOUT_GENERAL;
        barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        barrier.image = image;
        barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT,
                             VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr, 1,
                             &barrier);
    });
    return Image(std::move(state));
}

// ---- Sampler -----------------------------------------------------------------------------------

Sampler::Sampler() = default;
Sampler::~Sampler() = default;
Sampler::Sampler(Sampler&&) noexcept = default;
Sampler& Sampler::operator=(Sampler&&) noexcept = default;
Sampler::Sampler(std::unique_ptr<detail::SamplerState> state) : mState(std::move(state)) {}

detail::SamplerState& Sampler::getState() const
{
    if (!mState)
        throw Error("use of an empty gpu::Sampler");
    return *mState;
}

const SamplerDesc& Sampler::getDesc() const
{
    return getState().desc;
}

namespace {

VkSamplerAddressMode toVkAddressMode(AddressMode mode)
{
    switch (mode) {
    case AddressMode::ClampToEdge:
        return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    case AddressMode::Repeat:
        return VK_SAMPLER_ADDRESS_MODE_REPEAT;
    case AddressMode::MirroredRepeat:
        return VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT;
    case AddressMode::ClampToBorder:
        return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER;
    }
    return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
}

} // namespace

Sampler Context::createSampler(const SamplerDesc& desc)
{
    auto state = std::make_unique<detail::SamplerState>();
    state->device = mDevice;
    state->desc = desc;
    const VkFilter filter = desc.filter == Filter::Linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
    const VkSamplerAddressMode address = toVkAddressMode(desc.addressMode);
    VkSamplerCreateInfo info{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    info.magFilter = filter;
    info.minFilter = filter;
    info.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    info.addressModeU = address;
    info.addressModeV = address;
    info.addressModeW = address;
    info.maxLod = 0.0f;
    info.borderColor = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;
    detail::checkResult(vkCreateSampler(mDevice->device, &info, nullptr, &state->sampler),
                        "vkCreateSampler");
    return Sampler(std::move(state));
}

} // namespace rtlab::gpu
