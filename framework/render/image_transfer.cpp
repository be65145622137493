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
    uploadInto(result, image);
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
    uploadInto(result, image);
    return result;
}

namespace {

void requireTarget(const gpu::Image& target, gpu::Format format, int width, int height,
                   const char* what)
{
    const gpu::ImageDesc& d = target.getDesc();
    if (d.format != format || d.dimension != gpu::ImageDimension::Image2D ||
        int(d.width) != width || int(d.height) != height || d.depth != 1)
        throw Error(std::string("uploadInto: ") + what + " of " + std::to_string(width) + "x" +
                    std::to_string(height) + " needs a 2D " + std::string(gpu::getFormatName(format)) +
                    " image of that size, the target is " +
                    std::string(gpu::getFormatName(d.format)) + " " +
                    std::to_string(d.width) + "x" + std::to_string(d.height) + "x" +
                    std::to_string(d.depth));
}

} // namespace

void uploadInto(gpu::Image& target, const Image<float>& image)
{
    requireTarget(target, gpu::Format::R32Float, image.width, image.height, "a float image");
    target.upload(image.pixels.data(), image.pixels.size() * sizeof(float));
}

void uploadInto(gpu::Image& target, const Image<glm::vec3>& image)
{
    requireTarget(target, gpu::Format::RGBA32Float, image.width, image.height, "an RGB image");
    std::vector<float> texels(image.pixels.size() * 4);
    for (std::size_t i = 0; i < image.pixels.size(); ++i) {
        texels[4 * i + 0] = image.pixels[i].x;
        texels[4 * i + 1] = image.pixels[i].y;
        texels[4 * i + 2] = image.pixels[i].z;
        texels[4 * i + 3] = 1.0f;
    }
    target.upload(texels.data(), texels.size() * sizeof(float));
}

void uploadConeVisibility(const std::array<gpu::Image*, 4>& targets,
                          const std::vector<Image<float>>& cones)
{
    if (cones.size() != 16)
        throw Error("uploadConeVisibility: 16 cone images expected, found " +
                    std::to_string(cones.size()));
    const int w = cones[0].width, h = cones[0].height;
    for (const Image<float>& c : cones)
        if (c.width != w || c.height != h)
            throw Error("uploadConeVisibility: the cone images differ in size");
    const std::size_t pixels = std::size_t(w) * std::size_t(h);
    std::vector<float> texels(pixels * 4);
    for (std::size_t g = 0; g < 4; ++g) {
        if (targets[g] == nullptr)
            throw Error("uploadConeVisibility: target image " + std::to_string(g) + " is null");
        requireTarget(*targets[g], gpu::Format::RGBA32Float, w, h, "cone visibilities");
        for (std::size_t i = 0; i < pixels; ++i)
            for (std::size_t c = 0; c < 4; ++c)
                texels[4 * i + c] = cones[4 * g + c].pixels[i];
        targets[g]->upload(texels.data(), texels.size() * sizeof(float));
    }
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
