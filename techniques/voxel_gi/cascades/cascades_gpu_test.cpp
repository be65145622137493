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

void compare(const glm::vec3& offset, const CascadeSettings& settings)
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
    volume.gatherCones(g, cpuCones);
    gpu::Context context;
    CascadeGatherGpu gather;
    gather.gatherCones(context, volume, g, gpuCones);
    expectGpuConesMatchCpu(cpuCones, gpuCones, g, volume.getCones().halfAngle);
    // A second call uploads no level (nothing changed), only the pixels.
    gather.gatherCones(context, volume, g, gpuCones);
    EXPECT_EQ(gather.getLastUploadBytes(), 2 * g.position.pixels.size() * sizeof(glm::vec4));
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

} // namespace
