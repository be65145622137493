#include "reference/exr_io.h"

#include "core/error.h"
#include "core/image_file_size.h"
#include "core/json.h"

#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace rtlab::reference {

namespace {

//! One EXR channel: a strided view into a result image (F = float or const float).
template <class F> struct ChannelView {
    std::string name;
    F* data = nullptr;
    int stride = 1;
};

template <class R> using FloatOf = std::conditional_t<std::is_const_v<R>, const float, float>;
template <class R>
using VectorImageOf =
    std::conditional_t<std::is_const_v<R>, const Image<glm::vec3>, Image<glm::vec3>>;

template <class R>
void addVector(std::vector<ChannelView<FloatOf<R>>>& out, const std::string& prefix,
               VectorImageOf<R>& image)
{
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c)
        out.push_back(
            {prefix + names[c], image.pixels.empty() ? nullptr : &image.pixels[0].x + c, 3});
}

template <class R> std::vector<ChannelView<FloatOf<R>>> listValueChannels(R& r)
{
    std::vector<ChannelView<FloatOf<R>>> out;
    switch (r.settings.quantity) {
    case Quantity::Ao:
    case Quantity::AoUniform:
    case Quantity::Obscurance:
        out.push_back({"Y", r.occlusion.pixels.data(), 1});
        break;
    case Quantity::Bent:
        addVector<R>(out, "", r.bentNormal);
        out.push_back({"ao", r.occlusion.pixels.data(), 1});
        out.push_back({"aperture", r.aperture.pixels.data(), 1});
        out.push_back({"aperture_uniform", r.apertureUniform.pixels.data(), 1});
        break;
    case Quantity::Direct:
    case Quantity::Indirect:
    case Quantity::Full:
        addVector<R>(out, "", r.radiance);
        addVector<R>(out, "irradiance.", r.irradiance);
        break;
    }
    return out;
}

template <class R> std::vector<ChannelView<FloatOf<R>>> listStdErrChannels(R& r)
{
    std::vector<ChannelView<FloatOf<R>>> out;
    switch (r.settings.quantity) {
    case Quantity::Ao:
    case Quantity::AoUniform:
    case Quantity::Obscurance:
        out.push_back({"Y", r.occlusionStdErr.pixels.data(), 1});
        break;
    case Quantity::Bent:
        out.push_back({"bent_angle", r.bentNormalStdErr.pixels.data(), 1});
        out.push_back({"ao", r.occlusionStdErr.pixels.data(), 1});
        out.push_back({"aperture", r.apertureStdErr.pixels.data(), 1});
        out.push_back({"aperture_uniform", r.apertureUniformStdErr.pixels.data(), 1});
        break;
    case Quantity::Direct:
    case Quantity::Indirect:
    case Quantity::Full:
        addVector<R>(out, "", r.radianceStdErr);
        addVector<R>(out, "irradiance.", r.irradianceStdErr);
        break;
    }
    return out;
}

std::vector<std::pair<std::string, std::string>> listAttributes(const ReferenceResult& r)
{
    const ReferenceSettings& s = r.settings;
    const ReferenceStats& t = r.stats;
    return {
        {"quantity", getQuantityName(s.quantity)},
        {"radius", formatExact(s.radius)},
        {"falloff", getFalloffName(s.falloff)},
        {"bounces", std::to_string(s.bounces)},
        {"targetStdErr", formatExact(s.targetStdErr)},
        {"targetRelStdErr", formatExact(s.targetRelStdErr)},
        {"batchSize", std::to_string(s.batchSize)},
        {"maxSamples", std::to_string(s.maxSamples)},
        {"seed", std::to_string(s.seed)},
        {"rayEpsilonScale", formatExact(s.rayEpsilonScale)},
        {"cacheKey", t.cacheKey},
        {"seconds", formatExact(t.seconds)},
        {"rayCount", std::to_string(t.rayCount)},
        {"meanSamples", formatExact(t.meanSamples)},
        {"surfacePixels", std::to_string(t.surfacePixels)},
        {"pixelsAtCap", std::to_string(t.pixelsAtCap)},
        {"maxStdErr", formatExact(t.maxStdErr)},
        {"rayEpsilon", formatExact(t.rayEpsilon)},
        {"sceneScale", formatExact(t.sceneScale)},
    };
}

double parseDouble(const std::string& text, const std::string& what)
{
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size())
        throw Error("reference: EXR attribute rtlab:" + what + " is not a number: '" + text + "'");
    return v;
}

long long parseInteger(const std::string& text, const std::string& what)
{
    char* end = nullptr;
    const long long v = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || end != text.c_str() + text.size())
        throw Error("reference: EXR attribute rtlab:" + what + " is not an integer: '" + text +
                    "'");
    return v;
}

void writeExr(const std::string& path, int width, int height,
              const std::vector<ChannelView<const float>>& channels,
              const std::vector<std::pair<std::string, std::string>>& attributes)
{
    const std::size_t pixels = std::size_t(width) * std::size_t(height);
    const std::size_t n = channels.size();
    for (const auto& c : channels)
        if (!c.data)
            throw Error("reference: cannot write '" + path + "': the image of channel '" + c.name +
                        "' is empty");
    std::vector<float> interleaved(pixels * n);
    for (std::size_t c = 0; c < n; ++c)
        for (std::size_t p = 0; p < pixels; ++p)
            interleaved[p * n + c] = channels[c].data[p * std::size_t(channels[c].stride)];

    OIIO::ImageSpec spec(width, height, int(n), OIIO::TypeDesc::FLOAT);
    spec.channelnames.clear();
    for (const auto& c : channels)
        spec.channelnames.push_back(c.name);
    spec.alpha_channel = -1;
    spec.attribute("compression", "zip");
    for (const auto& [key, value] : attributes)
        spec.attribute("rtlab:" + key, value);
    auto out = OIIO::ImageOutput::create(path);
    if (!out)
        throw Error("reference: cannot create '" + path + "': " + OIIO::geterror());
    if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, interleaved.data()) ||
        !out->close())
        throw Error("reference: cannot write '" + path + "': " + out->geterror());
}

struct ExrFile {
    OIIO::ImageSpec spec;
    std::vector<float> data;

    const float* find(const std::string& name, const std::string& path) const
    {
        for (int c = 0; c < spec.nchannels; ++c)
            if (spec.channelnames[c] == name)
                return data.data() + c;
        throw Error("reference: '" + path + "' has no channel '" + name + "'");
    }
    std::string getAttribute(const std::string& key, const std::string& path) const
    {
        const OIIO::ParamValue* p = spec.find_attribute("rtlab:" + key);
        if (!p)
            throw Error("reference: '" + path + "' has no attribute rtlab:" + key);
        return spec.get_string_attribute("rtlab:" + key);
    }
};

ExrFile readExr(const std::string& path)
{
    checkExrHeader(path); // before the decoder sees a size it would allocate for
    auto in = OIIO::ImageInput::open(path);
    if (!in)
        throw Error("reference: cannot read '" + path + "': " + OIIO::geterror());
    ExrFile file;
    file.spec = in->spec();
    checkImageFileSize(path, file.spec.width, file.spec.height, file.spec.nchannels);
    file.data.resize(std::size_t(file.spec.width) * std::size_t(file.spec.height) *
                     std::size_t(file.spec.nchannels));
    if (!in->read_image(0, 0, 0, file.spec.nchannels, OIIO::TypeDesc::FLOAT, file.data.data()))
        throw Error("reference: cannot read the pixels of '" + path + "': " + in->geterror());
    in->close();
    return file;
}

void readChannels(const ExrFile& file, const std::string& path,
                  const std::vector<ChannelView<float>>& channels)
{
    const std::size_t pixels = std::size_t(file.spec.width) * std::size_t(file.spec.height);
    const std::size_t n = std::size_t(file.spec.nchannels);
    for (const auto& c : channels) {
        const float* src = file.find(c.name, path);
        for (std::size_t p = 0; p < pixels; ++p)
            c.data[p * std::size_t(c.stride)] = src[p * n];
    }
}

} // namespace

std::string formatExact(double value)
{
    if (std::isinf(value))
        return value > 0 ? "inf" : "-inf";
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", value);
    return buf;
}

void allocateResultImages(ReferenceResult& r, Quantity quantity, int width, int height)
{
    r.settings.quantity = quantity;
    r.width = width;
    r.height = height;
    r.sampleCount = Image<std::uint32_t>(width, height, 0u);
    switch (quantity) {
    case Quantity::Ao:
    case Quantity::AoUniform:
    case Quantity::Obscurance:
        r.occlusion = Image<float>(width, height, 1.0f);
        r.occlusionStdErr = Image<float>(width, height, 0.0f);
        break;
    case Quantity::Bent:
        r.occlusion = Image<float>(width, height, 1.0f);
        r.occlusionStdErr = Image<float>(width, height, 0.0f);
        r.bentNormal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
        r.bentNormalStdErr = Image<float>(width, height, 0.0f);
        r.aperture = Image<float>(width, height, 0.0f);
        r.apertureStdErr = Image<float>(width, height, 0.0f);
        r.apertureUniform = Image<float>(width, height, 0.0f);
        r.apertureUniformStdErr = Image<float>(width, height, 0.0f);
        break;
    case Quantity::Direct:
    case Quantity::Indirect:
    case Quantity::Full:
        r.radiance = Image<glm::vec3>(width, height, glm::vec3(0.0f));
        r.radianceStdErr = Image<glm::vec3>(width, height, glm::vec3(0.0f));
        r.irradiance = Image<glm::vec3>(width, height, glm::vec3(0.0f));
        r.irradianceStdErr = Image<glm::vec3>(width, height, glm::vec3(0.0f));
        break;
    }
}

void writeReferenceExr(const ReferenceResult& result, const std::string& directory)
{
    std::error_code ec;
    std::filesystem::create_directories(directory, ec);
    if (ec)
        throw Error("reference: cannot create the folder '" + directory + "': " + ec.message());
    if (result.width <= 0 || result.height <= 0 ||
        result.sampleCount.size() != std::size_t(result.width) * std::size_t(result.height))
        throw Error("reference: cannot write an empty or inconsistent result");
    const ReferenceResult& r = result;
    const std::string name = getQuantityName(result.settings.quantity);
    const auto attributes = listAttributes(result);

    writeExr(directory + "/" + name + ".exr", r.width, r.height, listValueChannels(r), attributes);

    std::vector<float> samples(r.sampleCount.pixels.begin(), r.sampleCount.pixels.end());
    auto errors = listStdErrChannels(r);
    errors.push_back({"samples", samples.data(), 1});
    writeExr(directory + "/" + name + "_stderr.exr", r.width, r.height, errors, attributes);

    JsonObject json;
    for (const auto& [key, value] : attributes)
        json.add(key, value);
    std::ofstream sidecar(directory + "/" + name + ".json");
    sidecar << json.str() << "\n";
    if (!sidecar)
        throw Error("reference: cannot write '" + directory + "/" + name + ".json'");
}

ReferenceResult readReferenceExr(const std::string& directory, Quantity quantity)
{
    const std::string name = getQuantityName(quantity);
    const std::string valuePath = directory + "/" + name + ".exr";
    const std::string errorPath = directory + "/" + name + "_stderr.exr";
    const ExrFile values = readExr(valuePath);
    const ExrFile errors = readExr(errorPath);
    if (values.spec.width != errors.spec.width || values.spec.height != errors.spec.height)
        throw Error("reference: '" + valuePath + "' and '" + errorPath + "' differ in size");
    if (values.getAttribute("quantity", valuePath) != name)
        throw Error("reference: '" + valuePath + "' does not hold the quantity " + name);

    ReferenceResult r;
    allocateResultImages(r, quantity, values.spec.width, values.spec.height);
    readChannels(values, valuePath, listValueChannels(r));
    readChannels(errors, errorPath, listStdErrChannels(r));
    const float* samples = errors.find("samples", errorPath);
    for (std::size_t p = 0; p < r.sampleCount.size(); ++p)
        r.sampleCount.pixels[p] = std::uint32_t(samples[p * std::size_t(errors.spec.nchannels)]);

    auto get = [&](const char* key) { return values.getAttribute(key, valuePath); };
    ReferenceSettings& s = r.settings;
    s.radius = parseDouble(get("radius"), "radius");
    s.falloff = parseFalloff(get("falloff"));
    s.bounces = int(parseInteger(get("bounces"), "bounces"));
    s.targetStdErr = parseDouble(get("targetStdErr"), "targetStdErr");
    s.targetRelStdErr = parseDouble(get("targetRelStdErr"), "targetRelStdErr");
    s.batchSize = int(parseInteger(get("batchSize"), "batchSize"));
    s.maxSamples = int(parseInteger(get("maxSamples"), "maxSamples"));
    s.seed = std::strtoull(get("seed").c_str(), nullptr, 10);
    s.rayEpsilonScale = parseDouble(get("rayEpsilonScale"), "rayEpsilonScale");
    ReferenceStats& t = r.stats;
    t.cacheKey = get("cacheKey");
    t.seconds = parseDouble(get("seconds"), "seconds");
    t.rayCount = std::strtoull(get("rayCount").c_str(), nullptr, 10);
    t.meanSamples = parseDouble(get("meanSamples"), "meanSamples");
    t.surfacePixels = int(parseInteger(get("surfacePixels"), "surfacePixels"));
    t.pixelsAtCap = int(parseInteger(get("pixelsAtCap"), "pixelsAtCap"));
    t.maxStdErr = parseDouble(get("maxStdErr"), "maxStdErr");
    t.rayEpsilon = parseDouble(get("rayEpsilon"), "rayEpsilon");
    t.sceneScale = parseDouble(get("sceneScale"), "sceneScale");
    return r;
}

} // namespace rtlab::reference
