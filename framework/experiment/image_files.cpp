#include "experiment/image_files.h"

#include "core/error.h"
#include "core/image_file_size.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace rtlab::experiment {

namespace {

void writeChannels(const float* data, int width, int height, int channels, const std::string& path)
{
    auto out = OIIO::ImageOutput::create(path);
    if (!out)
        throw Error(path + ": cannot create an image writer: " + OIIO::geterror());
    OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, data) || !out->close())
        throw Error(path + ": cannot write: " + out->geterror());
}

} // namespace

void writeExr(const Image<float>& image, const std::string& path)
{
    writeChannels(image.pixels.data(), image.width, image.height, 1, path);
}

void writeExr(const Image<glm::vec3>& image, const std::string& path)
{
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
    writeChannels(&image.pixels.data()->x, image.width, image.height, 3, path);
}

void writePng(const Image<glm::vec3>& display, const std::string& path)
{
    std::vector<unsigned char> bytes(display.pixels.size() * 3);
    for (std::size_t i = 0; i < display.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const float v = display.pixels[i][c];
            bytes[3 * i + std::size_t(c)] =
                (unsigned char)(std::isfinite(v) ? std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)
                                                 : 0);
        }
    auto out = OIIO::ImageOutput::create(path);
    if (!out)
        throw Error(path + ": cannot create an image writer: " + OIIO::geterror());
    OIIO::ImageSpec spec(display.width, display.height, 3, OIIO::TypeDesc::UINT8);
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, bytes.data()) ||
        !out->close())
        throw Error(path + ": cannot write: " + out->geterror());
}

namespace {

// The first 3 channels of an image file OpenImageIO opens, as float (8-bit values in [0, 1]).
Image<glm::vec3> readRgb(const std::string& path, const char* format)
{
    auto in = OIIO::ImageInput::open(path);
    if (!in)
        throw Error(path + ": cannot open: " + OIIO::geterror());
    if (std::string(in->format_name()) != format)
        throw Error(path + ": expected " + (std::string(format) == "png" ? "a PNG" : "an OpenEXR") +
                    " file, found " + in->format_name());
    const OIIO::ImageSpec& spec = in->spec();
    checkImageFileSize(path, spec.width, spec.height, spec.nchannels);
    if (spec.nchannels < 3)
        throw Error(path + ": expected 3 channels, found " + std::to_string(spec.nchannels));
    Image<glm::vec3> image(spec.width, spec.height);
    if (!in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, &image.pixels.data()->x))
        throw Error(path + ": cannot read: " + in->geterror());
    return image;
}

} // namespace

Image<glm::vec3> readExrRgb(const std::string& path)
{
    checkExrHeader(path); // before the decoder sees a size it would allocate for
    return readRgb(path, "openexr");
}

Image<glm::vec3> readPngRgb(const std::string& path)
{
    return readRgb(path, "png");
}

Image<float> readExrScalar(const std::string& path)
{
    checkExrHeader(path); // before the decoder sees a size it would allocate for
    auto in = OIIO::ImageInput::open(path);
    if (!in)
        throw Error(path + ": cannot open: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    checkImageFileSize(path, spec.width, spec.height, spec.nchannels);
    Image<float> image(spec.width, spec.height);
    if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, image.pixels.data()))
        throw Error(path + ": cannot read: " + in->geterror());
    return image;
}

} // namespace rtlab::experiment
