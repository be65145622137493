// The Vulkan pixel gather of the cascades against the C++ one: same structure, same G-buffer,
// compared with the tolerance stated in families/voxel_gi/voxel_gi_gpu_parity.h.

#include "cascade_gather_gpu.h"
#include "cascade_volume.h"

#include "families/voxel_gi/voxel_gi_gpu_parity.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"
#include "gpu/context.h"
#include "reference/reference.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace rtlab;
using namespace rtlab::voxelgi;
using namespace rtlab::voxelgi::testing;

namespace {

// The C++ and Vulkan cones of the open room seen from a camera, checked against each other.
std::pair<std::vector<glm::vec3>, std::vector<glm::vec3>> compare(const glm::vec3& offset,
                                                                  const CascadeSettings& settings)
{
    const scene::RenderScene s = makeOpenRoom(offset);
    scene::Camera camera;
    camera.position = offset + glm::vec3(0.8f, 0.4f, 1.6f);
    camera.target = offset + glm::vec3(-0.5f, -0.7f, -0.5f);
    camera.nearPlane = 1e-3f;
    const scene::GBuffer g = reference::castGBuffer(s, camera, 48, 32);
    CascadeVolume volume(settings);
    volume.voxelize(s, "k", glm::dvec3(camera.position), 0, false);
    volume.injectLight(s, "l", 0, false);
    std::vector<glm::vec3> cpuCones, gpuCones;
    volume.gatherCones(g, cpuCones); // with split cones, this traces the far cones the GPU reads
    gpu::Context context;
    CascadeGatherGpu gather;
    gather.gatherCones(context, volume, g, gpuCones);
    expectGpuConesMatchCpu(cpuCones, gpuCones, g, volume.getCones().halfAngle);
    // A second call uploads no level (nothing changed), only the pixels.
    gather.gatherCones(context, volume, g, gpuCones);
    EXPECT_EQ(gather.getLastUploadBytes(), 2 * g.position.pixels.size() * sizeof(glm::vec4));
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
