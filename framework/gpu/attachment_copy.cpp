#include "gpu/graphics.h"

#include "core/error.h"
#include "gpu/graphics_internal.h"
#include "gpu/vulkan_internal.h"

#include <string>

namespace rtlab::gpu {

void copyAttachmentToImage(CommandList& cmd, const RenderTarget& target, std::size_t index,
                           const Image& destination, std::uint32_t destinationZ,
                           std::string_view label)
{
    if (!target.isValid() || !destination.isValid())
        throw Error("copyAttachmentToImage: invalid render target or image");
    const RenderTargetDesc& desc = target.getDesc();
    if (index >= desc.colors.size())
        throw Error("copyAttachmentToImage: render target '" + desc.name + "' has no attachment " +
                    std::to_string(index));
    const ImageDesc& dst = destination.getDesc();
    const Format format = desc.colors[index].format;
    if (dst.width != desc.width || dst.height != desc.height || destinationZ >= dst.depth ||
        getTexelSize(dst.format) != getTexelSize(format))
        throw Error("copyAttachmentToImage: attachment '" + desc.colors[index].name + "' (" +
                    std::to_string(desc.width) + "x" + std::to_string(desc.height) + " " +
                    std::string(getFormatName(format)) + ") does not fit slice " +
                    std::to_string(destinationZ) + " of image '" + dst.name + "' (" +
                    std::to_string(dst.width) + "x" + std::to_string(dst.height) + "x" +
                    std::to_string(dst.depth) + " " + std::string(getFormatName(dst.format)) + ")");
    const VkImage source = target.getState().colors[index].image;
    const VkImage sink = destination.getState().image;
    VkImageCopy region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.dstOffset = {0, 0, static_cast<std::int32_t>(destinationZ)};
    region.extent = {desc.width, desc.height, 1};
    // Attachments and images stay in VK_IMAGE_LAYOUT_GENERAL between commands (and the command
    // list puts full barriers around every command); the copy moves both to transfer layouts and
    // back, as the gpu module's own transfers do.
    detail::appendEncodedCommand(
        cmd, std::string(label), [source, sink, region](VkCommandBuffer commands) {
            auto transition = [&](VkImageLayout srcFrom, VkImageLayout srcTo, VkImageLayout dstFrom,
                                  VkImageLayout dstTo, VkAccessFlags before, VkAccessFlags after) {
                VkImageMemoryBarrier barriers[2] = {};
                const VkImage images[2] = {source, sink};
                const VkImageLayout from[2] = {srcFrom, dstFrom};
                const VkImageLayout to[2] = {srcTo, dstTo};
                for (int i = 0; i < 2; ++i) {
                    VkImageMemoryBarrier& b = barriers[i];
                    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
                    b.srcAccessMask = before;
                    b.dstAccessMask = after;
                    b.oldLayout = from[i];
                    b.newLayout = to[i];
                    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
                    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
                    b.image = images[i];
                    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                }
                vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                                     VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0, nullptr,
                                     2, barriers);
            };
            const VkAccessFlags any = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
            transition(VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                       VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                       VK_ACCESS_MEMORY_WRITE_BIT, any);
            vkCmdCopyImage(commands, source, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, sink,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
            transition(VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                       VK_ACCESS_MEMORY_WRITE_BIT, any);
        });
}

} // namespace rtlab::gpu
