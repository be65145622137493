#pragma once
// Private to the gpu module: the Vulkan objects behind the public classes. Only .cpp files of
// framework/gpu include this header (and with it <vulkan/vulkan.h>).

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "gpu/context.h"

namespace rtlab::gpu::detail {

//! The name of a VkResult, e.g. "VK_ERROR_OUT_OF_DEVICE_MEMORY".
const char* getResultName(VkResult result);

//! Throws rtlab::Error("<what> failed: <result name>") unless result is VK_SUCCESS.
void checkResult(VkResult result, const char* what);

//! The Vulkan format of a Format.
VkFormat toVkFormat(Format format);

//! The descriptor type of a binding type.
VkDescriptorType toVkDescriptorType(BindingType type);

//! The instance and, when validation is on, the debug messenger.
struct InstanceState {
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    std::shared_ptr<ValidationLog> log; //!< the messenger writes here
    bool echo = false;
    bool validation = false;

    InstanceState() = default;
    InstanceState(const InstanceState&) = delete;
    InstanceState& operator=(const InstanceState&) = delete;
    ~InstanceState();
};

//! Creates an instance (headless: no surface extensions). Throws rtlab::EnvironmentError when
//! no Vulkan driver is installed or validation is requested but missing.
std::shared_ptr<InstanceState> createInstance(const ContextOptions& options, bool validation);

//! A physical device that rtlab can use, with its compute queue family.
struct PhysicalDeviceChoice {
    VkPhysicalDevice device = VK_NULL_HANDLE;
    std::uint32_t queueFamily = 0;
    DeviceInfo info;
};

//! Every usable physical device. Throws rtlab::EnvironmentError when there is none.
std::vector<PhysicalDeviceChoice> findUsableDevices(VkInstance instance);

//! The best device, or the best one whose name contains `nameFilter` (case-insensitive).
//! Throws rtlab::EnvironmentError listing the names when nothing matches.
PhysicalDeviceChoice chooseDevice(const std::vector<PhysicalDeviceChoice>& devices,
                                  const std::string& nameFilter, const char* filterOrigin);

//! A buffer with its own memory allocation.
struct RawBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr; //!< persistently mapped when host-visible
    bool coherent = true;
    VkDeviceSize size = 0;
};

//! The logical device. Shared by the Context and every object created from it.
struct DeviceState {
    std::shared_ptr<InstanceState> instance;
    VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    std::uint32_t queueFamily = 0;
    DeviceInfo info;
    VkPhysicalDeviceMemoryProperties memory{};
    VkPhysicalDeviceLimits limits{};
    bool stagingUploads = true;     //!< buffers live in memory the host cannot map
    bool keepStaging = true;        //!< reuse the two staging buffers below across transfers
    bool timestampsEnabled = false; //!< run() writes timestamp queries
    PFN_vkSetDebugUtilsObjectNameEXT setObjectNameFn = nullptr; //!< only with validation

    // For synchronous one-off transfers (uploads, downloads, layout changes).
    VkCommandPool transferPool = VK_NULL_HANDLE;
    VkCommandBuffer transferCommands = VK_NULL_HANDLE;
    VkFence transferFence = VK_NULL_HANDLE;
    std::mutex queueMutex;

    // The staging buffers kept between transfers (grown to the largest transfer up to
    // kKeptStagingLimit; larger ones get a buffer of their own), one per direction.
    RawBuffer uploadStaging;
    RawBuffer downloadStaging;
    std::mutex stagingMutex;

    DeviceState() = default;
    DeviceState(const DeviceState&) = delete;
    DeviceState& operator=(const DeviceState&) = delete;
    ~DeviceState();

    //! A memory type allowed by `typeBits` with all `required` flags, preferring one that also
    //! has `preferred`; UINT32_MAX when there is none.
    std::uint32_t findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                 VkMemoryPropertyFlags preferred = 0) const;

    //! Where a raw buffer's memory comes from.
    enum class MemoryKind {
        DeviceLocal,       //!< device-local, not mapped
        DeviceLocalMapped, //!< device-local and host-visible (unified memory), mapped
        HostStaging,       //!< host-visible (cached where possible), mapped
    };
    //! Creates a buffer and binds fresh memory of the given kind.
    RawBuffer createRawBuffer(VkDeviceSize size, VkBufferUsageFlags usage, MemoryKind kind,
                              const std::string& name);
    void destroyRawBuffer(RawBuffer& buffer);

    //! Records `record` into a command buffer between full barriers, submits it and waits.
    void submitAndWait(const std::function<void(VkCommandBuffer)>& record);

    //! Labels an object for debuggers and validation messages (no-op without debug utils).
    void setObjectName(VkObjectType type, std::uint64_t handle, const std::string& name);
};

//! Makes host writes to a mapped, non-coherent buffer visible to the device.
void flushMapped(DeviceState& device, const RawBuffer& raw);
//! Makes device writes to a mapped, non-coherent buffer visible to the host.
void invalidateMapped(DeviceState& device, const RawBuffer& raw);
//! Copies `data` into a temporary staging buffer and runs `copy(cmd, stagingBuffer)`.
void uploadThroughStaging(DeviceState& device, const void* data, std::size_t size,
                          const std::function<void(VkCommandBuffer, VkBuffer)>& copy);
//! Runs `copy(cmd, stagingBuffer)` and copies the staging buffer's first `size` bytes out.
void downloadThroughStaging(DeviceState& device, void* data, std::size_t size,
                            const std::function<void(VkCommandBuffer, VkBuffer)>& copy);

//! Appends a command to `list` that `encode` records into the command buffer of Context::run().
//! Like every command it is timed and separated from its neighbours by full barriers. What
//! `encode` uses must live until run() returns.
void appendEncodedCommand(CommandList& list, std::string label,
                          std::function<void(VkCommandBuffer)> encode);
//! The device that `list` records commands for.
const std::shared_ptr<DeviceState>& getRecordingDevice(CommandList& list);

//! Records a barrier that orders all earlier memory writes before all later accesses.
void recordFullBarrier(VkCommandBuffer commands);
//! Records a barrier that makes all earlier device writes visible to host reads.
void recordHostReadBarrier(VkCommandBuffer commands);

struct BufferState {
    std::shared_ptr<DeviceState> device;
    RawBuffer raw;
    std::string name;
    bool vertexIndexUsage = false; //!< created with BufferDesc::vertexIndexUsage
    bool direct = false;           //!< raw.mapped is the buffer's own memory: transfers are memcpys
    ~BufferState();
};

struct ImageState {
    std::shared_ptr<DeviceState> device;
    VkImage image = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkFormatFeatureFlags features = 0; //!< optimal-tiling features of the format
    ImageDesc desc;
    ~ImageState();
};

struct SamplerState {
    std::shared_ptr<DeviceState> device;
    VkSampler sampler = VK_NULL_HANDLE;
    SamplerDesc desc;
    ~SamplerState();
};

struct PipelineState {
    std::shared_ptr<DeviceState> device;
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
    std::string name;
    std::vector<BindingSlot> bindings;
    std::uint32_t pushConstantSize = 0;
    ~PipelineState();
};

//! What Context::run() reuses between submissions. Pools grow when a run needs more.
struct RunState {
    std::shared_ptr<DeviceState> device;
    VkCommandPool commandPool = VK_NULL_HANDLE;
    VkCommandBuffer commands = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkQueryPool queryPool = VK_NULL_HANDLE;
    std::uint32_t queryCapacity = 0;
    VkDescriptorPool descriptorPool = VK_NULL_HANDLE;
    std::uint32_t setCapacity = 0;
    std::uint32_t storageBufferCapacity = 0;
    std::uint32_t storageImageCapacity = 0;
    std::uint32_t sampledImageCapacity = 0;
    std::vector<CommandTime> log;  //!< every command timed since the last takeRunLog()
    std::uint64_t runCount = 0;    //!< runs submitted so far

    explicit RunState(std::shared_ptr<DeviceState> owner);
    RunState(const RunState&) = delete;
    RunState& operator=(const RunState&) = delete;
    ~RunState();
};

} // namespace rtlab::gpu::detail
