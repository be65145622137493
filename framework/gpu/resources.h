#pragma once
// GPU resources: storage buffers, 2D/3D images and samplers. All are move-only RAII owners of
// their Vulkan objects and keep the device alive. Upload/download calls are synchronous: they
// return when the data has arrived.

#include "core/error.h"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "gpu/format.h"

namespace rtlab::gpu {

namespace detail {
struct DeviceState;
struct BufferState;
struct ImageState;
struct SamplerState;
} // namespace detail

//! Values that may be copied to and from GPU memory byte for byte (and are not pointers).
template <class T>
concept PlainData = std::is_trivially_copyable_v<T> && !std::is_pointer_v<T>;

//! Description of a storage buffer.
struct BufferDesc {
    std::size_t size = 0; //!< bytes, > 0
    std::string name;     //!< shown in errors and debug tools
    //! Also usable as vertex and index buffer of draws (gpu/graphics.h).
    bool vertexIndexUsage = false;
    //! Data that crosses the bus once per use: inputs the host writes for one dispatch (per
    //! frame G-buffer pixels) or outputs it reads back. Where device memory cannot be mapped (a
    //! discrete GPU) the buffer lives in host-visible memory that shaders read and write over
    //! the bus, so upload() and download() are a memcpy rather than a staging copy and a queue
    //! submission each. Elsewhere (lavapipe, unified memory) it changes nothing.
    bool hostVisible = false;
};

//! A storage buffer (also usable as transfer source and destination, and as vertex and index
//! buffer when created with BufferDesc::vertexIndexUsage).
class Buffer {
public:
    Buffer();
    ~Buffer();
    Buffer(Buffer&&) noexcept;
    Buffer& operator=(Buffer&&) noexcept;

    //! False for a default-constructed or moved-from Buffer.
    bool isValid() const { return mState != nullptr; }
    //! Size in bytes.
    std::size_t getSize() const;
    //! The name from BufferDesc ("buffer" when none was given).
    const std::string& getName() const;
    //! True when upload() and download() copy straight into and out of the buffer's memory (no
    //! staging buffer, no queue submission): always on unified memory, and for
    //! BufferDesc::hostVisible buffers everywhere.
    bool isHostMapped() const;

    //! Copies `size` bytes from `data` to the buffer at byte `offset`.
    void upload(const void* data, std::size_t size, std::size_t offset = 0);
    //! Copies `size` bytes at byte `offset` of the buffer to `data`.
    void download(void* data, std::size_t size, std::size_t offset = 0) const;

    //! Uploads an array of trivially copyable values at byte `offset`.
    template <PlainData T> void uploadSpan(std::span<const T> values, std::size_t offset = 0)
    {
        upload(values.data(), values.size_bytes(), offset);
    }
    //! Downloads `count` values of type T (all that fit when count is 0).
    template <PlainData T>
    std::vector<T> downloadVector(std::size_t count = 0, std::size_t offset = 0) const
    {
        if (count == 0)
            count = (getSize() - offset) / sizeof(T);
        std::vector<T> values(count);
        download(values.data(), count * sizeof(T), offset);
        return values;
    }

    //! Internal state (defined in gpu/vulkan_internal.h).
    detail::BufferState& getState() const;

private:
    friend class Context;
    explicit Buffer(std::unique_ptr<detail::BufferState> state);
    std::unique_ptr<detail::BufferState> mState;
};

//! Uploads to `buffer`, which holds `held`, what of `next` differs from it, byte for byte: one
//! upload of the span from the first element that differs to the last (when the two are as
//! long) or to the end of `next` (when the length changed: the elements after a change shifted),
//! or none. `buffer` must have room for `next` (a pass that patches gives its buffers a margin,
//! getPatchCapacity). Returns the bytes uploaded. What a pass uses when a frame changes a part of
//! its data (a character's vertices, a dug model's mesh) and the rest stays.
template <PlainData T>
std::size_t uploadChangedSpan(Buffer& buffer, std::span<const T> held, std::span<const T> next)
{
    if (next.size_bytes() > buffer.getSize())
        throw Error("uploadChangedSpan: " + std::to_string(next.size()) + " elements do not fit a buffer of " +
                    std::to_string(buffer.getSize()) + " bytes");
    const std::size_t common = std::min(held.size(), next.size());
    std::size_t first = 0, last = next.size();
    while (first < common && std::memcmp(&held[first], &next[first], sizeof(T)) == 0)
        ++first;
    if (held.size() == next.size())
        while (last > first && std::memcmp(&held[last - 1], &next[last - 1], sizeof(T)) == 0)
            --last;
    if (first < last)
        buffer.upload(next.data() + first, (last - first) * sizeof(T), first * sizeof(T));
    return (last - first) * sizeof(T);
}

//! Elements to allocate for `count` in a buffer that uploadChangedSpan patches: a quarter more, so
//! that a mesh that grows a little (a dig) is patched, not allocated and uploaded again.
inline std::size_t getPatchCapacity(std::size_t count)
{
    return count + count / 4 + 64;
}

//! How an image will be bound.
enum class ImageUsage : std::uint32_t {
    Storage = 1, //!< imageLoad/imageStore
    Sampled = 2, //!< texture() through a combined image sampler
    StorageAndSampled = 3,
};

//! 2D or 3D.
enum class ImageDimension { Image2D, Image3D };

//! Description of an image. Images have one mip level and one array layer.
struct ImageDesc {
    ImageDimension dimension = ImageDimension::Image2D;
    Format format = Format::RGBA32Float;
    std::uint32_t width = 1;
    std::uint32_t height = 1;
    std::uint32_t depth = 1; //!< must be 1 for 2D images
    ImageUsage usage = ImageUsage::StorageAndSampled;
    std::string name;
};

//! A 2D or 3D image in device memory. Between commands it is in VK_IMAGE_LAYOUT_GENERAL
//! (valid for storage and sampled use alike); upload and download switch to transfer
//! layouts for the copy only.
class Image {
public:
    Image();
    ~Image();
    Image(Image&&) noexcept;
    Image& operator=(Image&&) noexcept;

    //! False for a default-constructed or moved-from Image.
    bool isValid() const { return mState != nullptr; }
    //! The description it was created with (with the default name filled in).
    const ImageDesc& getDesc() const;
    //! width * height * depth * texel size.
    std::size_t getByteSize() const;

    //! Replaces the whole image with tightly packed texels (x fastest, then y, then z).
    //! `size` must equal getByteSize().
    void upload(const void* data, std::size_t size);
    //! Reads the whole image as tightly packed texels. `size` must equal getByteSize().
    void download(void* data, std::size_t size) const;

    //! Uploads the whole image from an array of texel components.
    template <PlainData T> void uploadSpan(std::span<const T> values)
    {
        upload(values.data(), values.size_bytes());
    }
    //! Downloads the whole image as an array of texel components.
    template <PlainData T> std::vector<T> downloadVector() const
    {
        std::vector<T> values(getByteSize() / sizeof(T));
        download(values.data(), values.size() * sizeof(T));
        return values;
    }

    //! Internal state (defined in gpu/vulkan_internal.h).
    detail::ImageState& getState() const;

private:
    friend class Context;
    explicit Image(std::unique_ptr<detail::ImageState> state);
    std::unique_ptr<detail::ImageState> mState;
};

//! Texture filtering.
enum class Filter { Nearest, Linear };

//! What happens outside [0, 1].
enum class AddressMode { ClampToEdge, Repeat, MirroredRepeat, ClampToBorder };

//! Description of a sampler. Coordinates are normalised; there is a single mip level.
struct SamplerDesc {
    Filter filter = Filter::Linear;                     //!< for both magnification and minification
    AddressMode addressMode = AddressMode::ClampToEdge; //!< for u, v and w
};

//! A sampler object.
class Sampler {
public:
    Sampler();
    ~Sampler();
    Sampler(Sampler&&) noexcept;
    Sampler& operator=(Sampler&&) noexcept;

    //! False for a default-constructed or moved-from Sampler.
    bool isValid() const { return mState != nullptr; }
    const SamplerDesc& getDesc() const;
    //! Internal state (defined in gpu/vulkan_internal.h).
    detail::SamplerState& getState() const;

private:
    friend class Context;
    explicit Sampler(std::unique_ptr<detail::SamplerState> state);
    std::unique_ptr<detail::SamplerState> mState;
};

} // namespace rtlab::gpu
