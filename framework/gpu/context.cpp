// Context: logical device and queue on the chosen physical device.

#include "gpu/context.h"

#include <cstdlib>
#include <cstring>
#include <string_view>

#include "core/error.h"
#include "gpu/vulkan_internal.h"

namespace rtlab::gpu {

namespace {

bool readFlagFromEnv(const char* name)
{
    const char* value = std::getenv(name);
    if (value == nullptr)
        return false;
    const std::string_view v(value);
    return v == "1" || v == "true" || v == "TRUE" || v == "on" || v == "ON" || v == "yes" ||
           v == "YES";
}

// Whether buffers can live in memory that is device-local and host-visible without staging:
// true on unified-memory devices (integrated GPUs, CPUs). Discrete GPUs may expose a small
// host-visible device-local heap (the PCIe BAR), which is not meant for large buffers.
bool canMapDeviceMemory(const detail::DeviceState& device)
{
    if (device.info.type != DeviceType::IntegratedGpu && device.info.type != DeviceType::Cpu)
        return false;
    constexpr VkMemoryPropertyFlags kWanted = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT |
                                              VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                              VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    for (std::uint32_t i = 0; i < device.memory.memoryTypeCount; ++i) {
        if ((device.memory.memoryTypes[i].propertyFlags & kWanted) == kWanted)
            return true;
    }
    return false;
}

void createLogicalDevice(detail::DeviceState& state, const detail::PhysicalDeviceChoice& choice)
{
    state.physicalDevice = choice.device;
    state.queueFamily = choice.queueFamily;
    state.info = choice.info;
    vkGetPhysicalDeviceMemoryProperties(choice.device, &state.memory);
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(choice.device, &props);
    state.limits = props.limits;

    VkPhysicalDeviceFeatures available;
    vkGetPhysicalDeviceFeatures(choice.device, &available);
    VkPhysicalDeviceFeatures enabled{};
    enabled.shaderStorageImageReadWithoutFormat = available.shaderStorageImageReadWithoutFormat;
    enabled.shaderStorageImageWriteWithoutFormat = available.shaderStorageImageWriteWithoutFormat;
    enabled.shaderInt64 = available.shaderInt64;
    enabled.shaderFloat64 = available.shaderFloat64;

    const float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = choice.queueFamily;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;

    VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    info.queueCreateInfoCount = 1;
    info.pQueueCreateInfos = &queueInfo;
    info.pEnabledFeatures = &enabled;
    detail::checkResult(vkCreateDevice(choice.device, &info, nullptr, &state.device),
                        "vkCreateDevice");
    vkGetDeviceQueue(state.device, choice.queueFamily, 0, &state.queue);

    if (state.instance->validation) {
        state.setObjectNameFn = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
            vkGetInstanceProcAddr(state.instance->instance, "vkSetDebugUtilsObjectNameEXT"));
    }

    VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = choice.queueFamily;
    detail::checkResult(vkCreateCommandPool(state.device, &poolInfo, nullptr, &state.transferPool),
                        "vkCreateCommandPool");
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = state.transferPool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    detail::checkResult(vkAllocateCommandBuffers(state.device, &alloc, &state.transferCommands),
                        "vkAllocateCommandBuffers");
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    detail::checkResult(vkCreateFence(state.device, &fenceInfo, nullptr, &state.transferFence),
                        "vkCreateFence");
}

} // namespace

namespace detail {

RunState::RunState(std::shared_ptr<DeviceState> owner) : device(std::move(owner))
{
    VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = device->queueFamily;
    checkResult(vkCreateCommandPool(device->device, &poolInfo, nullptr, &commandPool),
                "vkCreateCommandPool");
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = commandPool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    checkResult(vkAllocateCommandBuffers(device->device, &alloc, &commands),
                "vkAllocateCommandBuffers");
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    checkResult(vkCreateFence(device->device, &fenceInfo, nullptr, &fence), "vkCreateFence");
}

RunState::~RunState()
{
    VkDevice d = device->device;
    vkQueueWaitIdle(device->queue);
    if (descriptorPool != VK_NULL_HANDLE)
        vkDestroyDescriptorPool(d, descriptorPool, nullptr);
    if (queryPool != VK_NULL_HANDLE)
        vkDestroyQueryPool(d, queryPool, nullptr);
    if (fence != VK_NULL_HANDLE)
        vkDestroyFence(d, fence, nullptr);
    if (commandPool != VK_NULL_HANDLE)
        vkDestroyCommandPool(d, commandPool, nullptr);
}

} // namespace detail

Context::Context(const ContextOptions& options)
{
    const bool validation = options.enableValidation || readFlagFromEnv("RTLAB_VK_VALIDATION");
    auto instance = detail::createInstance(options, validation);
    const auto devices = detail::findUsableDevices(instance->instance);

    std::string filter = options.deviceName;
    const char* origin = "ContextOptions::deviceName";
    if (filter.empty()) {
        if (const char* env = std::getenv("RTLAB_VK_DEVICE"); env != nullptr && *env != '\0') {
            filter = env;
            origin = "RTLAB_VK_DEVICE";
        }
    }
    const detail::PhysicalDeviceChoice choice = detail::chooseDevice(devices, filter, origin);

    mDevice = std::make_shared<detail::DeviceState>();
    mDevice->instance = std::move(instance);
    createLogicalDevice(*mDevice, choice);
    // RTLAB_VK_STAGING=1: a discrete GPU's transfers on any device (to test them on lavapipe).
    mDevice->stagingUploads = options.forceStagingUploads || readFlagFromEnv("RTLAB_VK_STAGING") ||
                              !canMapDeviceMemory(*mDevice);
    mDevice->keepStaging = options.keepStagingBuffers;
    mDevice->timestampsEnabled = mDevice->info.timestampsSupported && !options.disableTimestamps;
    mRun = std::make_unique<detail::RunState>(mDevice);
}

Context::~Context() = default;
Context::Context(Context&&) noexcept = default;
Context& Context::operator=(Context&&) noexcept = default;

std::vector<DeviceInfo> Context::enumerateDevices()
{
    ContextOptions options;
    auto instance = detail::createInstance(options, false);
    std::vector<DeviceInfo> infos;
    for (const detail::PhysicalDeviceChoice& d : detail::findUsableDevices(instance->instance))
        infos.push_back(d.info);
    return infos;
}

const DeviceInfo& Context::getDeviceInfo() const
{
    return mDevice->info;
}

bool Context::isValidationEnabled() const
{
    return mDevice->instance->validation;
}

std::shared_ptr<ValidationLog> Context::getValidationLog() const
{
    return mDevice->instance->log;
}

bool Context::usesStagingUploads() const
{
    return mDevice->stagingUploads;
}

bool Context::hasGpuTimestamps() const
{
    return mDevice->timestampsEnabled;
}

void Context::waitIdle()
{
    std::lock_guard lock(mDevice->queueMutex);
    detail::checkResult(vkQueueWaitIdle(mDevice->queue), "vkQueueWaitIdle");
}

} // namespace rtlab::gpu
