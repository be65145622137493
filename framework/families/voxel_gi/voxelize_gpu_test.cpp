// The Vulkan voxelizer against the C++ one (voxelize.h) on the same scenes and regions: the same
// surface and solid voxels, the same coverage and attributes up to float rounding, the box
// options (a scrolled slab, a dug region), huge coordinates, the fallback when a ray meets too
// many surfaces, and the arguments it refuses.

#include "families/voxel_gi/voxelize_gpu.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"

#include "core/error.h"
#include "gpu/context.h"
#include "scene/procedural.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>

using namespace rtlab;
using namespace rtlab::voxelgi;
using namespace rtlab::voxelgi::testing;

namespace {

struct GridDifference {
    std::size_t voxels = 0, flagsDiffer = 0;
    std::size_t faces = 0, occupancyDiffer = 0; // faces whose occupancy differs at all
    double worstOccupancy = 0.0;                // largest occupancy difference
    double worstAttribute = 0.0;                // largest albedo / emission difference
    double worstNormal = 0.0;                   // largest difference of the surface normals
    std::size_t attributeDiffer = 0;            // faces (both covered) whose albedo differs > 1e-4
};

GridDifference compareGrids(const VoxelGrid& cpu, const VoxelGrid& gpu)
{
    GridDifference d;
    EXPECT_EQ(cpu.region, gpu.region);
    d.voxels = cpu.flags.size();
    EXPECT_EQ(gpu.flags.size(), d.voxels);
    for (std::size_t v = 0; v < d.voxels; ++v) {
        d.flagsDiffer += cpu.flags[v] != gpu.flags[v] ? 1 : 0;
        if (cpu.flags[v] == kVoxelSurface && gpu.flags[v] == kVoxelSurface)
            d.worstNormal = std::max(d.worstNormal, double(glm::length(cpu.normal[v] - gpu.normal[v])));
        for (int f = 0; f < kFaceCount; ++f) {
            const std::size_t i = v * kFaceCount + std::size_t(f);
            ++d.faces;
            const double occ = std::abs(double(cpu.faces[i].a) - double(gpu.faces[i].a));
            d.occupancyDiffer += occ > 0.0 ? 1 : 0;
            d.worstOccupancy = std::max(d.worstOccupancy, occ);
            if (cpu.faces[i].a > 0.0f && gpu.faces[i].a > 0.0f) {
                const double albedo = glm::length(glm::vec3(cpu.faces[i]) - glm::vec3(gpu.faces[i]));
                const double emission = glm::length(cpu.emission[i] - gpu.emission[i]);
                d.attributeDiffer += albedo > 1e-4 ? 1 : 0;
                d.worstAttribute = std::max({d.worstAttribute, albedo, emission});
            }
        }
    }
    return d;
}

scene::RenderScene makeRoomScene(glm::vec3 o)
{
    scene::RenderScene s = makeOpenRoom(o);
    // An emitter and a slanted box, so that faces see different materials at different depths.
    addBox(s, o + glm::vec3(-0.71f, -0.93f, 0.13f), o + glm::vec3(-0.33f, -0.41f, 0.52f),
           addMaterial(s, glm::vec3(0.1f, 0.7f, 0.2f), glm::vec3(2.0f, 1.0f, 0.5f)));
    return s;
}

// Tolerance. The fragments are computed in float from positions relative to the region's corner,
// against double: a sample on a triangle's edge, or a fragment on a voxel boundary, may fall the
// other way. At most 1 in 10,000 voxels may change its flags, 2 in 10,000 faces their occupancy
// (by at most two rays' share, 2 / S^2) or their albedo or emission (by more than 1e-4); every
// other albedo and emission equal up to float rounding (1e-5), and the normals within 1e-2 (a
// voxel's normal is the normalised sum of its fragments' normals, which cancel where a thin wall's
// two sides share a coarse voxel). Measured on lavapipe: axis-aligned scenes identical to 2e-7;
// the slanted scene 1e5 from the origin 1 voxel's flags, 12 faces' occupancy (one ray each) and 6
// faces' attributes of 32^3 voxels, identical near the origin; tomorrow_town identical but for
// the sums (worst normal 2e-3 at 2 m voxels).
void expectGpuMatchesCpu(const scene::RenderScene& s, const VoxelRegion& region, const VoxelizeOptions& options)
{
    gpu::Context context;
    VoxelizerGpu gpu;
    VoxelizeStats cpuStats, gpuStats;
    const VoxelGrid a = voxelizeTriangles(s, region, options, &cpuStats);
    const VoxelGrid b = gpu.voxelize(context, s, region, options, &gpuStats);
    EXPECT_EQ(gpu.getCounters().fallbacks, 0);
    const GridDifference d = compareGrids(a, b);
    EXPECT_GT(a.surfaceVoxels.size(), 50u);
    EXPECT_EQ(cpuStats.trianglesConsidered, gpuStats.trianglesConsidered);
    EXPECT_LE(d.flagsDiffer, d.voxels / 10000);
    EXPECT_LE(d.occupancyDiffer, 2 * d.faces / 10000);
    EXPECT_LE(d.worstOccupancy, 2.0 / (options.supersampling * options.supersampling) + 1e-6);
    EXPECT_LE(d.attributeDiffer, 2 * d.faces / 10000);
    if (d.occupancyDiffer == 0 && d.flagsDiffer == 0 && d.attributeDiffer == 0) {
        EXPECT_LE(d.worstAttribute, 1e-5);
        EXPECT_LE(d.worstNormal, 1e-2);
    }
}

TEST(VoxelizeGpu, MatchesTheCppVoxelizer)
{
    const glm::vec3 o(0.0f);
    const scene::RenderScene s = makeRoomScene(o);
    for (const int supersampling : {1, 4})
        for (const bool solid : {true, false})
            expectGpuMatchesCpu(s, {glm::dvec3(o) - 1.3, 2.6 / 32, 32}, {.supersampling = supersampling, .solid = solid});
}

TEST(VoxelizeGpu, MatchesFarFromTheOrigin)
{
    const glm::vec3 o(1e5f, 0.0f, -1e5f);
    expectGpuMatchesCpu(makeRoomScene(o), {glm::dvec3(o) - 1.3, 2.6 / 32, 32}, {.supersampling = 4});
}

// Boxes turned about a slanted axis (closed, so solid spans form) and a soup of random
// triangles: edges and depths at arbitrary positions, where float and double may disagree.
scene::RenderScene makeSlantedScene(glm::vec3 o)
{
    scene::RenderScene s;
    const auto turned = [&](glm::vec3 lo, glm::vec3 hi, float angle, std::uint32_t m) {
        const std::size_t first = s.positions.size();
        addBox(s, lo, hi, m);
        const glm::vec3 axis = glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f));
        const glm::vec3 c = 0.5f * (lo + hi);
        for (std::size_t i = first; i < s.positions.size(); ++i) {
            // Rodrigues' rotation about `axis` through the box's centre.
            const glm::vec3 p = s.positions[i] - c;
            s.positions[i] = c + p * std::cos(angle) + glm::cross(axis, p) * std::sin(angle) +
                             axis * glm::dot(axis, p) * (1.0f - std::cos(angle));
        }
    };
    turned(o + glm::vec3(-0.9f, -0.8f, -0.7f), o + glm::vec3(0.1f, -0.2f, 0.4f), 0.61f,
           addMaterial(s, glm::vec3(0.8f, 0.3f, 0.2f)));
    turned(o + glm::vec3(0.2f, -0.3f, -0.6f), o + glm::vec3(0.9f, 0.8f, 0.1f), 1.13f,
           addMaterial(s, glm::vec3(0.2f, 0.4f, 0.9f), glm::vec3(0.5f, 0.5f, 0.0f)));
    const auto soup = addMaterial(s, glm::vec3(0.5f, 0.9f, 0.5f));
    std::uint32_t state = 12345u;
    const auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / 16777216.0f * 2.4f - 1.2f;
    };
    for (int t = 0; t < 300; ++t) {
        const std::uint32_t base = std::uint32_t(s.positions.size());
        const glm::vec3 c(next(), next(), next());
        for (int k = 0; k < 3; ++k) {
            s.positions.push_back(o + c + 0.15f * glm::vec3(next(), next(), next()));
            s.normals.push_back(glm::vec3(0, 1, 0));
        }
        s.indices.insert(s.indices.end(), {base, base + 1, base + 2});
        s.triangleMaterial.push_back(soup);
    }
    s.updateBounds();
    return s;
}

TEST(VoxelizeGpu, MatchesOnSlantedGeometry)
{
    for (const glm::vec3 o : {glm::vec3(0.0f), glm::vec3(1e5f, 0.0f, -1e5f)})
        expectGpuMatchesCpu(makeSlantedScene(o), {glm::dvec3(o) - 1.3, 2.6 / 32, 32}, {.supersampling = 4});
}

TEST(VoxelizeGpu, MatchesOnTomorrowTown)
{
    // 88,540 triangles (the meshed landscape and buildings): regions of 4, 16 and 64 m around its
    // centre, the largest with columns of over 3,000 triangles.
    const scene::Scene town = scene::makeProceduralScene("tomorrow_town");
    const scene::RenderScene s = town.assembleRenderScene(town.meshSdfModels(0), {}, 0);
    const glm::dvec3 c = 0.5 * (glm::dvec3(s.boundsMin) + glm::dvec3(s.boundsMax));
    for (const double size : {4.0, 16.0, 64.0})
        expectGpuMatchesCpu(s, {c - size / 2, size / 32, 32}, {.supersampling = 4});
}

TEST(VoxelizeGpu, VoxelizesOnlyTheBoxItIsGiven)
{
    // A scrolled slab and a dug region (voxelize.h VoxelizeOptions::boxBegin/boxEnd).
    const scene::RenderScene s = makeSlantedScene(glm::vec3(0.0f));
    const VoxelRegion region{glm::dvec3(-1.3), 2.6 / 32, 32};
    VoxelizeOptions slab{.supersampling = 4};
    slab.boxBegin = {28, 0, 0};
    expectGpuMatchesCpu(s, region, slab);
    VoxelizeOptions dug{.supersampling = 3};
    dug.boxBegin = {9, 11, 5};
    dug.boxEnd = {20, 17, 26};
    expectGpuMatchesCpu(s, region, dug);
}

TEST(VoxelizeGpu, FallsBackToTheCppPathWhenARayMeetsTooManySurfaces)
{
    // 70 stacked floors: a vertical ray meets 70 > 64 surfaces. The answer is the C++ one.
    scene::RenderScene s;
    const auto m = addMaterial(s, glm::vec3(0.6f));
    for (int i = 0; i < VoxelizerGpu::kMaxFragmentsPerRay + 6; ++i)
        addFloor(s, -0.9f + 0.025f * float(i), -0.7f, 0.7f, -0.7f, 0.7f, m);
    const VoxelRegion region{glm::dvec3(-1.0), 2.0 / 16, 16};
    gpu::Context context;
    VoxelizerGpu gpu;
    const VoxelGrid a = voxelizeTriangles(s, region, {.supersampling = 2});
    const VoxelGrid b = gpu.voxelize(context, s, region, {.supersampling = 2});
    EXPECT_EQ(gpu.getCounters().fallbacks, 1);
    EXPECT_EQ(a.flags, b.flags);
    EXPECT_EQ(a.faces, b.faces);
    EXPECT_EQ(a.surfaceVoxels, b.surfaceVoxels);
}

TEST(VoxelizeGpu, RefusesWhatItCannotDo)
{
    gpu::Context context;
    VoxelizerGpu gpu;
    const scene::RenderScene s = makeOpenRoom(glm::vec3(0.0f));
    EXPECT_THROW(gpu.voxelize(context, s, {glm::dvec3(0.0), 0.01, VoxelizerGpu::kMaxResolution + 2}, {}), Error);
    EXPECT_THROW(gpu.voxelize(context, s, {glm::dvec3(0.0), 0.0, 8}, {}), Error);
    EXPECT_THROW(gpu.voxelize(context, s, {glm::dvec3(0.0), 0.1, 8}, {.supersampling = 17}), Error);
    // An empty scene and an empty box give empty grids.
    EXPECT_TRUE(gpu.voxelize(context, scene::RenderScene{}, {glm::dvec3(0.0), 0.1, 8}, {}).surfaceVoxels.empty());
    VoxelizeOptions none;
    none.boxBegin = {3, 3, 3};
    none.boxEnd = {3, 8, 8};
    EXPECT_TRUE(gpu.voxelize(context, s, {glm::dvec3(-1.0), 0.25, 8}, none).surfaceVoxels.empty());
}

} // namespace
