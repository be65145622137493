#pragma once
// Recording work for Context::run(): dispatches, draws and small transfer commands, each timed
// on the GPU with a pair of timestamps.
//
//   gpu::RunResult r = ctx.run([&](gpu::CommandList& cmd) {
//       cmd.dispatch(blur, {gpu::Binding::storageImage(0, src), gpu::Binding::storageImage(1,
//       dst)},
//                    gpu::PushConstants(params), gpu::GroupCount{w / 8, h / 8}, "blur");
//   });
//   std::optional<double> blurMs = r.sumGpuMs("blur");
//   double wallMs = r.cpuSubmitMs;

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "gpu/pipeline.h"
#include "gpu/resources.h"

namespace rtlab::gpu {

class GraphicsPipeline;
class RenderTarget;
struct IndexedDraw;

//! A resource bound to one binding of descriptor set 0 for a dispatch. The resource must live
//! until Context::run() returns.
struct Binding {
    std::uint32_t binding = 0;
    BindingType type = BindingType::StorageBuffer;
    const Buffer* buffer = nullptr;
    const Image* image = nullptr;
    const Sampler* sampler = nullptr;

    static Binding storageBuffer(std::uint32_t binding, const Buffer& buffer);
    static Binding storageImage(std::uint32_t binding, const Image& image);
    //! A combined image sampler.
    static Binding sampledImage(std::uint32_t binding, const Image& image, const Sampler& sampler);
};

//! Number of work groups in x, y and z.
struct GroupCount {
    std::uint32_t x = 1;
    std::uint32_t y = 1;
    std::uint32_t z = 1;
};

//! ceil(items / groupSize): work groups needed to cover `items` invocations.
constexpr std::uint32_t computeGroupCount(std::uint64_t items, std::uint32_t groupSize)
{
    return static_cast<std::uint32_t>((items + groupSize - 1) / groupSize);
}

//! A view of push-constant bytes. Copied when the dispatch is recorded.
class PushConstants {
public:
    //! No push constants.
    PushConstants() = default;
    //! The bytes of `value`, which must outlive the dispatch call.
    template <PlainData T>
    explicit PushConstants(const T& value)
        : mData(reinterpret_cast<const std::byte*>(&value)), mSize(sizeof(T))
    {
    }
    //! `size` bytes at `data`, which must outlive the dispatch call.
    PushConstants(const void* data, std::size_t size)
        : mData(static_cast<const std::byte*>(data)), mSize(size)
    {
    }

    const std::byte* getData() const { return mData; }
    std::size_t getSize() const { return mSize; }

private:
    const std::byte* mData = nullptr;
    std::size_t mSize = 0;
};

//! GPU time of one recorded command.
struct CommandTime {
    std::string label;           //!< the label given, or the pipeline name / command kind
    std::optional<double> gpuMs; //!< empty when the queue has no timestamps
    std::uint64_t runIndex = 0;  //!< which Context::run() recorded it (counts from 1 per Context)
    double runSubmitMs = 0.0;    //!< wall time from submit to fence of that whole run
};

//! What Context::run() measured.
struct RunResult {
    std::vector<CommandTime> commands; //!< in recording order
    //! From the start of the first command to the end of the last; empty without timestamps.
    std::optional<double> gpuTotalMs;
    double cpuRecordMs = 0.0; //!< recording and encoding the command buffer
    double cpuSubmitMs = 0.0; //!< wall time from vkQueueSubmit until the fence was signalled

    //! Sum of the GPU times of the commands with this label; empty when none has that label
    //! or timestamps are unavailable.
    std::optional<double> sumGpuMs(std::string_view label) const;
};

//! Collects commands during Context::run(). Bindings and push-constant sizes are checked
//! against the pipeline when the command is recorded; mistakes throw rtlab::Error.
class CommandList {
public:
    ~CommandList();
    CommandList(const CommandList&) = delete;
    CommandList& operator=(const CommandList&) = delete;

    //! Dispatches `groups` work groups of `pipeline` with `bindings` (every binding of the
    //! pipeline exactly once). An empty label uses the pipeline name.
    void dispatch(const ComputePipeline& pipeline, const std::vector<Binding>& bindings,
                  GroupCount groups, std::string_view label = {});
    //! Same, with push constants (their size must equal the pipeline's push-constant size).
    void dispatch(const ComputePipeline& pipeline, const std::vector<Binding>& bindings,
                  PushConstants pushConstants, GroupCount groups, std::string_view label = {});
    //! Dispatches with the group count read on the device from `args` at `offset` (three
    //! uint32: x, y, z, as an earlier command wrote them; vkCmdDispatchIndirect), so that work
    //! whose size the device computes needs no read-back. A count beyond the device's limits is
    //! undefined behaviour in Vulkan: the writer must bound it.
    void dispatchIndirect(const ComputePipeline& pipeline, const std::vector<Binding>& bindings,
                          PushConstants pushConstants, const Buffer& args, std::size_t offset,
                          std::string_view label = {});
    //! Sets every 32-bit word of the buffer to `value`.
    void fillBuffer(const Buffer& buffer, std::uint32_t value, std::string_view label = {});
    //! Sets the 32-bit words of [offset, offset + size) to `value` (both multiples of 4 within
    //! the buffer; throws rtlab::Error otherwise).
    void fillBuffer(const Buffer& buffer, std::uint32_t value, std::size_t offset, std::size_t size,
                    std::string_view label = {});
    //! Copies min(source size, destination size) bytes.
    void copyBuffer(const Buffer& source, const Buffer& destination, std::string_view label = {});
    //! Draws indexed triangles with `pipeline` into `target` in one render pass (see
    //! gpu/graphics.h). Push-constant size must equal the pipeline's. An empty label uses the
    //! pipeline name.
    void drawIndexed(const GraphicsPipeline& pipeline, const RenderTarget& target,
                     const IndexedDraw& draw, PushConstants pushConstants,
                     std::string_view label = {});

    //! Number of commands recorded so far.
    std::size_t countCommands() const;

    struct Impl;
    Impl& getImpl() { return *mImpl; }

private:
    friend class Context;
    explicit CommandList(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> mImpl;
};

} // namespace rtlab::gpu
