// Helpers shared by the gpu module: VkResult names, memory types, raw buffers, one-off
// submissions and barriers.

#include "gpu/vulkan_internal.h"

#include <chrono>
#include <limits>

#include "core/error.h"
#include "gpu/bus_counters.h"

namespace rtlab::gpu::detail {

const char* getResultName(VkResult result)
{
    switch (result) {
    case VK_SUCCESS:
        return "VK_SUCCESS";
    case VK_NOT_READY:
        return "VK_NOT_READY";
    case VK_TIMEOUT:
        return "VK_TIMEOUT";
    case VK_INCOMPLETE:
        return "VK_INCOMPLETE";
    case VK_ERROR_OUT_OF_HOST_MEMORY:
        return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
        return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
        return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
        return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_MEMORY_MAP_FAILED:
        return "VK_ERROR_MEMORY_MAP_FAILED";
    case VK_ERROR_LAYER_NOT_PRESENT:
        return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
        return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
        return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
        return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_TOO_MANY_OBJECTS:
        return "VK_ERROR_TOO_MANY_OBJECTS";
    case VK_ERROR_FORMAT_NOT_SUPPORTED:
        return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_FRAGMENTED_POOL:
        return "VK_ERROR_FRAGMENTED_POOL";
    case VK_ERROR_OUT_OF_POOL_MEMORY:
        return "VK_ERROR_OUT_OF_POOL_MEMORY";
    case VK_ERROR_UNKNOWN:
        return "VK_ERROR_UNKNOWN";
    default:
        return "VkResult(unknown)";
    }
}

void checkResult(VkResult result, const char* what)
{
    if (result != VK_SUCCESS)
        throw Error(std::string(what) + " failed: " + getResultName(result) + " (" +
                    std::to_string(static_cast<int>(result)) + ")");
}

VkFormat toVkFormat(Format format)
{
    switch (format) {
    case Format::R32Float:
        return VK_FORMAT_R32_SFLOAT;
    case Format::RGBA32Float:
        return VK_FORMAT_R32G32B32A32_SFLOAT;
    case Format::RGBA16Float:
        return VK_FORMAT_R16G16B16A16_SFLOAT;
    case Format::RGBA8Unorm:
        return VK_FORMAT_R8G8B8A8_UNORM;
    case Format::R32Uint:
        return VK_FORMAT_R32_UINT;
    }
    return VK_FORMAT_UNDEFINED;
}

DeviceState::~DeviceState()
{
    if (device != VK_NULL_HANDLE) {
        vkDeviceWaitIdle(device);
        destroyRawBuffer(uploadStaging);
        destroyRawBuffer(downloadStaging);
        if (transferFence != VK_NULL_HANDLE)
            vkDestroyFence(device, transferFence, nullptr);
        if (transferPool != VK_NULL_HANDLE)
            vkDestroyCommandPool(device, transferPool, nullptr);
        vkDestroyDevice(device, nullptr);
    }
}

std::uint32_t DeviceState::findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                          VkMemoryPropertyFlags preferred) const
{
    std::uint32_t fallback = std::numeric_limits<std::uint32_t>::max();
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
        const VkMemoryPropertyFlags flags = memory.memoryTypes[i].propertyFlags;
        if (!(typeBits & (1u << i)) || (flags & required) != required)
            continue;
        if ((flags & preferred) == preferred)
            return i;
        if (fallback == std::numeric_limits<std::uint32_t>::max())
            fallback = i;
    }
    return fallback;
}

RawBuffer DeviceState::createRawBuffer(VkDeviceSize size, VkBufferUsageFlags usage, MemoryKind kind,
                                       const std::string& name)
{
    RawBuffer raw;
    raw.size = size;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    checkResult(vkCreateBuffer(device, &info, nullptr, &raw.buffer), "vkCreateBuffer");

    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, raw.buffer, &req);
    constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    std::uint32_t type = kNone;
    switch (kind) {
    case MemoryKind::DeviceLocal:
        type = findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        if (type == kNone)
            type = findMemoryType(req.memoryTypeBits, 0);
        break;
    case MemoryKind::DeviceLocalMapped:
        type = findMemoryType(req.memoryTypeBits,
                              VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT |
                                  VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                              VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
        break;
    case MemoryKind::HostStaging:
        type = findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                              VK_MEMORY_PROPERTY_HOST_COHERENT_BIT |
                                  VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
        break;
    }
    if (type == kNone) {
        vkDestroyBuffer(device, raw.buffer, nullptr);
        throw Error("no suitable Vulkan memory type for buffer '" + name + "'");
    }
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    VkResult result = vkAllocateMemory(device, &alloc, nullptr, &raw.memory);
    if (result != VK_SUCCESS) {
        vkDestroyBuffer(device, raw.buffer, nullptr);
        throw Error("allocating " + std::to_string(size) + " bytes for buffer '" + name +
                    "' failed: " + getResultName(result));
    }
    result = vkBindBufferMemory(device, raw.buffer, raw.memory, 0);
    const VkMemoryPropertyFlags flags = memory.memoryTypes[type].propertyFlags;
    if (result == VK_SUCCESS && kind != MemoryKind::DeviceLocal) {
        raw.coherent = (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
        result = vkMapMemory(device, raw.memory, 0, VK_WHOLE_SIZE, 0, &raw.mapped);
    }
    if (result != VK_SUCCESS) {
        destroyRawBuffer(raw);
        checkResult(result, "binding or mapping buffer memory");
    }
    setObjectName(VK_OBJECT_TYPE_BUFFER, reinterpret_cast<std::uint64_t>(raw.buffer), name);
    return raw;
}

void DeviceState::destroyRawBuffer(RawBuffer& raw)
{
    if (raw.buffer != VK_NULL_HANDLE)
        vkDestroyBuffer(device, raw.buffer, nullptr);
    if (raw.memory != VK_NULL_HANDLE)
        vkFreeMemory(device, raw.memory, nullptr); // also unmaps
    raw = RawBuffer{};
}

void DeviceState::submitAndWait(const std::function<void(VkCommandBuffer)>& record)
{
    std::lock_guard lock(queueMutex);
    checkResult(vkResetCommandBuffer(transferCommands, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    checkResult(vkBeginCommandBuffer(transferCommands, &begin), "vkBeginCommandBuffer");
    recordFullBarrier(transferCommands);
    record(transferCommands);
    recordHostReadBarrier(transferCommands);
    checkResult(vkEndCommandBuffer(transferCommands), "vkEndCommandBuffer");

    checkResult(vkResetFences(device, 1, &transferFence), "vkResetFences");
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &transferCommands;
    checkResult(vkQueueSubmit(queue, 1, &submit, transferFence), "vkQueueSubmit");
    countSubmit();
    const auto waitStart = std::chrono::steady_clock::now();
    checkResult(vkWaitForFences(device, 1, &transferFence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    countWait(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - waitStart).count());
}

void DeviceState::setObjectName(VkObjectType type, std::uint64_t handle, const std::string& name)
{
    if (setObjectNameFn == nullptr || name.empty())
        return;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name.c_str();
    setObjectNameFn(device, &info);
}

void recordFullBarrier(VkCommandBuffer commands)
{
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                         VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &barrier, 0, nullptr, 0,
                         nullptr);
}

void recordHostReadBarrier(VkCommandBuffer commands)
{
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                         0, 1, &barrier, 0, nullptr, 0, nullptr);
}

} // namespace rtlab::gpu::detail
