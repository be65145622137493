#pragma once
// The headless Vulkan context: instance, chosen physical device, one compute queue (which also
// draws where its family supports graphics), optional validation. Everything else (buffers,
// images, pipelines, render targets, timed submissions) is created from it.
//
// Environment variables read when a Context is created:
//   RTLAB_VK_DEVICE=<substring>  pick the device whose name contains it (case-insensitive),
//                                unless ContextOptions::deviceName is set
//   RTLAB_VK_VALIDATION=1        turn on VK_LAYER_KHRONOS_validation (also "true", "on", "yes")
//
// Thread safety: a Context and the objects made from it are meant to be used from one thread.

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "gpu/commands.h"
#include "gpu/format.h"
#include "gpu/graphics.h"
#include "gpu/pipeline.h"
#include "gpu/resources.h"

namespace rtlab::gpu {

namespace detail {
struct DeviceState;
struct RunState;
} // namespace detail

//! Kind of physical device, as Vulkan reports it.
enum class DeviceType { Other, IntegratedGpu, DiscreteGpu, VirtualGpu, Cpu };

//! What rtlab knows about a physical device. Everything here is fixed for the device's lifetime.
struct DeviceInfo {
    std::string name; //!< e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    DeviceType type = DeviceType::Other;
    bool isCpu = false; //!< true for software rasterisers such as lavapipe
    std::uint32_t vendorId = 0;
    std::string vendorName; //!< "NVIDIA", "AMD", "Intel", "Mesa", ... or the id in hex
    std::uint32_t deviceId = 0;
    std::string apiVersion;          //!< "1.3.230"
    std::string driverName;          //!< e.g. "llvmpipe" (empty when the driver does not say)
    std::string driverInfo;          //!< e.g. "Mesa 22.3.6 (LLVM 15.0.6)"
    std::uint32_t driverVersion = 0; //!< raw, vendor-specific encoding
    std::string driverVersionString; //!< decoded with the vendor's convention

    double timestampPeriodNs = 0.0;       //!< nanoseconds per timestamp tick
    std::uint32_t timestampValidBits = 0; //!< of the compute queue; 0 = no timestamps
    bool timestampsSupported = false;     //!< timestampValidBits > 0 and a positive period

    std::uint32_t subTexelPrecisionBits = 0; //!< fraction bits of filtering weights
    std::uint32_t subPixelPrecisionBits = 0; //!< fraction bits of rasterised vertex positions
    std::uint32_t maxPushConstantsSize = 0;
    std::uint32_t maxComputeWorkGroupInvocations = 0;
    std::uint32_t maxComputeWorkGroupSize[3] = {0, 0, 0};
    std::uint32_t maxComputeWorkGroupCount[3] = {0, 0, 0};
    std::uint32_t maxImageDimension2D = 0;
    std::uint32_t maxImageDimension3D = 0;
    std::uint64_t deviceLocalBytes = 0; //!< size of the largest device-local memory heap

    //! One line: "name [type, vendor, driver driverInfo]".
    std::string describe() const;
};

//! "discrete GPU", "integrated GPU", "virtual GPU", "CPU", "other".
const char* getDeviceTypeName(DeviceType type);

//! Thread-safe list of the validation layer's warnings and errors. It outlives the Context that
//! fills it when a shared_ptr to it is kept, so messages raised while the device is destroyed
//! (leaked objects, for example) are seen as well.
class ValidationLog {
public:
    //! Adds one message (called by the debug messenger).
    void addMessage(std::string message);
    //! A copy of every message so far, oldest first.
    std::vector<std::string> getMessages() const;
    //! Number of messages so far.
    std::size_t countMessages() const;
    //! Forgets all messages (for tests that provoke one on purpose).
    void clearMessages();

private:
    mutable std::mutex mMutex;
    std::vector<std::string> mMessages;
};

//! Options for creating a Context.
struct ContextOptions {
    //! Case-insensitive substring of the device name to use. Empty: $RTLAB_VK_DEVICE, and when
    //! that is unset too, the best device (discrete GPU > integrated GPU > virtual GPU > CPU).
    std::string deviceName;
    //! Turn on VK_LAYER_KHRONOS_validation (with synchronisation validation) and record its
    //! warnings and errors in the validation log. $RTLAB_VK_VALIDATION=1 turns it on as well.
    bool enableValidation = false;
    //! Also print each validation message to stderr when it arrives.
    bool echoValidationMessages = true;
    //! Record validation messages here instead of in a new log (lets a caller see messages of
    //! a Context it does not own, such as the one runSmokeTest() creates).
    std::shared_ptr<ValidationLog> validationLog;
    //! Move buffer data through staging buffers even where device memory is host-visible
    //! (tests use this to cover the path that discrete GPUs take). The environment variable
    //! RTLAB_VK_STAGING=1 does the same for every context of a process.
    bool forceStagingUploads = false;
    //! Keep one host staging buffer per direction between transfers (grown to the largest
    //! transfer up to 64 MiB) instead of allocating one per upload or download. False: the
    //! allocation per transfer, the baseline of `gpu_transfer_benchmark`.
    bool keepStagingBuffers = true;
    //! Record no timestamps, as on a queue without timestamp support: GPU times are then
    //! reported as unavailable (empty), never as zero.
    bool disableTimestamps = false;
    //! Application name given to the driver.
    std::string applicationName = "rtlab";
};

//! A Vulkan instance and device with one compute queue. Move-only. Objects created from it keep
//! the device alive, so they may be destroyed after the Context.
class Context {
public:
    //! Creates the instance and picks the device. Throws rtlab::EnvironmentError when there is
    //! no usable Vulkan device (with the package to install), when the requested device name
    //! matches nothing (listing the available names), or when validation is requested but the
    //! layer is not installed.
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(Context&&) noexcept;
    Context& operator=(Context&&) noexcept;

    //! Every Vulkan device that rtlab could use on this machine, in enumeration order.
    //! Throws rtlab::EnvironmentError like the constructor when there is none.
    static std::vector<DeviceInfo> enumerateDevices();

    //! The device in use.
    const DeviceInfo& getDeviceInfo() const;
    //! Whether the validation layer is active.
    bool isValidationEnabled() const;
    //! The validation messages (empty and unused without validation).
    std::shared_ptr<ValidationLog> getValidationLog() const;
    //! Whether buffers are written and read through staging buffers.
    bool usesStagingUploads() const;
    //! Whether run() measures GPU times (the queue supports timestamps and they are not
    //! disabled).
    bool hasGpuTimestamps() const;

    //! A storage buffer in device memory. Contents are undefined until written.
    Buffer createBuffer(const BufferDesc& desc);
    //! A 2D or 3D image (in VK_IMAGE_LAYOUT_GENERAL between commands). Contents are undefined
    //! until written.
    Image createImage(const ImageDesc& desc);
    //! A sampler for combined image-sampler bindings.
    Sampler createSampler(const SamplerDesc& desc = {});
    //! A compute pipeline. Throws rtlab::Error when the device rejects it or the description
    //! exceeds device limits.
    ComputePipeline createPipeline(const ComputePipelineDesc& desc);
    //! A graphics pipeline (gpu/graphics.h). Throws rtlab::Error when the queue cannot draw, a
    //! format cannot be rendered to, or the device rejects the pipeline.
    GraphicsPipeline createGraphicsPipeline(const GraphicsPipelineDesc& desc);
    //! Colour and depth attachments of one size that draws render into (gpu/graphics.h).
    RenderTarget createRenderTarget(const RenderTargetDesc& desc);

    //! Records the commands that `record` issues into one command buffer, submits it, waits for
    //! completion and returns per-command GPU times and the CPU wall time of the submission.
    //! Consecutive commands are separated by full memory barriers. Exceptions thrown while
    //! recording propagate and nothing is submitted.
    RunResult run(const std::function<void(CommandList&)>& record);
    //! Every command timed by run() since the last call, oldest first, and clears the list.
    //! The timing harness reads it around a technique's work, so techniques never report their
    //! own GPU time.
    std::vector<CommandTime> takeRunLog();

    //! Waits until the device is idle.
    void waitIdle();

private:
    std::shared_ptr<detail::DeviceState> mDevice;
    std::unique_ptr<detail::RunState> mRun;
};

} // namespace rtlab::gpu
