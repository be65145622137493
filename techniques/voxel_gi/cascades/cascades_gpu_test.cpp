// The Vulkan pixel gather of the cascades against the C++ one: same structure, same G-buffer,
// compared with the tolerance stated in families/voxel_gi/voxel_gi_gpu_parity.h.

#include "cascade_gather_gpu.h"
#include "cascade_inject_gpu.h"
#include "cascade_volume.h"

#include "families/voxel_gi/cone_combine_gpu.h"
#include "families/voxel_gi/voxel_gi_gpu_parity.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"
#include "families/voxel_gi/voxelize_gpu.h"
#include "gpu/context.h"
#include "reference/reference.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace rtlab;
using namespace rtlab::voxelgi;
using namespace rtlab::voxelgi::testing;

namespace {

// The camera looking into the open room around `offset`.
scene::Camera makeRoomCamera(const glm::vec3& offset)
{
    scene::Camera camera;
    camera.position = offset + glm::vec3(0.8f, 0.4f, 1.6f);
    camera.target = offset + glm::vec3(-0.5f, -0.7f, -0.5f);
    camera.nearPlane = 1e-3f;
    return camera;
}

// The C++ and Vulkan cones of the open room seen from a camera, checked against each other.
// With `staged`, buffers take a discrete GPU's paths (gpu::ContextOptions::forceStagingUploads):
// the structure's through staging buffers, the per-frame pixels, levels and the combine's
// inputs and output in host-visible memory (gpu::BufferDesc::hostVisible).
std::pair<std::vector<glm::vec3>, std::vector<glm::vec3>>
compare(const glm::vec3& offset, const CascadeSettings& settings, bool staged = false)
{
    const scene::RenderScene s = makeOpenRoom(offset);
    const scene::Camera camera = makeRoomCamera(offset);
    const scene::GBuffer g = reference::castGBuffer(s, camera, 48, 32);
    CascadeVolume volume(settings);
    volume.voxelize(s, "k", glm::dvec3(camera.position), 0, false);
    volume.injectLight(s, "l", 0, false);
    std::vector<glm::vec3> cpuCones, gpuCones;
    volume.gatherCones(g, cpuCones); // with split cones, this traces the far cones the GPU reads
    gpu::ContextOptions options;
    options.forceStagingUploads = staged;
    gpu::Context context(options);
    EXPECT_TRUE(!staged || context.usesStagingUploads());
    CascadeGatherGpu gather;
    gather.gatherCones(context, volume, g, gpuCones);
    expectGpuConesMatchCpu(cpuCones, gpuCones, g, volume.getCones().halfAngle);
    // A second call uploads no level (nothing changed), only the pixels.
    gather.gatherCones(context, volume, g, gpuCones);
    EXPECT_EQ(gather.getLastUploadBytes(), 2 * g.position.pixels.size() * sizeof(glm::vec4));
    // Kept on the device: the same radiances, and the Vulkan combine of them gives the C++ combine
    // of the read-back ones (to the tolerance of cone_combine_gpu_test.cpp, 1e-4 per pixel).
    const gpu::Buffer& onDevice = gather.gatherConesOnDevice(context, volume, g);
    const std::vector<glm::vec4> kept = onDevice.downloadVector<glm::vec4>(gpuCones.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < kept.size(); ++i)
        differ += glm::vec3(kept[i]) != gpuCones[i] ? 1 : 0;
    EXPECT_EQ(differ, 0u);
    const ReducedGBuffer same = reduceGBuffer(g, 1);
    ConeCombineInputs in;
    in.coneRadiance = &gpuCones;
    in.reduced = &same;
    in.full = &g;
    in.coneHalfAngle = volume.getCones().halfAngle;
    ConeCombineGpu combiner;
    const Image<glm::vec3> cpu = combineCones(in), gpu = combiner.combine(context, onDevice, in);
    std::size_t pixelsOff = 0;
    for (std::size_t i = 0; i < cpu.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c)
            pixelsOff += std::abs(gpu.pixels[i][c] - cpu.pixels[i][c]) >
                         1e-4f * std::max(1e-3f, cpu.pixels[i][c]);
    EXPECT_EQ(pixelsOff, 0u);
    return {cpuCones, gpuCones};
}

CascadeSettings testSettings()
{
    CascadeSettings s;
    s.levels = 3;
    s.resolution = 16;
    s.voxelSize = 0.1;
    s.supersampling = 2;
    s.oneLevelPerFrame = false;
    return s;
}

TEST(CascadesGpu, VulkanGatherMatchesTheCppGather)
{
    compare(glm::vec3(0.0f), testSettings());
}

TEST(CascadesGpu, VulkanGatherMatchesThroughADiscreteGpusTransfers)
{
    compare(glm::vec3(0.0f), testSettings(), true);
}

TEST(CascadesGpu, VulkanGatherMatchesFarFromTheOrigin)
{
    compare(glm::vec3(1e5f, 0.0f, -1e5f), testSettings());
}

// The GPU matches the C++ gather with `option` set, near the origin and at 1e5, and follows the
// option: it changes the answer (against `plain`) far more than the two devices differ.
void expectTheGpuFollows(const CascadeSettings& option, const CascadeSettings& plain)
{
    for (const glm::vec3 offset : {glm::vec3(0.0f), glm::vec3(1e5f, 0.0f, -1e5f)}) {
        const auto [cpu, gpu] = compare(offset, option);
        const auto [cpuPlain, gpuPlain] = compare(offset, plain);
        double byOption = 0.0, byDevice = 0.0;
        for (std::size_t i = 0; i < cpu.size(); ++i) {
            byOption += glm::length(cpu[i] - cpuPlain[i]);
            byDevice += glm::length(gpu[i] - cpu[i]);
        }
        EXPECT_GT(byOption, 0.0);
        EXPECT_LT(byDevice, 0.01 * byOption);
    }
}

TEST(CascadesGpu, VulkanGatherMatchesWithTheLevelNoise)
{
    // The noise is hashed from world voxel cells on both sides (the GPU from the anchor's cell
    // and relative positions). Voxels of 0.2 so that the room's pixels lie in level 1's blend
    // band (radius 1.4 to 2.8 m).
    CascadeSettings plain = testSettings();
    plain.voxelSize = 0.2;
    CascadeSettings noisy = plain;
    noisy.levelNoise = 0.3;
    expectTheGpuFollows(noisy, plain);
}

TEST(CascadesGpu, VulkanGatherMatchesWithSplitCones)
{
    // The far cones traced in C++ (prepareFarCones), the near parts and the composite on Vulkan;
    // voxels of 0.2 so that pixels blend between two start levels too.
    CascadeSettings plain = testSettings();
    plain.voxelSize = 0.2;
    CascadeSettings split = plain;
    split.farStart = 2.5;
    expectTheGpuFollows(split, plain);
}

} // namespace

namespace {

// The open room (sky, a point light) voxelized around a camera near `offset`.
CascadeVolume makeVoxelizedRoom(const scene::RenderScene& s, const glm::vec3& offset,
                                const CascadeSettings& settings)
{
    CascadeVolume volume(settings);
    volume.voxelize(s, "k", glm::dvec3(makeRoomCamera(offset).position), 0, false);
    return volume;
}

// Relative difference of two irradiances (their channel sums) where the first is lit.
struct Differences {
    int lit = 0, within = 0, beyond = 0; // within 1e-3, beyond 1e-2
    double sum = 0.0, worst = 0.0;
    void add(const glm::vec3& cpu, const glm::vec3& gpu)
    {
        const double a = cpu.x + cpu.y + cpu.z, b = gpu.x + gpu.y + gpu.z;
        ASSERT_TRUE(std::isfinite(b));
        if (a <= 1e-6) {
            EXPECT_LE(std::abs(b), 1e-5);
            return;
        }
        const double rel = std::abs(a - b) / a;
        sum += rel;
        worst = std::max(worst, rel);
        within += rel <= 1e-3 ? 1 : 0;
        beyond += rel > 1e-2 ? 1 : 0;
        ++lit;
    }
};

// Light injection's cones on Vulkan against gatherVoxelIrradiance in C++, one level's surface
// voxels after the volume was lit (every field non-zero), near the origin and at 1e5. Tolerance
// as for the pixel gather (voxel_gi_gpu_parity.h: float from anchor-relative positions against
// double, a sample next to a voxel or level boundary may land on the other side): mean relative
// difference below 1e-5, 99 % of the lit faces within 1e-3. Measured on lavapipe: mean at most
// 5.5e-6 (the bounce fields of level 2), every face within 4.4e-4. Both tests fail when the
// shader drops the sky or the shadow cone's visibility.
TEST(CascadesGpu, VulkanInjectionConesMatchTheCppOnes)
{
    for (const glm::vec3 offset : {glm::vec3(0.0f), glm::vec3(1e5f, 0.0f, -1e5f)}) {
        const scene::RenderScene s = makeOpenRoom(offset);
        CascadeVolume volume = makeVoxelizedRoom(s, offset, testSettings());
        volume.injectLight(s, "l", 0, false);
        InjectionLights lights;
        lights.pointLights = &s.pointLights;
        lights.hasSky = true;
        lights.skyPerCone = computeSkyPerCone(s.sky, volume.getCones());
        gpu::Context context;
        CascadeInjectGpu inject;
        // Level 0 (1.6 m around the camera) holds no surface here; levels 1 and 2 do.
        int levelsChecked = 0;
        for (int li = 0; li < volume.getLevelCount(); ++li) {
            const auto& level = volume.getLevel(li);
            std::vector<FaceIrradiance> gpuIrradiance;
            inject.gatherIrradiance(context, volume, li, lights, gpuIrradiance);
            ASSERT_EQ(gpuIrradiance.size(), level.grid.surfaceVoxels.size());
            if (gpuIrradiance.empty())
                continue;
            ++levelsChecked;
            Differences d[kFieldCount];
            const int R = level.region.resolution;
            for (std::size_t i = 0; i < gpuIrradiance.size(); ++i) {
                const std::uint32_t vox = level.grid.surfaceVoxels[i];
                InjectionVoxel v;
                v.centre = level.region.getVoxelCentre(int(vox % std::uint32_t(R)),
                                                       int((vox / std::uint32_t(R)) % std::uint32_t(R)),
                                                       int(vox / (std::uint32_t(R) * std::uint32_t(R))));
                v.normal = level.grid.normal[vox];
                v.voxelSize = level.region.voxelSize;
                v.faces = &level.grid.faces[std::size_t(vox) * kFaceCount];
                const FaceIrradiance cpu = gatherVoxelIrradiance(CascadeVolume::FieldSampler{&volume}, v,
                                                                 volume.getCones(), lights,
                                                                 volume.getInjectionSettings());
                for (int field = kDirect; field < kFieldCount; ++field)
                    for (int face = 0; face < kFaceCount; ++face)
                        d[field].add(cpu.e[std::size_t(field)][std::size_t(face)],
                                     gpuIrradiance[i].e[std::size_t(field)][std::size_t(face)]);
            }
            for (int field = kDirect; field < kFieldCount; ++field) {
                SCOPED_TRACE("level " + std::to_string(li) + ", field " + std::to_string(field));
                ASSERT_GT(d[field].lit, 100);
                EXPECT_LT(d[field].sum / d[field].lit, 1e-5);
                EXPECT_GE(d[field].within, int(0.99 * d[field].lit));
            }
        }
        EXPECT_EQ(levelsChecked, 2);
        // Only the buffers that changed go up again: nothing, since nothing was re-lit.
        inject.resetCounters();
        std::vector<FaceIrradiance> again;
        inject.gatherIrradiance(context, volume, 1, lights, again);
        const std::size_t perCall = volume.getLevel(1).grid.surfaceVoxels.size() * 2 * sizeof(glm::vec4) +
                                    kConeCount * sizeof(glm::vec4) + 2 * s.pointLights.size() * sizeof(glm::vec4);
        EXPECT_EQ(inject.getCounters().uploadBytes, perCall);
    }
}

// A whole update with the cones on Vulkan gives the light buffers of the C++ update, for both
// schedules (three passes: the buffers go up again between the passes), and the pixels gather
// the same light from them; the tolerance of voxel_gi_gpu_parity.h.
TEST(CascadesGpu, VulkanInjectionGivesTheCppLightBuffers)
{
    for (const bool onePass : {false, true}) {
        SCOPED_TRACE(onePass ? "one pass" : "three passes");
        const glm::vec3 offset(0.0f);
        const scene::RenderScene s = makeOpenRoom(offset);
        CascadeSettings settings = testSettings();
        settings.onePass = onePass;
        settings.bounces = 3;
        CascadeVolume cpu = makeVoxelizedRoom(s, offset, settings);
        CascadeVolume gpu = makeVoxelizedRoom(s, offset, settings);
        gpu::Context context;
        CascadeInjectGpu inject;
        const auto onGpu = [&](int level, const InjectionLights& lights, std::vector<FaceIrradiance>& out) {
            inject.gatherIrradiance(context, gpu, level, lights, out);
        };
        // One pass needs one update per bounce to carry the light through its buffers.
        for (int update = 0; update < (onePass ? 3 : 1); ++update) {
            EXPECT_NE(cpu.injectLight(s, "l", update, false), "");
            EXPECT_NE(gpu.injectLight(s, "l", update, false, onGpu), "");
        }
        // Three passes of (or three updates of one pass over) the two levels holding surface.
        EXPECT_EQ(inject.getCounters().dispatches, 2 * 3);
        for (int li = 1; li < settings.levels; ++li) {
            Differences d[kFieldCount];
            const auto& a = cpu.getLevel(li);
            const auto& b = gpu.getLevel(li);
            for (const std::uint32_t vox : a.grid.surfaceVoxels)
                for (int face = 0; face < kFaceCount; ++face)
                    for (int field = kDirect; field < kFieldCount; ++field) {
                        const std::size_t f = std::size_t(vox) * kFaceCount + std::size_t(face);
                        d[field].add(a.light[std::size_t(field)][f], b.light[std::size_t(field)][f]);
                    }
            for (int field = kDirect; field < kFieldCount; ++field) {
                SCOPED_TRACE("level " + std::to_string(li) + ", field " + std::to_string(field));
                ASSERT_GT(d[field].lit, 100);
                EXPECT_LT(d[field].sum / d[field].lit, 1e-5);
                EXPECT_GE(d[field].within, int(0.99 * d[field].lit));
            }
        }
        const scene::GBuffer g = reference::castGBuffer(s, makeRoomCamera(offset), 48, 32);
        std::vector<glm::vec3> fromCpu, fromGpu;
        cpu.gatherCones(g, fromCpu);
        gpu.gatherCones(g, fromGpu);
        expectGpuConesMatchCpu(fromCpu, fromGpu, g, cpu.getCones().halfAngle);
    }
}

} // namespace

namespace {

// The same voxels up to float rounding: the scenes below are axis-aligned boxes, which the
// Vulkan voxelizer gives exactly as C++ does but for float sums (voxelize_gpu_test.cpp).
void expectSameVoxelsUpToRounding(const CascadeVolume& a, const CascadeVolume& b)
{
    for (int level = 0; level < a.getLevelCount(); ++level) {
        const VoxelGrid& x = a.getLevel(level).grid;
        const VoxelGrid& y = b.getLevel(level).grid;
        ASSERT_TRUE(x.region == y.region) << level;
        EXPECT_EQ(x.flags, y.flags) << level;
        EXPECT_EQ(x.surfaceVoxels, y.surfaceVoxels) << level;
        double worst = 0.0;
        for (std::size_t i = 0; i < x.faces.size(); ++i) {
            EXPECT_EQ(x.faces[i].a, y.faces[i].a);
            worst = std::max({worst, double(glm::length(glm::vec3(x.faces[i]) - glm::vec3(y.faces[i]))),
                              double(glm::length(x.emission[i] - y.emission[i]))});
        }
        EXPECT_LE(worst, 1e-5) << level;
    }
}

// The levels voxelized on Vulkan through their updates (first voxelization, a scroll that
// voxelizes only the new slabs, an edit that re-voxelizes only the changed region) hold the
// voxels the C++ path gives.
TEST(CascadesGpu, VulkanVoxelizationScrollsAndEditsLikeTheCppOne)
{
    const glm::vec3 emission(0.1f, 0.0f, 0.0f);
    const scene::RenderScene before = makeRoomWithBox(-0.2f, emission), after = makeRoomWithBox(-0.14f, emission);
    CascadeSettings settings = testSettings();
    settings.resolution = 16;
    settings.voxelSize = 1.0 / 16.0;
    gpu::Context context;
    VoxelizerGpu voxelizer;
    const CascadeVolume::Voxelizer onGpu = [&](const scene::RenderScene& g, const VoxelRegion& r,
                                               const VoxelizeOptions& o) {
        return voxelizer.voxelize(context, g, r, o);
    };
    CascadeVolume cpu(settings), gpu(settings);
    const glm::dvec3 a(0.0), b(3.0 / 16.0 + 0.01, 0.0, -1.0 / 16.0);
    cpu.voxelize(before, "before", a, 0, false);
    gpu.voxelize(before, "before", a, 0, false, onGpu);
    expectSameVoxelsUpToRounding(cpu, gpu);
    EXPECT_NE(gpu.voxelize(before, "before", b, 1, false, onGpu).find("voxelized the new slabs"), std::string::npos);
    cpu.voxelize(before, "before", b, 1, false);
    expectSameVoxelsUpToRounding(cpu, gpu);
    EXPECT_NE(gpu.voxelize(after, "after", b, 2, false, onGpu).find("re-voxelized the changed region"),
              std::string::npos);
    cpu.voxelize(after, "after", b, 2, false);
    expectSameVoxelsUpToRounding(cpu, gpu);
    EXPECT_GE(voxelizer.getCounters().calls, 4);
    EXPECT_EQ(voxelizer.getCounters().fallbacks, 0);
}

} // namespace

namespace {

// Split cones: the far cones traced on Vulkan (the gather shader's far-cone mode) against those
// traced in C++, at the same voxel centres, near the origin and at 1e5; then the Vulkan pixel
// gather over the Vulkan far cones against the whole C++ split gather (the tolerance of
// voxel_gi_gpu_parity.h). Tolerance for the far cones: 99 % within 1e-3 relative, at most 1 %
// beyond 1e-2 and a mean below 1e-3. Far cones run from the coarse levels to the cascade's outer
// sphere, where a sample just inside adds one more step and one just outside ends the cone: in
// float and double a few cones end differently. Measured on lavapipe: 17 of 2,219 cones beyond
// 1e-3, 6 beyond 1e-2 (worst 6 %), mean 1.5e-4, the same near the origin and at 1e5.
TEST(CascadesGpu, VulkanFarConesMatchTheCppOnes)
{
    for (const glm::vec3 offset : {glm::vec3(0.0f), glm::vec3(1e5f, 0.0f, -1e5f)}) {
        const scene::RenderScene s = makeOpenRoom(offset);
        const scene::Camera camera = makeRoomCamera(offset);
        const scene::GBuffer g = reference::castGBuffer(s, camera, 48, 32);
        CascadeSettings settings = testSettings();
        settings.voxelSize = 0.2;
        settings.farStart = 2.5;
        CascadeVolume cpu(settings), gpu(settings);
        for (CascadeVolume* v : {&cpu, &gpu}) {
            v->voxelize(s, "k", glm::dvec3(camera.position), 0, false);
            v->injectLight(s, "l", 0, false);
        }
        gpu::Context context;
        CascadeGatherGpu gather;
        std::size_t traced = 0;
        cpu.prepareFarCones(g);
        gpu.prepareFarCones(g, [&](const std::vector<std::pair<int, std::uint32_t>>& centres,
                                   std::vector<glm::vec3>& out, std::vector<glm::vec3>* sky) {
            traced += centres.size();
            gather.traceFarCones(context, gpu, centres, out, sky);
        });
        ASSERT_GT(traced, 100u);
        Differences d;
        for (int li = 0; li < settings.levels; ++li) {
            const auto& a = cpu.getLevel(li);
            const auto& b = gpu.getLevel(li);
            ASSERT_EQ(a.farSlot, b.farSlot);
            ASSERT_EQ(a.far.size(), b.far.size());
            for (std::size_t i = 0; i < a.far.size(); ++i)
                d.add(a.far[i], b.far[i]);
        }
        ASSERT_GT(d.lit, 100);
        EXPECT_LT(d.sum / d.lit, 1e-3);
        EXPECT_GE(d.within, int(0.99 * d.lit));
        EXPECT_LE(d.beyond, d.lit / 100);
        // The pixels over the Vulkan far cones against the whole C++ split gather.
        std::vector<glm::vec3> cpuCones, gpuCones;
        cpu.gatherCones(g, cpuCones);
        gather.gatherCones(context, gpu, g, gpuCones);
        expectGpuConesMatchCpu(cpuCones, gpuCones, g, cpu.getCones().halfAngle);
    }
}

} // namespace

namespace {

// The cones' sky and emitters traced with the light on Vulkan (cone_march.glsl: the sky's own
// transmittance from the sky start on, the emitters the cones meet; with split cones the far
// cones' sky through the near part's transmittance) against the C++ march, on the open room
// with a glowing box, with the tolerance of voxel_gi_gpu_parity.h. The light is unchanged by
// tracing the sky.
void compareSky(const glm::vec3& offset, const CascadeSettings& settings)
{
    scene::RenderScene s = makeOpenRoom(offset);
    addFloorEmitter(s, offset);
    const scene::Camera camera = makeRoomCamera(offset);
    const scene::GBuffer g = reference::castGBuffer(s, camera, 48, 32);
    CascadeVolume cpu(settings), gpu(settings);
    for (CascadeVolume* v : {&cpu, &gpu}) {
        v->voxelize(s, "k", glm::dvec3(camera.position), 0, false);
        v->injectLight(s, "l", 0, false);
    }
    bool emits = false;
    for (int i = 0; i < cpu.getLevelCount(); ++i)
        emits = emits || cpu.getLevel(i).emits;
    ASSERT_TRUE(emits);
    ConeSkyOutput sky;
    sky.skyPerCone = computeSkyPerCone(s.sky, cpu.getCones());
    std::vector<glm::vec3> cpuCones, cpuSky, gpuCones, gpuSky;
    sky.out = &cpuSky;
    cpu.gatherCones(g, cpuCones, &sky);
    ASSERT_EQ(cpuSky.size(), cpuCones.size());
    gpu::Context context;
    CascadeGatherGpu gather;
    gather.setConeSky(sky.skyPerCone);
    gpu.setConeSky(&sky.skyPerCone);
    if (settings.farStart > 0.0)
        gpu.prepareFarCones(g, [&](const std::vector<std::pair<int, std::uint32_t>>& centres,
                                   std::vector<glm::vec3>& out, std::vector<glm::vec3>* farSky) {
            gather.traceFarCones(context, gpu, centres, out, farSky);
        });
    gather.gatherCones(context, gpu, g, gpuCones);
    ASSERT_TRUE(gather.tracedSky());
    gather.readBackSky(gpuSky);
    expectGpuConesMatchCpu(cpuCones, gpuCones, g, cpu.getCones().halfAngle);
    expectGpuConesMatchCpu(cpuSky, gpuSky, g, cpu.getCones().halfAngle);
}

TEST(CascadesGpu, VulkanGatherTracesTheConesSkyAsTheCppOne)
{
    CascadeSettings split = testSettings();
    split.voxelSize = 0.2;
    split.farStart = 2.5;
    for (const bool opticalDepth : {false, true}) {
        CascadeSettings plain = testSettings();
        plain.skyOpticalDepth = split.skyOpticalDepth = opticalDepth;
        compareSky(glm::vec3(0.0f), plain);
        compareSky(glm::vec3(0.0f), split);
    }
    compareSky(glm::vec3(1e5f, 0.0f, -1e5f), split);
}

} // namespace
