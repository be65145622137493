#include "experiment/image_files.h"

#include "core/error.h"

#include <OpenImageIO/imageio.h>

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

Image<float> readExrScalar(const std::string& path)
{
    auto in = OIIO::ImageInput::open(path);
    if (!in)
        throw Error(path + ": cannot open: " + OIIO::geterror());
    const OIIO::ImageSpec& spec = in->spec();
    Image<float> image(spec.width, spec.height);
    if (!in->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, image.pixels.data()))
        throw Error(path + ": cannot read: " + in->geterror());
    return image;
}

} // namespace rtlab::experiment
