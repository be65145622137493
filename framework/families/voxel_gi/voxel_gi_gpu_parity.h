#pragma once
// For the voxel_gi tests of Vulkan pixel gathers (cascades, svo): the GPU's 16 cone radiances
// against the C++ ones on the same structure and G-buffer. The shaders march in float from
// positions relative to an anchor, the C++ paths in double, so a sample next to a voxel or level
// boundary may land on the other side and a cone's march differs from there on. Measured on
// lavapipe (cascades): mean relative difference 2.5e-7 over the lit pixels, every pixel within
// 1e-2. Tolerance: mean below 1e-5 (room for drivers that round pow, log2 and division
// differently), 99 % of the lit pixels within 1e-3, at most 1 % of the cones off by more than 1e-3.
// The cones' sky (expectGpuConeSkyMatchesCpu), measured on lavapipe: mean 5e-8 to 1.4e-7 with the
// sky's transmittance in occupancy, 4.0e-6 (svo) and 6.8e-6 (the 64-ary tree) in optical depth,
// where each voxel's -ln(1 - a) is taken in float (1 - a loses the digits of a near 1).

#include "families/voxel_gi/upsample.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace rtlab::voxelgi::testing {

inline void expectGpuConesMatchCpu(const std::vector<glm::vec3>& cpuCones,
                                   const std::vector<glm::vec3>& gpuCones, const scene::GBuffer& g,
                                   double coneHalfAngle)
{
    ASSERT_EQ(cpuCones.size(), gpuCones.size());
    int conesOff = 0;
    for (std::size_t i = 0; i < cpuCones.size(); ++i) {
        const double a = cpuCones[i].x + cpuCones[i].y + cpuCones[i].z;
        const double b = gpuCones[i].x + gpuCones[i].y + gpuCones[i].z;
        conesOff += std::abs(a - b) > 1e-3 * std::max(a, 1e-3) ? 1 : 0;
    }
    EXPECT_LE(conesOff, int(cpuCones.size() / 100)) << "cones differing by more than 1e-3";
    // Compared as irradiance too: the cones combined per pixel.
    const ReducedGBuffer same = reduceGBuffer(g, 1);
    const auto combine = [&](const std::vector<glm::vec3>& cones) {
        ConeCombineInputs in;
        in.coneRadiance = &cones;
        in.reduced = &same;
        in.full = &g;
        in.coneHalfAngle = coneHalfAngle;
        return combineCones(in);
    };
    const Image<glm::vec3> cpu = combine(cpuCones), gpu = combine(gpuCones);
    ASSERT_EQ(cpu.pixels.size(), gpu.pixels.size());
    double sum = 0.0;
    int lit = 0, within = 0;
    for (std::size_t i = 0; i < cpu.pixels.size(); ++i) {
        const double a = cpu.pixels[i].x + cpu.pixels[i].y + cpu.pixels[i].z;
        const double b = gpu.pixels[i].x + gpu.pixels[i].y + gpu.pixels[i].z;
        ASSERT_TRUE(std::isfinite(b));
        if (a <= 1e-6) {
            EXPECT_LE(b, 1e-6);
            continue;
        }
        const double rel = std::abs(a - b) / a;
        sum += rel;
        within += rel <= 1e-3 ? 1 : 0;
        ++lit;
    }
    ASSERT_GT(lit, 100);
    EXPECT_LT(sum / lit, 1e-5);
    EXPECT_GE(within, int(0.99 * lit));
}

//! The cones' sky and emitters of a sparse structure's Vulkan gather (`gather`: setConeSky,
//! gatherCones, readBackSky) against the C++ march on the same `structure` (gatherCones with a
//! ConeSkyOutput), with the tolerance above; tracing the sky leaves the light as it was without
//! (`light`: the Vulkan cones traced without the sky), bit for bit.
template <class Structure, class Gather, class Context>
void expectGpuConeSkyMatchesCpu(Structure& structure, Gather& gather, Context& context, const scene::GBuffer& g,
                                const scene::Sky& sky, const std::vector<glm::vec3>& light)
{
    ConeSkyOutput out;
    out.skyPerCone = computeSkyPerCone(sky, structure.getCones());
    std::vector<glm::vec3> cpuCones, cpuSky, gpuSky, gpuLight;
    out.out = &cpuSky;
    structure.gatherCones(g, cpuCones, &out);
    gather.setConeSky(out.skyPerCone);
    gather.gatherCones(context, structure, g, gpuLight);
    gather.readBackSky(gpuSky);
    EXPECT_EQ(gpuLight, light);
    expectGpuConesMatchCpu(cpuSky, gpuSky, g, structure.getCones().halfAngle);
}

//! A glowing box on the open room's floor (makeOpenRoom): the emitter the cones' sky carries.
inline void addFloorEmitter(scene::RenderScene& s, glm::vec3 offset)
{
    addBox(s, offset + glm::vec3(0.5f, -1.0f, -0.9f), offset + glm::vec3(0.9f, -0.6f, -0.5f),
           addMaterial(s, glm::vec3(0.5f), glm::vec3(2.0f, 1.5f, 1.0f)));
}

} // namespace rtlab::voxelgi::testing
