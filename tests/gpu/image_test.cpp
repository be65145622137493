// 2D and 3D images: transfers and shader copies in every supported format, storage-image
// writes, and linear filtering compared with analytic bilinear/trilinear interpolation.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

#include "core/error.h"
#include "gpu/context.h"
#include "gpu_test_support.h"

namespace rtlab::gpu::test {
namespace {

// Pseudo-random value in [0, 1) from an index.
float makeUnit(std::uint32_t i)
{
    std::uint32_t v = i * 747796405u + 2891336453u;
    v = ((v >> ((v >> 28) + 4)) ^ v) * 277803737u;
    v = (v >> 22) ^ v;
    return static_cast<float>(v >> 8) / 16777216.0f;
}

struct FormatCase {
    Format format;
    const char* qualifier; // GLSL layout format
    bool isUint;
};

const FormatCase kFormats[] = {
    {Format::R32Float, "r32f", false},       {Format::RGBA32Float, "rgba32f", false},
    {Format::RGBA16Float, "rgba16f", false}, {Format::RGBA8Unorm, "rgba8", false},
    {Format::R32Uint, "r32ui", true},
};

// Texel data for a format: normal floats in [-10, 10) (never NaN or denormal, which a
// conversion may legally alter), arbitrary bytes for UNORM8 and arbitrary words for UINT.
std::vector<std::byte> makeTexelData(Format format, std::size_t texels)
{
    const int channels = getChannelCount(format);
    const std::size_t values = texels * channels;
    std::vector<std::byte> bytes(texels * getTexelSize(format));
    for (std::size_t i = 0; i < values; ++i) {
        const auto index = static_cast<std::uint32_t>(i);
        const float f = std::round(makeUnit(index) * 200000.0f) / 10000.0f - 10.0f;
        switch (format) {
        case Format::R32Float:
        case Format::RGBA32Float:
            std::memcpy(&bytes[i * 4], &f, 4);
            break;
        case Format::RGBA16Float: {
            const std::uint16_t h = packHalf(f);
            std::memcpy(&bytes[i * 2], &h, 2);
            break;
        }
        case Format::RGBA8Unorm:
            bytes[i] = static_cast<std::byte>((index * 37u + 11u) & 0xffu);
            break;
        case Format::R32Uint: {
            const std::uint32_t u = index * 2654435761u;
            std::memcpy(&bytes[i * 4], &u, 4);
            break;
        }
        }
    }
    return bytes;
}

class ImageTest : public GpuTest {};

TEST_F(ImageTest, EveryFormatSurvivesTransfersAndShaderCopiesBitForBit)
{
    for (const ImageDimension dimension : {ImageDimension::Image2D, ImageDimension::Image3D}) {
        const bool is3d = dimension == ImageDimension::Image3D;
        const std::uint32_t w = is3d ? 5 : 13, h = is3d ? 6 : 7, d = is3d ? 3 : 1;
        for (const FormatCase& fc : kFormats) {
            SCOPED_TRACE(std::string(getFormatName(fc.format)) + (is3d ? " 3D" : " 2D"));
            const std::vector<std::byte> data = makeTexelData(fc.format, std::size_t{w} * h * d);
            const ImageDesc desc{dimension, fc.format, w, h, d, ImageUsage::Storage, "source"};
            Image source = getContext().createImage(desc);
            Image destination = getContext().createImage(desc);
            ASSERT_EQ(source.getByteSize(), data.size());
            source.upload(data.data(), data.size());
            EXPECT_EQ(source.downloadVector<std::byte>(), data) << "transfer round trip";

            const std::string image =
                std::string(fc.isUint ? "u" : "") + "image" + (is3d ? "3D" : "2D");
            const ComputePipeline copy = createTestPipeline(
                "copy_image.comp", {{0, BindingType::StorageImage}, {1, BindingType::StorageImage}},
                0, {}, {{"FORMAT", fc.qualifier}, {"IMAGE", image}, {"DIM", is3d ? "3" : "2"}});
            getContext().run([&](CommandList& cmd) {
                cmd.dispatch(
                    copy, {Binding::storageImage(0, source), Binding::storageImage(1, destination)},
                    GroupCount{computeGroupCount(w, 4), computeGroupCount(h, 4), d});
            });
            EXPECT_EQ(destination.downloadVector<std::byte>(), data) << "imageLoad/imageStore copy";
        }
    }
}

TEST_F(ImageTest, StorageImage2DWritesReadBackExactly)
{
    constexpr std::uint32_t kW = 37, kH = 23; // not multiples of the 8x8 group
    Image target = getContext().createImage(
        {ImageDimension::Image2D, Format::RGBA32Float, kW, kH, 1, ImageUsage::Storage, "target"});
    const ComputePipeline write =
        createTestPipeline("write_image2d.comp", {{0, BindingType::StorageImage}});
    getContext().run([&](CommandList& cmd) {
        cmd.dispatch(write, {Binding::storageImage(0, target)},
                     GroupCount{computeGroupCount(kW, 8), computeGroupCount(kH, 8)}, "write");
    });
    const std::vector<float> texels = target.downloadVector<float>();
    ASSERT_EQ(texels.size(), kW * kH * 4u);
    for (std::uint32_t y = 0; y < kH; ++y) {
        for (std::uint32_t x = 0; x < kW; ++x) {
            const float* t = &texels[(y * kW + x) * 4];
            const float fx = static_cast<float>(x), fy = static_cast<float>(y);
            ASSERT_EQ(t[0], fx);
            ASSERT_EQ(t[1], fy);
            ASSERT_EQ(t[2], fx * fy + 0.5f);
            ASSERT_EQ(t[3], -fx);
        }
    }
}

// Reference filtering with clamp-to-edge addressing. `s` is in texel units (u * size); texel
// centres sit at i + 0.5.
struct AxisWeights {
    int i0, i1;
    double fraction;
};

AxisWeights computeAxisWeights(double s, std::uint32_t size)
{
    const double t = s - 0.5;
    const double base = std::floor(t);
    const int last = static_cast<int>(size) - 1;
    const int i0 = static_cast<int>(base);
    return {std::clamp(i0, 0, last), std::clamp(i0 + 1, 0, last), t - base};
}

// Texel-space sample positions: random interior points, texel centres, midpoints between
// texels, and points in the clamped border half-texels.
std::vector<std::array<double, 3>> makeSamplePositions(const std::uint32_t size[3], int dims)
{
    std::vector<std::array<double, 3>> positions;
    for (std::uint32_t i = 0; i < 200; ++i) {
        std::array<double, 3> p{0.5, 0.5, 0.5};
        for (int a = 0; a < dims; ++a)
            p[a] = 0.5 + (size[a] - 1) * static_cast<double>(makeUnit(i * 3 + a + 1000));
        positions.push_back(p);
    }
    positions.push_back({1.5, 2.5, 1.5}); // a texel centre
    positions.push_back({2.0, 2.0, 2.0}); // midway between texels on every axis
    positions.push_back({1.25, 1.75, 1.0});
    positions.push_back({0.2, 0.3, 0.1}); // inside the first half texel: clamped
    positions.push_back({size[0] - 0.1, size[1] - 0.3, size[2] - 0.25});
    for (auto& p : positions) {
        for (int a = dims; a < 3; ++a)
            p[a] = 0.5;
    }
    return positions;
}

struct SampleCheck {
    double maxError = 0.0;
    double maxTolerance = 0.0;
    int farFromNearest = 0; // samples where nearest filtering would miss by > 4 tolerances
};

// Samples `image` at `positions` on the device and compares every channel with the
// analytic interpolation of `texels` (values per channel, `channels` per texel).
//
// Tolerance: Vulkan computes the filter weights with subTexelPrecisionBits (b) fraction bits.
// A weight off by at most 2^-b along one axis moves the result by at most 2^-b times the
// spread of the texel values involved; with one such error per axis the bound is
// dims * 2^-b * (max - min over the 2^dims texels), plus 1e-6 for float arithmetic on values
// of magnitude <= 1.
SampleCheck sampleAndCompare(GpuTest& test, Context& context, const Image& image, int dims,
                             const std::vector<float>& texels, int channels,
                             const std::vector<std::array<double, 3>>& positions)
{
    const ImageDesc& desc = image.getDesc();
    const std::uint32_t size[3] = {desc.width, desc.height, desc.depth};
    const auto count = static_cast<std::uint32_t>(positions.size());
    std::vector<float> coords(count * 4, 0.0f);
    for (std::uint32_t i = 0; i < count; ++i) {
        for (int a = 0; a < 3; ++a)
            coords[i * 4 + a] = static_cast<float>(positions[i][a] / size[a]);
    }

    Buffer coordBuffer = context.createBuffer({coords.size() * sizeof(float), "coords"});
    Buffer resultBuffer = context.createBuffer({count * 4 * sizeof(float), "results"});
    coordBuffer.uploadSpan<float>(coords);
    const Sampler sampler = context.createSampler({Filter::Linear, AddressMode::ClampToEdge});
    const ComputePipeline pipeline = test.createTestPipeline(
        "sample_image.comp",
        {{0, BindingType::SampledImage},
         {1, BindingType::StorageBuffer},
         {2, BindingType::StorageBuffer}},
        sizeof(std::uint32_t), {},
        {{"SAMPLER", dims == 3 ? "sampler3D" : "sampler2D"}, {"DIM", dims == 3 ? "3" : "2"}});
    context.run([&](CommandList& cmd) {
        cmd.dispatch(pipeline,
                     {Binding::sampledImage(0, image, sampler),
                      Binding::storageBuffer(1, coordBuffer),
                      Binding::storageBuffer(2, resultBuffer)},
                     PushConstants(count), GroupCount{computeGroupCount(count, 32)}, "sample");
    });
    const std::vector<float> results = resultBuffer.downloadVector<float>();

    const double step =
        std::ldexp(1.0, -static_cast<int>(context.getDeviceInfo().subTexelPrecisionBits));
    auto texel = [&](int x, int y, int z, int c) {
        return static_cast<double>(
            texels[((std::size_t(z) * size[1] + y) * size[0] + x) * channels + c]);
    };
    SampleCheck check;
    for (std::uint32_t i = 0; i < count; ++i) {
        AxisWeights w[3];
        for (int a = 0; a < 3; ++a)
            w[a] = computeAxisWeights(static_cast<double>(coords[i * 4 + a]) * size[a], size[a]);
        for (int c = 0; c < 4; ++c) {
            const float got = results[i * 4 + c];
            if (c >= channels) { // missing channels read as (0, 0, 0, 1)
                EXPECT_EQ(got, c == 3 ? 1.0f : 0.0f) << "sample " << i << " channel " << c;
                continue;
            }
            double expected = 0.0, lo = 1e30, hi = -1e30;
            for (int corner = 0; corner < 8; ++corner) {
                const int x = corner & 1 ? w[0].i1 : w[0].i0;
                const int y = corner & 2 ? w[1].i1 : w[1].i0;
                const int z = corner & 4 ? w[2].i1 : w[2].i0;
                const double weight = (corner & 1 ? w[0].fraction : 1 - w[0].fraction) *
                                      (corner & 2 ? w[1].fraction : 1 - w[1].fraction) *
                                      (corner & 4 ? w[2].fraction : 1 - w[2].fraction);
                const double v = texel(x, y, z, c);
                expected += weight * v;
                lo = std::min(lo, v);
                hi = std::max(hi, v);
            }
            const double tolerance = dims * step * (hi - lo) + 1e-6;
            const double error = std::abs(got - expected);
            EXPECT_LE(error, tolerance)
                << "sample " << i << " channel " << c << " at (" << coords[i * 4] << ", "
                << coords[i * 4 + 1] << ", " << coords[i * 4 + 2] << "): got " << got
                << ", expected " << expected;
            check.maxError = std::max(check.maxError, error);
            check.maxTolerance = std::max(check.maxTolerance, tolerance);
            const int nx = w[0].fraction < 0.5 ? w[0].i0 : w[0].i1;
            const int ny = w[1].fraction < 0.5 ? w[1].i0 : w[1].i1;
            const int nz = w[2].fraction < 0.5 ? w[2].i0 : w[2].i1;
            if (std::abs(texel(nx, ny, nz, c) - expected) > 4 * tolerance)
                ++check.farFromNearest;
        }
    }
    return check;
}

TEST_F(ImageTest, Sampled3DImageIsTrilinearlyFiltered)
{
    constexpr std::uint32_t kW = 5, kH = 4, kD = 3;
    std::vector<float> texels(kW * kH * kD);
    for (std::size_t i = 0; i < texels.size(); ++i)
        texels[i] = makeUnit(static_cast<std::uint32_t>(i) + 77);
    Image volume = getContext().createImage(
        {ImageDimension::Image3D, Format::R32Float, kW, kH, kD, ImageUsage::Sampled, "volume"});
    volume.uploadSpan<float>(texels);

    const std::uint32_t size[3] = {kW, kH, kD};
    const auto positions = makeSamplePositions(size, 3);
    const SampleCheck check =
        sampleAndCompare(*this, getContext(), volume, 3, texels, 1, positions);
    std::printf("3D trilinear: max error %.3g, largest tolerance %.3g (subTexelPrecisionBits %u)\n",
                check.maxError, check.maxTolerance,
                getContext().getDeviceInfo().subTexelPrecisionBits);
    // The comparison can tell linear from nearest filtering: most samples are far from the
    // nearest texel's value.
    EXPECT_GT(check.farFromNearest, static_cast<int>(positions.size()) / 2);
}

TEST_F(ImageTest, Sampled2DImageIsBilinearlyFilteredPerChannel)
{
    constexpr std::uint32_t kW = 6, kH = 5;
    std::vector<float> texels(kW * kH * 4);
    for (std::size_t i = 0; i < texels.size(); ++i)
        texels[i] = makeUnit(static_cast<std::uint32_t>(i) + 4242);
    Image picture = getContext().createImage({ImageDimension::Image2D, Format::RGBA32Float, kW, kH,
                                              1, ImageUsage::StorageAndSampled, "picture"});
    picture.uploadSpan<float>(texels);
    const std::uint32_t size[3] = {kW, kH, 1};
    const auto positions = makeSamplePositions(size, 2);
    const SampleCheck check =
        sampleAndCompare(*this, getContext(), picture, 2, texels, 4, positions);
    EXPECT_GT(check.farFromNearest, static_cast<int>(positions.size()) * 4 / 2);
}

TEST_F(ImageTest, InvalidImagesAndBindingsAreRejected)
{
    EXPECT_THROW(getContext().createImage({ImageDimension::Image2D, Format::R32Float, 4, 4, 2}),
                 Error);
    EXPECT_THROW(getContext().createImage({ImageDimension::Image3D, Format::R32Float, 0, 4, 2}),
                 Error);
    Image image = getContext().createImage({ImageDimension::Image2D, Format::R32Float, 4, 4});
    std::vector<float> wrongSize(3);
    EXPECT_THROW(image.uploadSpan<float>(wrongSize), Error);

    // Linear filtering of an integer format is refused when the dispatch is recorded.
    Image integers = getContext().createImage(
        {ImageDimension::Image3D, Format::R32Uint, 2, 2, 2, ImageUsage::Sampled, "integers"});
    Image storageOnly = getContext().createImage(
        {ImageDimension::Image3D, Format::R32Float, 2, 2, 2, ImageUsage::Storage, "storageOnly"});
    const Sampler linear = getContext().createSampler();
    Buffer buffer = getContext().createBuffer({64, "buffer"});
    const ComputePipeline pipeline =
        createTestPipeline("sample_image.comp",
                           {{0, BindingType::SampledImage},
                            {1, BindingType::StorageBuffer},
                            {2, BindingType::StorageBuffer}},
                           sizeof(std::uint32_t), {}, {{"SAMPLER", "sampler3D"}, {"DIM", "3"}});
    const std::uint32_t count = 1;
    auto record = [&](const Image& bound) {
        getContext().run([&](CommandList& cmd) {
            cmd.dispatch(pipeline,
                         {Binding::sampledImage(0, bound, linear),
                          Binding::storageBuffer(1, buffer), Binding::storageBuffer(2, buffer)},
                         PushConstants(count), GroupCount{1});
        });
    };
    try {
        record(integers);
        ADD_FAILURE() << "expected rtlab::Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("cannot filter format R32_UINT linearly"),
                  std::string::npos)
            << e.what();
    }
    try {
        record(storageOnly);
        ADD_FAILURE() << "expected rtlab::Error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("was not created for sampling"), std::string::npos)
            << e.what();
    }
}

} // namespace
} // namespace rtlab::gpu::test
