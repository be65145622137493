// The Vulkan combine (cone_combine_gpu.h) against the C++ one (upsample.h combineCones) on the
// same inputs: a reduced G-buffer with a depth step, sky, thin features that take the 3 x 3
// fallback, tilted normals, the occlusion family's visibilities and characters' capsules; the
// same far from the origin; and what it refuses. The resident gather (the G-buffer reduced on the
// device from its GPU images, the combine reading images and writing one) against the same.

#include "families/voxel_gi/cone_combine_gpu.h"

#include "core/error.h"
#include "families/voxel_gi/cone_tracing.h"
#include "families/voxel_gi/voxel_gi.h"
#include "gpu/context.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

using namespace rtlab;
using namespace rtlab::voxelgi;

namespace {

// A w x h G-buffer seen from above a floor at y = 0 (offset by `shift`): the left third a floor,
// then a wall 3 m farther facing the camera, sky in the top rows, a one-pixel pole every 7
// columns standing in front, and some tilted normals.
scene::GBuffer makeScene(int w, int h, const glm::dvec3& shift)
{
    scene::GBuffer g;
    g.width = w;
    g.height = h;
    g.camera.position = glm::vec3(shift + glm::dvec3(0.0, 2.0, 4.0));
    g.depth = Image<float>(w, h, INFINITY);
    g.position = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    g.normal = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    g.materialId = Image<std::uint32_t>(w, h, scene::kNoMaterial);
    for (int y = 3; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            glm::dvec3 p, n;
            double depth;
            if (x % 7 == 3) { // a pole
                p = glm::dvec3(0.05 * x, 0.05 * (h - y), -0.5);
                n = glm::normalize(glm::dvec3(0.3, 0.0, 1.0));
                depth = 4.5;
            } else if (x < w / 3) { // floor
                p = glm::dvec3(0.05 * x, 0.0, -0.05 * (h - y));
                n = (x + y) % 5 == 0 ? glm::normalize(glm::dvec3(0.6, 1.0, -0.3))
                                     : glm::dvec3(0, 1, 0);
                depth = 4.0 + 0.05 * (h - y);
            } else { // wall
                p = glm::dvec3(0.05 * x, 0.05 * (h - y), -3.0);
                n = glm::dvec3(0, 0, 1);
                depth = 7.0;
            }
            g.position.at(x, y) = glm::vec3(p + shift);
            g.normal.at(x, y) = glm::vec3(n);
            g.depth.at(x, y) = float(depth);
            g.materialId.at(x, y) = 0;
        }
    return g;
}

struct Inputs {
    scene::GBuffer full;
    ReducedGBuffer reduced;
    std::vector<glm::vec3> cones;
    std::vector<Image<float>> visibility;
    std::vector<scene::PosedCapsule> capsules;
};

Inputs makeInputs(int w, int h, int factor, const glm::dvec3& shift)
{
    Inputs in;
    in.full = makeScene(w, h, shift);
    in.reduced = reduceGBuffer(in.full, factor);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    in.cones.resize(std::size_t(in.reduced.gbuffer.width * in.reduced.gbuffer.height) * kConeCount);
    for (glm::vec3& c : in.cones)
        c = glm::vec3(unit(rng), unit(rng), unit(rng));
    for (int k = 0; k < kConeCount; ++k) {
        Image<float> v(w, h, 1.0f);
        for (float& x : v.pixels)
            x = unit(rng) * 1.2f - 0.1f; // also outside [0, 1]: both clamp
        in.visibility.push_back(std::move(v));
    }
    for (int i = 0; i < 10; ++i) {
        scene::PosedCapsule c;
        const glm::dvec3 base(0.05 * w * unit(rng), 0.1 + 1.0 * unit(rng), -3.0 * unit(rng));
        c.capsule.a = glm::vec3(base + shift);
        c.capsule.b =
            glm::vec3(base + shift + glm::dvec3(unit(rng) - 0.5, 1.2 * unit(rng), unit(rng) - 0.5));
        c.capsule.radius = 0.05f + 0.2f * unit(rng);
        in.capsules.push_back(c);
    }
    return in;
}

ConeCombineInputs describe(const Inputs& in, bool visibility, bool capsules,
                           CapsuleResolution resolution = CapsuleResolution::Full)
{
    ConeCombineInputs c;
    c.capsuleResolution = resolution;
    c.coneRadiance = &in.cones;
    c.reduced = &in.reduced;
    c.full = &in.full;
    c.visibility = visibility ? &in.visibility : nullptr;
    c.capsules = capsules ? &in.capsules : nullptr;
    c.coneHalfAngle = 0.52;
    return c;
}

// Per pixel, the largest relative difference of the three channels (against max(cpu, 1e-3)).
struct Difference {
    double worst = 0.0, mean = 0.0;
    int lit = 0, skyNonZero = 0;
};

Difference compare(const Image<glm::vec3>& cpu, const Image<glm::vec3>& gpu,
                   const scene::GBuffer& g)
{
    Difference d;
    EXPECT_EQ(cpu.pixels.size(), gpu.pixels.size());
    for (std::size_t i = 0; i < cpu.pixels.size(); ++i) {
        if (g.materialId.pixels[i] == scene::kNoMaterial) {
            d.skyNonZero += gpu.pixels[i] != glm::vec3(0.0f) ? 1 : 0;
            continue;
        }
        double rel = 0.0;
        for (int c = 0; c < 3; ++c) {
            EXPECT_TRUE(std::isfinite(gpu.pixels[i][c]));
            rel = std::max(rel, std::abs(double(cpu.pixels[i][c]) - double(gpu.pixels[i][c])) /
                                    std::max(double(cpu.pixels[i][c]), 1e-3));
        }
        d.worst = std::max(d.worst, rel);
        d.mean += rel;
        ++d.lit;
    }
    d.mean /= std::max(d.lit, 1);
    return d;
}

void expectParity(const glm::dvec3& shift, int factor)
{
    const Inputs in = makeInputs(61, 37, factor, shift);
    gpu::Context context;
    ConeCombineGpu combiner;
    int occluded = 0;
    for (const bool visibility : {false, true})
        for (const int capsules : {0, 1, 2}) { // none, at every pixel, at the traced pixels
            const ConeCombineInputs c =
                describe(in, visibility, capsules > 0,
                         capsules == 2 ? CapsuleResolution::Traced : CapsuleResolution::Full);
            const Image<glm::vec3> cpu = combineCones(c);
            const Image<glm::vec3> gpu = combiner.combine(context, c);
            const Difference d = compare(cpu, gpu, in.full);
            SCOPED_TRACE("visibility " + std::to_string(visibility) + ", capsules " +
                         std::to_string(capsules));
            ASSERT_GT(d.lit, 1500);
            EXPECT_EQ(d.skyNonZero, 0);
            // Float against double: measured on lavapipe, mean 1.5e-7 and every pixel within 4.4e-6
            // (the capsules' angles come from an arithmetic atan2; with the built-in asin and acos
            // it was 1.4e-3). Tolerance: mean below 1e-6 and every pixel within 1e-4, room for
            // drivers that round division, sqrt and exp differently (Vulkan allows a few ulps).
            EXPECT_LT(d.mean, 1e-6);
            EXPECT_LT(d.worst, 1e-4);
            if (capsules > 0) {
                // The capsules do change the result (the comparison covers their tests).
                const Image<glm::vec3> open = combineCones(describe(in, visibility, false));
                for (std::size_t i = 0; i < open.pixels.size(); ++i)
                    occluded += glm::length(open.pixels[i] - cpu.pixels[i]) > 1e-3f ? 1 : 0;
            }
        }
    EXPECT_GT(occluded, 400);
}

TEST(ConeCombineGpu, MatchesTheCppCombineAtEveryReduction)
{
    for (const int factor : {1, 2, 4}) {
        SCOPED_TRACE("factor " + std::to_string(factor));
        expectParity(glm::dvec3(0.0), factor);
    }
}

// Positions 1e5 from the origin: the shader works relative to the camera, so the capsule tests
// keep their precision (the C++ combine works in double on the same float inputs).
TEST(ConeCombineGpu, MatchesTheCppCombineFarFromTheOrigin)
{
    expectParity(glm::dvec3(1e5, -3e4, 7e4), 4);
}

// The cone radiances where a Vulkan pixel gather leaves them: a buffer on the device.
TEST(ConeCombineGpu, ReadsConesFromADeviceBuffer)
{
    const Inputs in = makeInputs(40, 24, 4, glm::dvec3(0.0));
    gpu::Context context;
    std::vector<glm::vec4> cones(in.cones.size());
    for (std::size_t i = 0; i < cones.size(); ++i)
        cones[i] = glm::vec4(in.cones[i], 7.0f); // w is not read
    gpu::Buffer buffer = context.createBuffer({cones.size() * sizeof(glm::vec4), "test.cones"});
    buffer.uploadSpan<glm::vec4>(cones);
    ConeCombineGpu combiner;
    const ConeCombineInputs c = describe(in, true, true);
    const Image<glm::vec3> fromBuffer = combiner.combine(context, buffer, c);
    const Image<glm::vec3> uploaded = combiner.combine(context, c);
    EXPECT_EQ(fromBuffer.pixels, uploaded.pixels);
    // Too small a buffer for the reduced G-buffer is refused.
    gpu::Buffer small = context.createBuffer({64, "test.small"});
    EXPECT_THROW(combiner.combine(context, small, c), Error);
}

TEST(ConeCombineGpu, RefusesVisibilityImagesOfAnotherSize)
{
    Inputs in = makeInputs(40, 24, 2, glm::dvec3(0.0));
    in.visibility[5] = Image<float>(20, 12, 1.0f);
    gpu::Context context;
    ConeCombineGpu combiner;
    try {
        combiner.combine(context, describe(in, true, false));
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("visibility image 5 is 20x12, not 40x24"),
                  std::string::npos)
            << e.what();
    }
}

// The capsules at the traced pixels multiply a device's cone buffer in place: the buffer then
// holds what the C++ occludeTracedCones makes of the same cones (float against double: the
// parity tolerance above).
TEST(ConeCombineGpu, OccludesTheTracedConesInTheDeviceBuffer)
{
    const Inputs in = makeInputs(40, 24, 4, glm::dvec3(0.0));
    gpu::Context context;
    std::vector<glm::vec4> cones(in.cones.size());
    for (std::size_t i = 0; i < cones.size(); ++i)
        cones[i] = glm::vec4(in.cones[i], 0.0f);
    gpu::Buffer buffer = context.createBuffer({cones.size() * sizeof(glm::vec4), "test.cones"});
    buffer.uploadSpan<glm::vec4>(cones);
    ConeCombineGpu combiner;
    combiner.combine(context, buffer, describe(in, false, true, CapsuleResolution::Traced));
    const std::vector<glm::vec4> after = buffer.downloadVector<glm::vec4>(cones.size());
    std::vector<glm::vec3> expected = in.cones;
    occludeTracedCones(in.reduced.gbuffer, expected, in.capsules, 0.52);
    int changed = 0;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        changed += expected[i] != in.cones[i] ? 1 : 0;
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(after[i][c], expected[i][c], 1e-4 * std::max(1e-3f, expected[i][c])) << i;
    }
    EXPECT_GT(changed, 20); // the capsules hide part of some traced pixels' cones
}

// "auto" gathers on Vulkan only on a GPU; "vulkan" wherever there is a context.
TEST(ConeCombineGpu, AutoGathersOnTheDeviceOnlyOnAGpu)
{
    gpu::Context context;
    EXPECT_EQ(shouldGatherOnGpu(&context, "auto"), !context.getDeviceInfo().isCpu);
    EXPECT_TRUE(shouldGatherOnGpu(&context, "vulkan"));
    EXPECT_FALSE(shouldGatherOnGpu(&context, "cpu"));
    EXPECT_FALSE(shouldGatherOnGpu(nullptr, "vulkan"));
    EXPECT_FALSE(shouldGatherOnGpu(nullptr, "auto"));
}

// "auto" combines on Vulkan only where the cones were traced there and the device is a GPU.
TEST(ConeCombineGpu, AutoCombinesOnTheDeviceOnlyForAGpuGather)
{
    gpu::Context context;
    EXPECT_EQ(shouldCombineOnGpu(&context, true), !context.getDeviceInfo().isCpu);
    EXPECT_FALSE(shouldCombineOnGpu(&context, false));
    EXPECT_TRUE(shouldCombineOnGpu(&context, false, "vulkan"));
    EXPECT_FALSE(shouldCombineOnGpu(&context, true, "cpu"));
    EXPECT_FALSE(shouldCombineOnGpu(nullptr, true, "vulkan"));
}

// The G-buffer as the frame keeps it on the GPU (pipeline/frame_start.h positionDepthGpu,
// worldNormalGpu), and the visibilities as the occlusion family leaves them (four RGBA32F images,
// cone k in channel k % 4 of image k / 4).
struct GpuInputs {
    gpu::Image positionDepth, normal;
    std::array<gpu::Image, 4> visibility;
    plugin::VoxelGiGpuGBuffer images;

    GpuInputs(gpu::Context& context, const Inputs& in)
    {
        const scene::GBuffer& g = in.full;
        const auto make = [&](const char* name, int w, int h) {
            return context.createImage({gpu::ImageDimension::Image2D, gpu::Format::RGBA32Float, std::uint32_t(w),
                                        std::uint32_t(h), 1, gpu::ImageUsage::StorageAndSampled, name});
        };
        positionDepth = make("test.position_depth", g.width, g.height);
        normal = make("test.normal", g.width, g.height);
        std::vector<glm::vec4> p(g.position.pixels.size()), n(p.size());
        for (std::size_t i = 0; i < p.size(); ++i) {
            p[i] = glm::vec4(g.position.pixels[i], g.depth.pixels[i]);
            n[i] = glm::vec4(g.normal.pixels[i], 0.0f);
        }
        positionDepth.uploadSpan<glm::vec4>(p);
        normal.uploadSpan<glm::vec4>(n);
        for (std::size_t image = 0; image < 4; ++image) {
            visibility[image] = make("test.visibility", g.width, g.height);
            std::vector<glm::vec4> v(p.size());
            for (std::size_t i = 0; i < v.size(); ++i)
                for (int c = 0; c < 4; ++c)
                    v[i][c] = in.visibility[4 * image + std::size_t(c)].pixels[i];
            visibility[image].uploadSpan<glm::vec4>(v);
        }
        images = {&positionDepth, &normal, g.width, g.height, glm::dvec3(g.camera.position)};
    }
    std::array<const gpu::Image*, 4> getVisibility() const
    {
        return {&visibility[0], &visibility[1], &visibility[2], &visibility[3]};
    }
};

// A pixel cone dispatch whose "cones" are given: mode 0 copies [pixel * 16 + cone] from the extra
// buffer at binding 6, mode 1 writes each pixel's start (position in cone 0, normal in cone 1),
// so that the reduction and the combine are tested apart from any structure's march.
struct ProbeDispatch {
    PixelConeDispatch dispatch;
    gpu::Buffer unused, given;

    explicit ProbeDispatch(gpu::Context& context)
    {
        const auto path = std::filesystem::temp_directory_path() / "rtlab_probe_cones.comp";
        std::ofstream(path) << R"(#version 450
layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;
layout(std430, binding = 0) readonly buffer A { vec4 a[]; };
layout(std430, binding = 1) readonly buffer B { vec4 b[]; };
layout(std430, binding = 2) readonly buffer P { vec4 positions[]; };
layout(std430, binding = 3) readonly buffer N { vec4 normals[]; };
layout(std430, binding = 4) writeonly buffer O { vec4 cones[]; };
layout(std430, binding = 5) readonly buffer D { vec4 directions[]; };
layout(std430, binding = 6) readonly buffer G { vec4 given[]; };
layout(push_constant) uniform K { ivec4 size; } pc; // width, height, mode
void main()
{
    const ivec3 id = ivec3(gl_GlobalInvocationID);
    if (id.x >= pc.size.x || id.y >= pc.size.y)
        return;
    const int p = id.y * pc.size.x + id.x, k = id.z;
    cones[p * 16 + k] = pc.size.z == 0 ? given[p * 16 + k] : k == 0 ? positions[p] : k == 1 ? normals[p] : vec4(0.0);
}
)";
        dispatch.create(context, path, "test.probe", sizeof(glm::ivec4), ConeSet::make(29.0), 1);
        unused = dispatch.makeBuffer(16, "test.unused");
    }
    const PixelConeDispatch& run(const PixelSource& pixels, const glm::dvec3& anchor, int mode,
                                 const std::vector<glm::vec3>* cones = nullptr)
    {
        dispatch.preparePixels(pixels, anchor);
        std::vector<glm::vec4> g(std::max<std::size_t>(cones ? cones->size() : 0, 1), glm::vec4(0.0f));
        for (std::size_t i = 0; cones && i < cones->size(); ++i)
            g[i] = glm::vec4((*cones)[i], 0.0f);
        given = dispatch.makeBuffer(g.size() * sizeof(glm::vec4), "test.given", true);
        given.uploadSpan<glm::vec4>(g);
        const glm::ivec2 size = pixels.getSize();
        const glm::ivec4 constants(size.x, size.y, mode, 0);
        dispatch.run(unused, unused, gpu::PushConstants(constants), nullptr, {&given});
        return dispatch;
    }
};

// The reduction on the device picks reduceGBuffer's representatives and lays out their starts as
// uploadPixels does, at every reduction and far from the origin (positions relative to an anchor
// that is not a float). The upload rounds the double difference once; the device subtracts the
// float anchor and then what that left, exact near the anchor (Sterbenz) and rounded twice
// farther away: within one float ulp of the upload's.
TEST(ConeCombineGpu, ReducesTheGBufferOnTheDeviceAsTheUploadDoes)
{
    gpu::Context context;
    ProbeDispatch probe(context);
    for (const glm::dvec3 shift : {glm::dvec3(0.0), glm::dvec3(1e5, -3e4, 7e4)})
        for (const int factor : {1, 3, 4}) {
            SCOPED_TRACE("factor " + std::to_string(factor) + ", shift " + std::to_string(shift.x));
            const Inputs in = makeInputs(61, 37, factor, shift);
            const GpuInputs onGpu(context, in);
            const glm::dvec3 anchor = shift + glm::dvec3(0.1, 0.7, -1.3);
            const PixelConeDispatch& d = probe.run({.gpu = &onGpu.images, .factor = factor}, anchor, 1);
            const ReducedGBuffer& r = in.reduced;
            ASSERT_EQ(d.getPixelsSize(), glm::ivec2(r.gbuffer.width, r.gbuffer.height));
            EXPECT_EQ(d.getRepresentative().downloadVector<int>(r.representative.size()), r.representative);
            const std::vector<glm::vec4> starts = d.getOutput().downloadVector<glm::vec4>(r.representative.size() * 16);
            int surfaces = 0;
            for (int y = 0; y < r.gbuffer.height; ++y)
                for (int x = 0; x < r.gbuffer.width; ++x) {
                    const std::size_t s = std::size_t(y * r.gbuffer.width + x);
                    const bool surface = r.gbuffer.hasSurface(x, y);
                    surfaces += surface ? 1 : 0;
                    // uploadPixels: the double difference rounded to float once.
                    const glm::vec3 p(surface ? glm::dvec3(r.gbuffer.position.at(x, y)) - anchor : glm::dvec3(0.0));
                    for (int c = 0; c < 3; ++c)
                        EXPECT_LE(std::abs(starts[s * 16][c] - p[c]),
                                  std::nextafter(std::abs(p[c]), INFINITY) - std::abs(p[c]))
                            << x << ", " << y << ": " << starts[s * 16][c] << " against " << p[c];
                    EXPECT_EQ(starts[s * 16].w, surface ? 1.0f : 0.0f);
                    EXPECT_EQ(starts[s * 16 + 1], glm::vec4(r.gbuffer.normal.at(x, y), 0.0f)) << x << ", " << y;
                }
            EXPECT_GT(surfaces, 50);
        }
}

// The resident combine reads the G-buffer and the visibilities from images and writes an image:
// the same as the combine of uploaded buffers (the same shader on the same floats: equal but for
// the compiler's freedom to contract the two variants differently, 1e-6 relative), and so the
// C++ combine within that test's tolerance, with and without visibilities and capsules (at every
// pixel and at the traced ones), far from the origin too.
TEST(ConeCombineGpu, TheResidentCombineMatchesTheUploadedOne)
{
    gpu::Context context;
    ProbeDispatch probe(context);
    ConeCombineGpu resident, uploaded;
    for (const glm::dvec3 shift : {glm::dvec3(0.0), glm::dvec3(1e5, -3e4, 7e4)}) {
        const Inputs in = makeInputs(61, 37, 4, shift);
        const GpuInputs onGpu(context, in);
        for (const bool visibility : {false, true})
            for (const int capsules : {0, 1, 2}) {
                SCOPED_TRACE("visibility " + std::to_string(visibility) + ", capsules " + std::to_string(capsules));
                const ConeCombineInputs c = describe(in, visibility, capsules > 0,
                                                     capsules == 2 ? CapsuleResolution::Traced : CapsuleResolution::Full);
                ResidentCombineInputs r;
                r.gbuffer = &onGpu.images;
                if (visibility)
                    r.visibility = onGpu.getVisibility();
                r.capsules = c.capsules;
                r.coneHalfAngle = c.coneHalfAngle;
                r.capsuleResolution = c.capsuleResolution;
                const PixelConeDispatch& d = probe.run({.gpu = &onGpu.images, .factor = 4}, shift, 0, &in.cones);
                const gpu::Image& image = resident.combineResident(context, d, 4, r);
                EXPECT_EQ(&image, resident.getResidentOutput());
                EXPECT_EQ(image.getDesc().width, 61u);
                const Image<glm::vec3> fromImages = resident.readBackResident();
                const Image<glm::vec3> fromBuffers = uploaded.combine(context, c);
                const Difference same = compare(fromBuffers, fromImages, in.full);
                ASSERT_GT(same.lit, 1500);
                EXPECT_EQ(same.skyNonZero, 0);
                EXPECT_LT(same.worst, 1e-6);
                const Difference cpu = compare(combineCones(c), fromImages, in.full);
                EXPECT_LT(cpu.mean, 1e-6);
                EXPECT_LT(cpu.worst, 1e-4);
                // Only the capsules cross the bus: 4 vec4 each.
                EXPECT_EQ(resident.getLastUploadBytes(), capsules > 0 ? in.capsules.size() * 64 : 0u);
            }
    }
}

// What the resident combine refuses: visibilities of another size (named), a reduction that is
// not the traced one, and a read-back before any combine.
TEST(ConeCombineGpu, TheResidentCombineRefusesInputsThatDoNotFit)
{
    gpu::Context context;
    ProbeDispatch probe(context);
    const Inputs in = makeInputs(40, 24, 2, glm::dvec3(0.0));
    const GpuInputs onGpu(context, in);
    ConeCombineGpu combiner;
    EXPECT_THROW(combiner.readBackResident(), Error);
    const PixelConeDispatch& d = probe.run({.gpu = &onGpu.images, .factor = 2}, glm::dvec3(0.0), 0, &in.cones);
    ResidentCombineInputs r;
    r.gbuffer = &onGpu.images;
    EXPECT_THROW(combiner.combineResident(context, d, 4, r), Error);
    gpu::Image small = context.createImage({gpu::ImageDimension::Image2D, gpu::Format::RGBA32Float, 20, 12, 1,
                                            gpu::ImageUsage::StorageAndSampled, "test.small_visibility"});
    r.visibility = onGpu.getVisibility();
    r.visibility[2] = &small;
    try {
        combiner.combineResident(context, d, 2, r);
        FAIL() << "expected an error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("'test.small_visibility' is 20x12"), std::string::npos) << e.what();
    }
}

// Not a test: the two combines' wall times at 1280x720 with a quarter-resolution trace, with and
// without capsules, for the choice shouldCombineOnGpu makes (run it with
// --gtest_also_run_disabled_tests; the medians of three calls, after one).
TEST(ConeCombineGpu, DISABLED_Timing)
{
    for (const bool capsules : {false, true}) {
        const Inputs in = makeInputs(1280, 720, 4, glm::dvec3(0.0));
        gpu::Context context;
        ConeCombineGpu combiner;
        const ConeCombineInputs c = describe(in, false, capsules);
        const gpu::Buffer& cones = combiner.uploadCones(context, in.cones);
        std::vector<double> cpuMs, gpuMs;
        for (int repeat = 0; repeat < 4; ++repeat) {
            const auto t0 = std::chrono::steady_clock::now();
            const Image<glm::vec3> cpu = combineCones(c);
            const auto t1 = std::chrono::steady_clock::now();
            const Image<glm::vec3> gpu = combiner.combine(context, cones, c);
            const auto t2 = std::chrono::steady_clock::now();
            if (repeat == 0)
                continue;
            cpuMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
            gpuMs.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
        }
        std::sort(cpuMs.begin(), cpuMs.end());
        std::sort(gpuMs.begin(), gpuMs.end());
        std::printf("%s: C++ combine %.1f ms, Vulkan combine %.1f ms (%s)\n",
                    capsules ? "10 capsules" : "no capsules", cpuMs[1], gpuMs[1],
                    context.getDeviceInfo().name.c_str());
    }
}

} // namespace
