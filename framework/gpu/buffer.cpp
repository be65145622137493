// Storage buffers and their upload/download paths (mapped on unified memory, staged otherwise).

#include "gpu/resources.h"

#include <cstring>
#include <mutex>

#include "gpu/bus_counters.h"
#include "core/error.h"
#include "gpu/vulkan_internal.h"

namespace rtlab::gpu {

namespace detail {

namespace {

// Transfers up to this size reuse the device's kept staging buffer of their direction.
constexpr VkDeviceSize kKeptStagingLimit = VkDeviceSize(64) << 20;

// The staging buffer of one transfer: the device's kept buffer of that direction (locked for
// the transfer, grown to a power of two when too small) or, when the device keeps none or the
// transfer is larger than the limit, a temporary one freed on scope exit. A kept buffer saves
// the allocation (and on a discrete GPU the pinning of host pages) of every transfer.
class StagingBuffer {
public:
    StagingBuffer(DeviceState& device, VkDeviceSize size, bool upload) : mDevice(device)
    {
        const VkBufferUsageFlags usage =
            VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        if (!device.keepStaging || size > kKeptStagingLimit) {
            mOwned = device.createRawBuffer(size, usage, DeviceState::MemoryKind::HostStaging,
                                            "staging");
            mRaw = &mOwned;
            return;
        }
        mLock = std::unique_lock(device.stagingMutex);
        RawBuffer& kept = upload ? device.uploadStaging : device.downloadStaging;
        if (kept.size < size) {
            VkDeviceSize capacity = VkDeviceSize(1) << 20;
            while (capacity < size)
                capacity *= 2;
            device.destroyRawBuffer(kept);
            kept = device.createRawBuffer(capacity, usage, DeviceState::MemoryKind::HostStaging,
                                          upload ? "staging.upload" : "staging.download");
        }
        mRaw = &kept;
    }
    ~StagingBuffer()
    {
        if (mRaw == &mOwned)
            mDevice.destroyRawBuffer(mOwned);
    }
    StagingBuffer(const StagingBuffer&) = delete;
    StagingBuffer& operator=(const StagingBuffer&) = delete;
    const RawBuffer& getRaw() const { return *mRaw; }

private:
    DeviceState& mDevice;
    RawBuffer mOwned;
    const RawBuffer* mRaw = nullptr;
    std::unique_lock<std::mutex> mLock;
};

} // namespace

BufferState::~BufferState()
{
    if (device)
        device->destroyRawBuffer(raw);
}

void flushMapped(DeviceState& device, const RawBuffer& raw)
{
    if (raw.coherent)
        return;
    VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    range.memory = raw.memory;
    range.size = VK_WHOLE_SIZE;
    checkResult(vkFlushMappedMemoryRanges(device.device, 1, &range), "vkFlushMappedMemoryRanges");
}

void invalidateMapped(DeviceState& device, const RawBuffer& raw)
{
    if (raw.coherent)
        return;
    VkMappedMemoryRange range{VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
    range.memory = raw.memory;
    range.size = VK_WHOLE_SIZE;
    checkResult(vkInvalidateMappedMemoryRanges(device.device, 1, &range),
                "vkInvalidateMappedMemoryRanges");
}

void uploadThroughStaging(DeviceState& device, const void* data, std::size_t size,
                          const std::function<void(VkCommandBuffer, VkBuffer)>& copy)
{
    countUpload(size);
    StagingBuffer staging(device, size, true);
    std::memcpy(staging.getRaw().mapped, data, size);
    flushMapped(device, staging.getRaw());
    device.submitAndWait([&](VkCommandBuffer cmd) { copy(cmd, staging.getRaw().buffer); });
}

void downloadThroughStaging(DeviceState& device, void* data, std::size_t size,
                            const std::function<void(VkCommandBuffer, VkBuffer)>& copy)
{
    countReadback(size);
    StagingBuffer staging(device, size, false);
    device.submitAndWait([&](VkCommandBuffer cmd) { copy(cmd, staging.getRaw().buffer); });
    invalidateMapped(device, staging.getRaw());
    std::memcpy(data, staging.getRaw().mapped, size);
}

} // namespace detail

Buffer::Buffer() = default;
Buffer::~Buffer() = default;
Buffer::Buffer(Buffer&&) noexcept = default;
Buffer& Buffer::operator=(Buffer&&) noexcept = default;
Buffer::Buffer(std::unique_ptr<detail::BufferState> state) : mState(std::move(state)) {}

detail::BufferState& Buffer::getState() const
{
    if (!mState)
        throw Error("use of an empty gpu::Buffer");
    return *mState;
}

std::size_t Buffer::getSize() const
{
    return static_cast<std::size_t>(getState().raw.size);
}

const std::string& Buffer::getName() const
{
    return getState().name;
}

bool Buffer::isHostMapped() const
{
    return getState().direct;
}

namespace {

void checkRange(const detail::BufferState& state, std::size_t size, std::size_t offset,
                const char* what)
{
    if (offset > state.raw.size || size > state.raw.size - offset)
        throw Error(std::string(what) + " of " + std::to_string(size) + " bytes at offset " +
                    std::to_string(offset) + " exceeds buffer '" + state.name + "' of " +
                    std::to_string(state.raw.size) + " bytes");
}

} // namespace

void Buffer::upload(const void* data, std::size_t size, std::size_t offset)
{
    detail::BufferState& state = getState();
    checkRange(state, size, offset, "upload");
    if (size == 0)
        return;
    detail::DeviceState& device = *state.device;
    if (state.direct) {
        std::memcpy(static_cast<std::byte*>(state.raw.mapped) + offset, data, size);
        detail::flushMapped(device, state.raw);
        detail::countUpload(size);
        return;
    }
    detail::uploadThroughStaging(device, data, size, [&](VkCommandBuffer cmd, VkBuffer staging) {
        VkBufferCopy region{0, offset, size};
        vkCmdCopyBuffer(cmd, staging, state.raw.buffer, 1, &region);
    });
}

void Buffer::download(void* data, std::size_t size, std::size_t offset) const
{
    detail::BufferState& state = getState();
    checkRange(state, size, offset, "download");
    if (size == 0)
        return;
    detail::DeviceState& device = *state.device;
    if (state.direct) {
        detail::invalidateMapped(device, state.raw);
        std::memcpy(data, static_cast<const std::byte*>(state.raw.mapped) + offset, size);
        detail::countReadback(size);
        return;
    }
    detail::downloadThroughStaging(device, data, size, [&](VkCommandBuffer cmd, VkBuffer staging) {
        VkBufferCopy region{offset, 0, size};
        vkCmdCopyBuffer(cmd, state.raw.buffer, staging, 1, &region);
    });
}

Buffer Context::createBuffer(const BufferDesc& desc)
{
    if (desc.size == 0)
        throw Error("gpu buffer '" + desc.name + "' has size 0");
    auto state = std::make_unique<detail::BufferState>();
    state->device = mDevice;
    state->name = desc.name.empty() ? std::string("buffer") : desc.name;
    using Kind = detail::DeviceState::MemoryKind;
    const Kind kind = !mDevice->stagingUploads ? Kind::DeviceLocalMapped
                      : desc.hostVisible       ? Kind::HostStaging
                                               : Kind::DeviceLocal;
    // Any storage buffer may hold the arguments of an indirect dispatch (a count the device wrote).
    VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    if (desc.vertexIndexUsage)
        usage |= VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_INDEX_BUFFER_BIT;
    state->raw = mDevice->createRawBuffer(desc.size, usage, kind, state->name);
    state->vertexIndexUsage = desc.vertexIndexUsage;
    state->direct = state->raw.mapped != nullptr;
    return Buffer(std::move(state));
}

} // namespace rtlab::gpu
