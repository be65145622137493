// Recording commands (with checks against the pipeline), encoding them with timestamps and
// descriptor sets, submitting, and reading back the timings.

#include "gpu/commands.h"

#include <algorithm>
#include <chrono>
#include <cstring>

#include "core/error.h"
#include "gpu/bus_counters.h"
#include "gpu/timestamps.h"
#include "gpu/vulkan_internal.h"

namespace rtlab::gpu {

// ---- Binding / RunResult -----------------------------------------------------------------------

Binding Binding::storageBuffer(std::uint32_t binding, const Buffer& buffer)
{
    Binding b;
    b.binding = binding;
    b.type = BindingType::StorageBuffer;
    b.buffer = &buffer;
    return b;
}

Binding Binding::storageImage(std::uint32_t binding, const Image& image)
{
    Binding b;
    b.binding = binding;
    b.type = BindingType::StorageImage;
    b.image = &image;
    return b;
}

Binding Binding::sampledImage(std::uint32_t binding, const Image& image, const Sampler& sampler)
{
    Binding b;
    b.binding = binding;
    b.type = BindingType::SampledImage;
    b.image = &image;
    b.sampler = &sampler;
    return b;
}

std::optional<double> RunResult::sumGpuMs(std::string_view label) const
{
    std::optional<double> sum;
    for (const CommandTime& c : commands) {
        if (c.label != label)
            continue;
        if (!c.gpuMs)
            return std::nullopt;
        sum = sum.value_or(0.0) + *c.gpuMs;
    }
    return sum;
}

// ---- CommandList -------------------------------------------------------------------------------

namespace {

enum class CommandKind { Dispatch, Fill, Copy, Encoded };

struct RecordedCommand {
    CommandKind kind = CommandKind::Dispatch;
    std::string label;
    const detail::PipelineState* pipeline = nullptr;
    std::vector<Binding> bindings; // sorted by binding number
    std::vector<std::byte> pushConstants;
    GroupCount groups;
    VkBuffer source = VK_NULL_HANDLE;
    VkBuffer destination = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    VkDeviceSize offset = 0; // Fill; DispatchIndirect: of the arguments
    VkBuffer indirect = VK_NULL_HANDLE; // Dispatch: read the group count from here
    std::uint32_t fillValue = 0;
    std::function<void(VkCommandBuffer)> encode; // CommandKind::Encoded
};

} // namespace

struct CommandList::Impl {
    std::shared_ptr<detail::DeviceState> device;
    std::vector<RecordedCommand> commands;
};

void detail::appendEncodedCommand(CommandList& list, std::string label,
                                  std::function<void(VkCommandBuffer)> encode)
{
    RecordedCommand cmd;
    cmd.kind = CommandKind::Encoded;
    cmd.label = std::move(label);
    cmd.encode = std::move(encode);
    list.getImpl().commands.push_back(std::move(cmd));
}

const std::shared_ptr<detail::DeviceState>& detail::getRecordingDevice(CommandList& list)
{
    return list.getImpl().device;
}

CommandList::CommandList(std::unique_ptr<Impl> impl) : mImpl(std::move(impl)) {}
CommandList::~CommandList() = default;

std::size_t CommandList::countCommands() const
{
    return mImpl->commands.size();
}

void CommandList::dispatch(const ComputePipeline& pipeline, const std::vector<Binding>& bindings,
                           GroupCount groups, std::string_view label)
{
    dispatch(pipeline, bindings, PushConstants(), groups, label);
}

namespace {

void checkBindings(const detail::PipelineState& pipe, const std::vector<Binding>& given,
                   const detail::DeviceState* device)
{
    auto fail = [&](const std::string& why) {
        throw Error("dispatch of '" + pipe.name + "': " + why);
    };
    for (const BindingSlot& slot : pipe.bindings) {
        const auto n = std::count_if(given.begin(), given.end(),
                                     [&](const Binding& b) { return b.binding == slot.binding; });
        if (n == 0)
            fail("binding " + std::to_string(slot.binding) + " (" + getBindingTypeName(slot.type) +
                 ") is not bound");
        if (n > 1)
            fail("binding " + std::to_string(slot.binding) + " is bound more than once");
    }
    for (const Binding& b : given) {
        const auto slot =
            std::find_if(pipe.bindings.begin(), pipe.bindings.end(),
                         [&](const BindingSlot& s) { return s.binding == b.binding; });
        const std::string where = "binding " + std::to_string(b.binding);
        if (slot == pipe.bindings.end())
            fail(where + " is not part of the pipeline layout");
        if (slot->type != b.type)
            fail(where + " expects a " + getBindingTypeName(slot->type) + ", got a " +
                 getBindingTypeName(b.type));
        if (b.type == BindingType::StorageBuffer) {
            if (b.buffer == nullptr || !b.buffer->isValid())
                fail(where + ": empty buffer");
            if (b.buffer->getState().device.get() != device)
                fail(where + ": buffer belongs to another context");
            continue;
        }
        if (b.image == nullptr || !b.image->isValid())
            fail(where + ": empty image");
        const detail::ImageState& image = b.image->getState();
        if (image.device.get() != device)
            fail(where + ": image belongs to another context");
        const auto usage = static_cast<std::uint32_t>(image.desc.usage);
        if (b.type == BindingType::StorageImage) {
            if (!(usage & static_cast<std::uint32_t>(ImageUsage::Storage)))
                fail(where + ": image '" + image.desc.name + "' was not created for storage use");
            continue;
        }
        if (!(usage & static_cast<std::uint32_t>(ImageUsage::Sampled)))
            fail(where + ": image '" + image.desc.name + "' was not created for sampling");
        if (b.sampler == nullptr || !b.sampler->isValid())
            fail(where + ": empty sampler");
        if (b.sampler->getDesc().filter == Filter::Linear &&
            !(image.features & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT))
            fail(where + ": this device cannot filter format " +
                 std::string(getFormatName(image.desc.format)) + " linearly");
    }
}

} // namespace

void CommandList::dispatch(const ComputePipeline& pipeline, const std::vector<Binding>& bindings,
                           PushConstants pushConstants, GroupCount groups, std::string_view label)
{
    const detail::PipelineState& pipe = pipeline.getState();
    const detail::DeviceState& device = *mImpl->device;
    if (pipe.device != mImpl->device)
        throw Error("dispatch of '" + pipe.name + "': pipeline belongs to another context");
    if (pushConstants.getSize() != pipe.pushConstantSize)
        throw Error("dispatch of '" + pipe.name + "': " + std::to_string(pushConstants.getSize()) +
                    " bytes of push constants given, the pipeline declares " +
                    std::to_string(pipe.pushConstantSize));
    const std::uint32_t counts[3] = {groups.x, groups.y, groups.z};
    for (int i = 0; i < 3; ++i) {
        if (counts[i] > device.limits.maxComputeWorkGroupCount[i])
            throw Error("dispatch of '" + pipe.name + "': " + std::to_string(counts[i]) +
                        " work groups in dimension " + std::to_string(i) +
                        " exceed the device limit of " +
                        std::to_string(device.limits.maxComputeWorkGroupCount[i]));
    }
    checkBindings(pipe, bindings, &device);

    RecordedCommand cmd;
    cmd.kind = CommandKind::Dispatch;
    cmd.label = label.empty() ? pipe.name : std::string(label);
    cmd.pipeline = &pipe;
    cmd.bindings = bindings;
    std::sort(cmd.bindings.begin(), cmd.bindings.end(),
              [](const Binding& a, const Binding& b) { return a.binding < b.binding; });
    cmd.pushConstants.assign(pushConstants.getData(),
                             pushConstants.getData() + pushConstants.getSize());
    cmd.groups = groups;
    mImpl->commands.push_back(std::move(cmd));
}

void CommandList::dispatchIndirect(const ComputePipeline& pipeline, const std::vector<Binding>& bindings,
                                   PushConstants pushConstants, const Buffer& args, std::size_t offset,
                                   std::string_view label)
{
    const detail::BufferState& state = args.getState();
    if (state.device != mImpl->device)
        throw Error("dispatchIndirect: buffer '" + state.name + "' belongs to another context");
    if (offset % 4 != 0 || offset > state.raw.size || state.raw.size - offset < 3 * sizeof(std::uint32_t))
        throw Error("dispatchIndirect: no three words of arguments at byte " + std::to_string(offset) +
                    " of buffer '" + state.name + "' (" + std::to_string(state.raw.size) + " bytes)");
    dispatch(pipeline, bindings, pushConstants, GroupCount{0, 0, 0}, label);
    mImpl->commands.back().indirect = state.raw.buffer;
    mImpl->commands.back().offset = offset;
}

void CommandList::fillBuffer(const Buffer& buffer, std::uint32_t value, std::string_view label)
{
    const detail::BufferState& state = buffer.getState();
    if (state.device != mImpl->device)
        throw Error("fillBuffer: buffer '" + state.name + "' belongs to another context");
    RecordedCommand cmd;
    cmd.kind = CommandKind::Fill;
    cmd.label = label.empty() ? std::string("fillBuffer") : std::string(label);
    cmd.destination = state.raw.buffer;
    cmd.size = state.raw.size & ~VkDeviceSize{3};
    cmd.fillValue = value;
    mImpl->commands.push_back(std::move(cmd));
}

void CommandList::fillBuffer(const Buffer& buffer, std::uint32_t value, std::size_t offset,
                             std::size_t size, std::string_view label)
{
    const detail::BufferState& state = buffer.getState();
    if (offset % 4 != 0 || size % 4 != 0 || offset > state.raw.size || size > state.raw.size - offset)
        throw Error("fillBuffer: [" + std::to_string(offset) + ", " + std::to_string(offset + size) +
                    ") is not a range of whole words within buffer '" + state.name + "' of " +
                    std::to_string(state.raw.size) + " bytes");
    fillBuffer(buffer, value, label);
    mImpl->commands.back().offset = offset;
    mImpl->commands.back().size = size;
}

void CommandList::copyBuffer(const Buffer& source, const Buffer& destination,
                             std::string_view label)
{
    const detail::BufferState& src = source.getState();
    const detail::BufferState& dst = destination.getState();
    if (src.device != mImpl->device || dst.device != mImpl->device)
        throw Error("copyBuffer: buffer belongs to another context");
    if (&src == &dst)
        throw Error("copyBuffer: source and destination are the same buffer '" + src.name + "'");
    RecordedCommand cmd;
    cmd.kind = CommandKind::Copy;
    cmd.label = label.empty() ? std::string("copyBuffer") : std::string(label);
    cmd.source = src.raw.buffer;
    cmd.destination = dst.raw.buffer;
    cmd.size = std::min(src.raw.size, dst.raw.size);
    mImpl->commands.push_back(std::move(cmd));
}

// ---- Context::run ------------------------------------------------------------------------------

namespace {

using Clock = std::chrono::steady_clock;

double elapsedMs(Clock::time_point from, Clock::time_point to)
{
    return std::chrono::duration<double, std::milli>(to - from).count();
}

void ensureQueryCapacity(detail::RunState& run, std::uint32_t needed)
{
    if (run.queryCapacity >= needed)
        return;
    VkDevice device = run.device->device;
    if (run.queryPool != VK_NULL_HANDLE)
        vkDestroyQueryPool(device, run.queryPool, nullptr);
    run.queryPool = VK_NULL_HANDLE;
    run.queryCapacity = 0;
    const std::uint32_t capacity = std::max(needed, 64u);
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    info.queryCount = capacity;
    detail::checkResult(vkCreateQueryPool(device, &info, nullptr, &run.queryPool),
                        "vkCreateQueryPool");
    run.queryCapacity = capacity;
}

void prepareDescriptorPool(detail::RunState& run, const std::vector<RecordedCommand>& commands)
{
    std::uint32_t sets = 0, buffers = 0, images = 0, sampled = 0;
    for (const RecordedCommand& c : commands) {
        if (c.kind != CommandKind::Dispatch || c.bindings.empty())
            continue;
        ++sets;
        for (const Binding& b : c.bindings) {
            buffers += b.type == BindingType::StorageBuffer;
            images += b.type == BindingType::StorageImage;
            sampled += b.type == BindingType::SampledImage;
        }
    }
    VkDevice device = run.device->device;
    if (run.descriptorPool != VK_NULL_HANDLE && sets <= run.setCapacity &&
        buffers <= run.storageBufferCapacity && images <= run.storageImageCapacity &&
        sampled <= run.sampledImageCapacity) {
        detail::checkResult(vkResetDescriptorPool(device, run.descriptorPool, 0),
                            "vkResetDescriptorPool");
        return;
    }
    if (run.descriptorPool != VK_NULL_HANDLE)
        vkDestroyDescriptorPool(device, run.descriptorPool, nullptr);
    run.descriptorPool = VK_NULL_HANDLE;
    auto grow = [](std::uint32_t need, std::uint32_t old) {
        return std::max({need, 2 * old, 16u});
    };
    run.setCapacity = grow(sets, run.setCapacity);
    run.storageBufferCapacity = grow(buffers, run.storageBufferCapacity);
    run.storageImageCapacity = grow(images, run.storageImageCapacity);
    run.sampledImageCapacity = grow(sampled, run.sampledImageCapacity);
    const VkDescriptorPoolSize sizes[] = {
        {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, run.storageBufferCapacity},
        {VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, run.storageImageCapacity},
        {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, run.sampledImageCapacity},
    };
    VkDescriptorPoolCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    info.maxSets = run.setCapacity;
    info.poolSizeCount = 3;
    info.pPoolSizes = sizes;
    detail::checkResult(vkCreateDescriptorPool(device, &info, nullptr, &run.descriptorPool),
                        "vkCreateDescriptorPool");
}

// Allocates and writes one descriptor set per dispatch that has bindings.
std::vector<VkDescriptorSet> writeDescriptorSets(detail::RunState& run,
                                                 const std::vector<RecordedCommand>& commands)
{
    VkDevice device = run.device->device;
    std::vector<VkDescriptorSet> sets(commands.size(), VK_NULL_HANDLE);
    std::size_t bindingCount = 0;
    for (const RecordedCommand& c : commands)
        bindingCount += c.bindings.size();
    std::vector<VkDescriptorBufferInfo> bufferInfos;
    std::vector<VkDescriptorImageInfo> imageInfos;
    std::vector<VkWriteDescriptorSet> writes;
    bufferInfos.reserve(bindingCount); // pointers into these must stay valid
    imageInfos.reserve(bindingCount);
    writes.reserve(bindingCount);
    for (std::size_t i = 0; i < commands.size(); ++i) {
        const RecordedCommand& c = commands[i];
        if (c.kind != CommandKind::Dispatch || c.bindings.empty())
            continue;
        VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        alloc.descriptorPool = run.descriptorPool;
        alloc.descriptorSetCount = 1;
        alloc.pSetLayouts = &c.pipeline->setLayout;
        detail::checkResult(vkAllocateDescriptorSets(device, &alloc, &sets[i]),
                            "vkAllocateDescriptorSets");
        for (const Binding& b : c.bindings) {
            VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            w.dstSet = sets[i];
            w.dstBinding = b.binding;
            w.descriptorCount = 1;
            w.descriptorType = detail::toVkDescriptorType(b.type);
            if (b.type == BindingType::StorageBuffer) {
                bufferInfos.push_back({b.buffer->getState().raw.buffer, 0, VK_WHOLE_SIZE});
                w.pBufferInfo = &bufferInfos.back();
            } else {
                const VkSampler sampler = b.type == BindingType::SampledImage
                                              ? b.sampler->getState().sampler
                                              : VK_NULL_HANDLE;
                imageInfos.push_back({sampler, b.image->getState().view, VK_IMAGE_LAYOUT_GENERAL});
                w.pImageInfo = &imageInfos.back();
            }
            writes.push_back(w);
        }
    }
    if (!writes.empty())
        vkUpdateDescriptorSets(device, static_cast<std::uint32_t>(writes.size()), writes.data(), 0,
                               nullptr);
    return sets;
}

void encodeCommand(VkCommandBuffer cb, const RecordedCommand& c, VkDescriptorSet set)
{
    switch (c.kind) {
    case CommandKind::Dispatch:
        vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, c.pipeline->pipeline);
        if (set != VK_NULL_HANDLE)
            vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, c.pipeline->layout, 0, 1,
                                    &set, 0, nullptr);
        if (!c.pushConstants.empty())
            vkCmdPushConstants(cb, c.pipeline->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0,
                               static_cast<std::uint32_t>(c.pushConstants.size()),
                               c.pushConstants.data());
        if (c.indirect != VK_NULL_HANDLE)
            vkCmdDispatchIndirect(cb, c.indirect, c.offset);
        else
            vkCmdDispatch(cb, c.groups.x, c.groups.y, c.groups.z);
        break;
    case CommandKind::Fill:
        if (c.size > 0)
            vkCmdFillBuffer(cb, c.destination, c.offset, c.size, c.fillValue);
        break;
    case CommandKind::Copy: {
        const VkBufferCopy region{0, 0, c.size};
        vkCmdCopyBuffer(cb, c.source, c.destination, 1, &region);
        break;
    }
    case CommandKind::Encoded:
        c.encode(cb);
        break;
    }
}

} // namespace

RunResult Context::run(const std::function<void(CommandList&)>& record)
{
    const Clock::time_point recordStart = Clock::now();
    auto impl = std::make_unique<CommandList::Impl>();
    impl->device = mDevice;
    CommandList list(std::move(impl));
    record(list);
    const std::vector<RecordedCommand>& commands = list.getImpl().commands;
    const auto count = static_cast<std::uint32_t>(commands.size());

    detail::RunState& run = *mRun;
    const DeviceInfo& info = mDevice->info;
    const bool timestamps = mDevice->timestampsEnabled && count > 0;
    if (timestamps)
        ensureQueryCapacity(run, 2 * count);
    prepareDescriptorPool(run, commands);
    const std::vector<VkDescriptorSet> sets = writeDescriptorSets(run, commands);

    VkCommandBuffer cb = run.commands;
    detail::checkResult(vkResetCommandBuffer(cb, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    detail::checkResult(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
    if (timestamps)
        vkCmdResetQueryPool(cb, run.queryPool, 0, 2 * count);
    for (std::uint32_t i = 0; i < count; ++i) {
        detail::recordFullBarrier(cb); // also orders against earlier submissions and uploads
        if (timestamps)
            vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, run.queryPool, 2 * i);
        encodeCommand(cb, commands[i], sets[i]);
        if (timestamps)
            vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, run.queryPool, 2 * i + 1);
    }
    detail::recordHostReadBarrier(cb);
    detail::checkResult(vkEndCommandBuffer(cb), "vkEndCommandBuffer");

    RunResult result;
    const Clock::time_point submitStart = Clock::now();
    result.cpuRecordMs = elapsedMs(recordStart, submitStart);
    {
        std::lock_guard lock(mDevice->queueMutex);
        detail::checkResult(vkResetFences(mDevice->device, 1, &run.fence), "vkResetFences");
        VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        submit.commandBufferCount = 1;
        submit.pCommandBuffers = &cb;
        detail::checkResult(vkQueueSubmit(mDevice->queue, 1, &submit, run.fence), "vkQueueSubmit");
        detail::countSubmit();
        const Clock::time_point waitStart = Clock::now();
        detail::checkResult(vkWaitForFences(mDevice->device, 1, &run.fence, VK_TRUE, UINT64_MAX),
                            "vkWaitForFences");
        detail::countWait(elapsedMs(waitStart, Clock::now()));
    }
    result.cpuSubmitMs = elapsedMs(submitStart, Clock::now());

    std::vector<std::uint64_t> ticks(2 * std::size_t{count}, 0);
    if (timestamps) {
        detail::checkResult(
            vkGetQueryPoolResults(mDevice->device, run.queryPool, 0, 2 * count,
                                  ticks.size() * sizeof(std::uint64_t), ticks.data(),
                                  sizeof(std::uint64_t),
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
    }
    const std::uint32_t bits = timestamps ? info.timestampValidBits : 0;
    const std::uint64_t runIndex = ++run.runCount;
    for (std::uint32_t i = 0; i < count; ++i) {
        result.commands.push_back(
            {commands[i].label,
             convertTicksToMs(ticks[2 * i], ticks[2 * i + 1], bits, info.timestampPeriodNs), runIndex,
             result.cpuSubmitMs});
    }
    if (count > 0)
        result.gpuTotalMs =
            convertTicksToMs(ticks[0], ticks[2 * count - 1], bits, info.timestampPeriodNs);
    run.log.insert(run.log.end(), result.commands.begin(), result.commands.end());
    return result;
}

std::vector<CommandTime> Context::takeRunLog()
{
    std::vector<CommandTime> log;
    log.swap(mRun->log);
    return log;
}

} // namespace rtlab::gpu
