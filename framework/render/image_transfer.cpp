#include "render/image_transfer.h"

#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"

namespace rtlab::render {

gpu::Image createImageFrom(gpu::Context& context, const Image<float>& image,
                           const std::string& name)
{
    gpu::ImageDesc desc;
    desc.format = gpu::Format::R32Float;
    desc.width = static_cast<std::uint32_t>(image.width);
    desc.height = static_cast<std::uint32_t>(image.height);
    desc.name = name;
    gpu::Image result = context.createImage(desc);
    result.uploadSpan<float>(image.pixels);
    return result;
}

gpu::Image createImageFrom(gpu::Context& context, const Image<glm::vec3>& image,
                           const std::string& name)
{
    gpu::ImageDesc desc;
    desc.format = gpu::Format::RGBA32Float;
    desc.width = static_cast<std::uint32_t>(image.width);
    desc.height = static_cast<std::uint32_t>(image.height);
    desc.name = name;
    gpu::Image result = context.createImage(desc);
    std::vector<float> texels(image.pixels.size() * 4);
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        texels[4 * i + 0] = image.pixels[i].x;
        texels[4 * i + 1] = image.pixels[i].y;
        texels[4 * i + 2] = image.pixels[i].z;
        texels[4 * i + 3] = 1.0f;
    }
    result.uploadSpan<float>(texels);
    return result;
}

namespace {

// Every channel of every texel as float, channel-interleaved.
std::vector<float> downloadAsFloats(const gpu::Image& image)
{
    const gpu::ImageDesc& desc = image.getDesc();
    if (desc.dimension != gpu::ImageDimension::Image2D)
        throw Error("download of image '" + desc.name + "': only 2D images can be read back");
    std::vector<float> values;
    switch (desc.format) {
    case gpu::Format::R32Float:
    case gpu::Format::RGBA32Float:
        return image.downloadVector<float>();
    case gpu::Format::RGBA16Float:
        for (const std::uint16_t h : image.downloadVector<std::uint16_t>())
            values.push_back(gpu::unpackHalf(h));
        return values;
    case gpu::Format::RGBA8Unorm:
        for (const std::uint8_t b : image.downloadVector<std::uint8_t>())
            values.push_back(static_cast<float>(b) / 255.0f);
        return values;
    case gpu::Format::R32Uint:
        for (const std::uint32_t u : image.downloadVector<std::uint32_t>())
            values.push_back(static_cast<float>(u));
        return values;
    }
    return values;
}

} // namespace

Image<glm::vec3> downloadRgb(const gpu::Image& image)
{
    const gpu::ImageDesc& desc = image.getDesc();
    if (gpu::getChannelCount(desc.format) != 4)
        throw Error("downloadRgb: image '" + desc.name + "' has format " +
                    std::string(gpu::getFormatName(desc.format)) + ", not four channels");
    const std::vector<float> values = downloadAsFloats(image);
    Image<glm::vec3> result(static_cast<int>(desc.width), static_cast<int>(desc.height));
    for (std::size_t i = 0; i < result.pixels.size(); ++i)
        result.pixels[i] = glm::vec3(values[4 * i], values[4 * i + 1], values[4 * i + 2]);
    return result;
}

Image<float> downloadScalar(const gpu::Image& image, int channel)
{
    const gpu::ImageDesc& desc = image.getDesc();
    const int channels = gpu::getChannelCount(desc.format);
    if (channel < 0 || channel >= channels)
        throw Error("downloadScalar: image '" + desc.name + "' has no channel " +
                    std::to_string(channel));
    const std::vector<float> values = downloadAsFloats(image);
    Image<float> result(static_cast<int>(desc.width), static_cast<int>(desc.height));
    for (std::size_t i = 0; i < result.pixels.size(); ++i)
        result.pixels[i] = values[std::size_t(channels) * i + std::size_t(channel)];
    return result;
}

} // namespace rtlab::render
