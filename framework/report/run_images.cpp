// PNGs of every run's images, for looking: the technique's output and the reference in grey,
// and the signed error as a heat map (|error| through viridis, fixed range so that images of one
// study compare). The EXRs beside them keep the numbers.

#include "report/report_detail.h"

#include "core/error.h"
#include "experiment/image_files.h"
#include "plot/color.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace rtlab::report::detail {

namespace {

void writePng(const std::vector<std::uint8_t>& rgb, int width, int height, const std::string& path)
{
    auto out = OIIO::ImageOutput::create(path);
    if (!out)
        throw Error(path + ": cannot create a PNG writer");
    const OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, rgb.data()) || !out->close())
        throw Error(path + ": cannot write: " + out->geterror());
}

std::uint8_t encodeSrgb(float v)
{
    v = std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f);
    const float s = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return std::uint8_t(std::lround(s * 255.0f));
}

void writeGreyPng(const Image<float>& image, const std::string& path)
{
    std::vector<std::uint8_t> rgb(image.pixels.size() * 3);
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = encodeSrgb(image.pixels[i]);
    writePng(rgb, image.width, image.height, path);
}

void writeHeatPng(const Image<float>& error, float maxAbs, const std::string& path)
{
    std::vector<std::uint8_t> rgb(error.pixels.size() * 3);
    for (std::size_t i = 0; i < error.pixels.size(); ++i) {
        const float e = std::isfinite(error.pixels[i]) ? std::abs(error.pixels[i]) : maxAbs;
        const plot::Color c = plot::sampleColorMap(plot::ColorMap::Viridis, std::min(1.0f, e / maxAbs));
        rgb[3 * i] = c.r;
        rgb[3 * i + 1] = c.g;
        rgb[3 * i + 2] = c.b;
    }
    writePng(rgb, error.width, error.height, path);
}

} // namespace

RunImages findRunImages(const experiment::Row& row)
{
    const auto get = [&](const std::string& key) {
        const auto it = row.find(key);
        return it == row.end() ? std::string() : std::string(it->second);
    };
    RunImages images{get("image.technique"), get("image.reference"), get("image.error")};
    if (images.technique.empty())
        for (const auto& [key, value] : row) {
            // image.q with image.q_reference and image.q_error beside it.
            if (key.rfind("image.", 0) != 0)
                continue;
            const std::string reference = get(key + "_reference"), error = get(key + "_error");
            if (!reference.empty() && !error.empty()) {
                images = {std::string(value), reference, error};
                break;
            }
        }
    if (images.reference.empty() || images.error.empty())
        return {};
    return images;
}

int writeRunImages(const std::vector<experiment::Row>& rows, float errorRange)
{
    int written = 0;
    for (const auto& row : rows) {
        const RunImages images = findRunImages(row);
        if (!images.valid() || !std::filesystem::exists(images.technique))
            continue;
        const std::string dir = std::filesystem::path(images.technique).parent_path().string();
        if (std::filesystem::exists(dir + "/error.png"))
            continue;  // made by an earlier report
        writeGreyPng(experiment::readExrScalar(images.technique), dir + "/technique.png");
        writeGreyPng(experiment::readExrScalar(images.reference), dir + "/reference.png");
        writeHeatPng(experiment::readExrScalar(images.error), errorRange, dir + "/error.png");
        ++written;
    }
    return written;
}

} // namespace rtlab::report::detail
