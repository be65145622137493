#include "core/image_file_size.h"

#include "core/error.h"

#include <cstdint>
#include <algorithm>
#include <atomic>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

namespace rtlab {

namespace {
std::atomic<long long> gValueLimit{kMaxImageFileValues};
} // namespace

long long getImageFileValueLimit() { return gValueLimit.load(); }

void setImageFileValueLimit(long long values) { gValueLimit.store(std::max(1ll, values)); }

void checkImageFileSize(const std::string& path, long long width, long long height, long long channels)
{
    const std::string size =
        std::to_string(width) + " x " + std::to_string(height) + " x " + std::to_string(channels) + " channels";
    if (width <= 0 || height <= 0 || channels <= 0)
        throw Error(path + ": image of " + size + ": expected a positive size");
    const long long limit = getImageFileValueLimit();
    if (width > limit || height > limit || channels > limit || width * height > limit / channels)
        throw Error(path + ": image of " + size + " is larger than rtlab reads (" + std::to_string(limit) +
                    " values)");
}

namespace {

//! The size in bytes of a value of an OpenEXR attribute type whose size is fixed (OpenEXR file
//! layout, "attribute types"), or -1 for the variable-size ones (string, chlist, stringvector,
//! preview, opaque types).
int getFixedAttributeSize(const std::string& type)
{
    static const std::pair<const char*, int> kSizes[] = {
        {"box2i", 16},   {"box2f", 16},    {"chromaticities", 32}, {"compression", 1},
        {"double", 8},   {"envmap", 1},    {"float", 4},           {"int", 4},
        {"keycode", 28}, {"lineOrder", 1}, {"m33f", 36},           {"m44f", 64},
        {"m33d", 72},    {"m44d", 128},    {"rational", 8},        {"tiledesc", 9},
        {"timecode", 8}, {"v2i", 8},       {"v2f", 8},             {"v2d", 16},
        {"v3i", 12},     {"v3f", 12},      {"v3d", 24},            {"deepImageState", 1}};
    for (const auto& [name, size] : kSizes)
        if (type == name)
            return size;
    return -1;
}

//! A cursor over the header bytes; every read is bounds-checked.
class HeaderReader {
public:
    HeaderReader(const std::string& path, std::vector<char> bytes) : mPath(path), mBytes(std::move(bytes)) {}

    std::string readName()
    {
        const auto end = std::find(mBytes.begin() + std::ptrdiff_t(mAt), mBytes.end(), '\0');
        if (end == mBytes.end())
            fail("a name runs past the end of the header");
        std::string s(mBytes.begin() + std::ptrdiff_t(mAt), end);
        mAt = std::size_t(end - mBytes.begin()) + 1;
        return s;
    }
    std::int32_t readInt()
    {
        need(4);
        std::int32_t v;
        std::memcpy(&v, mBytes.data() + mAt, 4); // little-endian, as the format and x86-64
        mAt += 4;
        return v;
    }
    std::uint8_t readByte()
    {
        need(1);
        return std::uint8_t(mBytes[mAt++]);
    }
    //! The bytes [at, at + size) as a sub-reader.
    HeaderReader slice(std::size_t size)
    {
        need(size);
        HeaderReader r(mPath, std::vector<char>(mBytes.begin() + std::ptrdiff_t(mAt),
                                                mBytes.begin() + std::ptrdiff_t(mAt + size)));
        mAt += size;
        return r;
    }
    std::size_t position() const { return mAt; }
    bool atEnd() const { return mAt >= mBytes.size(); }
    [[noreturn]] void fail(const std::string& what) const { throw Error(mPath + ": not a readable OpenEXR file: " + what); }

private:
    void need(std::size_t n) const
    {
        if (mBytes.size() - mAt < n)
            fail("the header ends early");
    }
    std::string mPath;
    std::vector<char> mBytes;
    std::size_t mAt = 0;
};

//! Scanlines per chunk of each compression (the format's table; 0 = unknown method).
int getLinesPerChunk(int compression)
{
    static const int lines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
    return compression >= 0 && compression < int(std::size(lines)) ? lines[compression] : 0;
}

} // namespace

void checkExrHeader(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw Error(path + ": cannot open");
    // The header of a file rtlab writes is a few hundred bytes; 1 MiB leaves room for long
    // attribute lists without reading a large file whole.
    std::vector<char> bytes(1 << 20);
    in.read(bytes.data(), std::streamsize(bytes.size()));
    bytes.resize(std::size_t(in.gcount()));
    in.clear();
    in.seekg(0, std::ios::end);
    const long long fileSize = static_cast<long long>(in.tellg());

    HeaderReader r(path, std::move(bytes));
    const std::int32_t magic = r.readInt();
    if (magic != 20000630)
        r.fail("no OpenEXR magic number");
    const std::int32_t version = r.readInt();
    if ((version & 0xff) != 2)
        r.fail("version " + std::to_string(version & 0xff) + ", expected 2");
    if (version & 0x800)
        r.fail("deep data, which rtlab does not read");
    if (version & 0x1000)
        r.fail("several parts, which rtlab does not read");
    const bool tiled = (version & 0x200) != 0;

    long long width = 0, height = 0, channels = -1, tileWidth = 0, tileHeight = 0;
    int compression = -1;
    for (;;) {
        const std::string name = r.readName();
        if (name.empty())
            break;
        const std::string type = r.readName();
        const std::int32_t size = r.readInt();
        if (size < 0)
            r.fail("attribute '" + name + "' has a negative size");
        // OpenEXR reads a value of a fixed-size type by its type, not by the size field: a
        // different size would make its reading of the rest of the header differ from this one
        // (a later "string" then claims gigabytes, which the decoder allocates before reading).
        const int fixed = getFixedAttributeSize(type);
        if (fixed >= 0 && size != fixed)
            r.fail("attribute '" + name + "' of type " + type + " has size " + std::to_string(size) +
                   ", expected " + std::to_string(fixed));
        HeaderReader value = r.slice(std::size_t(size));
        if (name == "dataWindow" && type == "box2i") {
            const long long xMin = value.readInt(), yMin = value.readInt();
            const long long xMax = value.readInt(), yMax = value.readInt();
            width = xMax - xMin + 1;
            height = yMax - yMin + 1;
        } else if (name == "channels" && type == "chlist") {
            channels = 0;
            while (!value.readName().empty()) {
                value.readInt();  // pixel type
                value.readInt();  // pLinear and reserved
                if (value.readInt() != 1 || value.readInt() != 1)
                    value.fail("subsampled channels, which rtlab does not read");
                ++channels;
            }
        } else if (name == "compression" && type == "compression") {
            compression = value.readByte();
        } else if (name == "tiles" && type == "tiledesc") {
            tileWidth = std::uint32_t(value.readInt());
            tileHeight = std::uint32_t(value.readInt());
        }
    }
    if (channels < 0 || compression < 0 || width == 0)
        r.fail("no channels, compression or dataWindow attribute");
    if (getLinesPerChunk(compression) == 0)
        r.fail("unknown compression " + std::to_string(compression));
    checkImageFileSize(path, width, height, channels);
    long long chunks = (height + getLinesPerChunk(compression) - 1) / getLinesPerChunk(compression);
    if (tiled) {
        if (tileWidth <= 0 || tileHeight <= 0)
            r.fail("a tiled image without a valid tile size");
        chunks = ((width + tileWidth - 1) / tileWidth) * ((height + tileHeight - 1) / tileHeight);
    }
    // The offset table (8 bytes per chunk) follows the header; each chunk needs at least its
    // 4-byte y (or tile coordinates) and 4-byte size after it.
    if (fileSize < static_cast<long long>(r.position()) + 16 * chunks)
        r.fail(std::to_string(chunks) + " chunks of " + std::to_string(width) + " x " + std::to_string(height) +
               " pixels do not fit in " + std::to_string(fileSize) + " bytes");
}

} // namespace rtlab
