// The shared voxelizer against hand-counted cases: a box's shell and solid interior, coverage of
// a partly covered column, open geometry that must not fill, geometry on voxel boundaries, huge
// coordinates, degenerate input and thread-count determinism.

#include "families/voxel_gi/voxelize.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"

#include "core/error.h"

#include <glm/common.hpp>
#include <glm/vector_relational.hpp>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <set>
#include <tuple>

using namespace rtlab;
using namespace rtlab::voxelgi;
using namespace rtlab::voxelgi::testing;

namespace {

VoxelRegion unitRegion(int resolution, glm::dvec3 origin = glm::dvec3(0.0))
{
    return {origin, 1.0 / resolution, resolution};
}

TEST(Voxelize, BoxHasAShellOfSurfaceVoxelsAndASolidInterior)
{
    scene::RenderScene s;
    const auto red = addMaterial(s, {0.7f, 0.1f, 0.1f});
    // [0.3, 0.7]^3 in an 8^3 grid of 0.125: surface voxels 2 and 5 on each axis, 3..4 inside.
    addBox(s, glm::vec3(0.3f), glm::vec3(0.7f), red);
    VoxelizeStats stats;
    const VoxelGrid g = voxelizeTriangles(s, unitRegion(8), {.supersampling = 4}, &stats);
    const VoxelRegion& r = g.region;
    int surface = 0, solid = 0;
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) {
                const bool inBox = x >= 2 && x <= 5 && y >= 2 && y <= 5 && z >= 2 && z <= 5;
                const bool inner = x >= 3 && x <= 4 && y >= 3 && y <= 4 && z >= 3 && z <= 4;
                const std::uint8_t f = g.flags[r.index(x, y, z)];
                EXPECT_EQ(bool(f & kVoxelSurface), inBox && !inner) << x << " " << y << " " << z;
                EXPECT_EQ(bool(f & kVoxelSolid), inner) << x << " " << y << " " << z;
                surface += (f & kVoxelSurface) ? 1 : 0;
                solid += (f & kVoxelSolid) ? 1 : 0;
            }
    EXPECT_EQ(surface, 64 - 8);
    EXPECT_EQ(solid, 8);
    EXPECT_EQ(stats.surfaceVoxels, std::size_t(surface));
    EXPECT_EQ(g.surfaceVoxels.size(), std::size_t(surface));
    // The -x face of a voxel on the box's -x side, inside the box's y-z extent: every x-ray hits.
    const glm::vec4 face = g.face(r.index(2, 3, 3), 1);
    EXPECT_FLOAT_EQ(face.a, 1.0f);
    EXPECT_NEAR(face.r, 0.7f, 1e-6f);
    // Along y it is covered where y-rays run inside the box (x from 0.3 on: 2 of 4 ray
    // columns), although they meet no surface in it.
    EXPECT_FLOAT_EQ(g.face(r.index(2, 3, 3), 2).a, 0.5f);
    // Its normal points out of the box.
    EXPECT_NEAR(g.normal[r.index(2, 3, 3)].x, -1.0f, 1e-6f);
    // Solid voxels are opaque and carry the surface albedo one layer in.
    const glm::vec4 inside = g.face(r.index(3, 3, 3), 1);
    EXPECT_FLOAT_EQ(inside.a, 1.0f);
    EXPECT_NEAR(inside.r, 0.7f, 1e-6f);
}

TEST(Voxelize, CoverageIsTheShareOfRaysThatHit)
{
    scene::RenderScene s;
    const auto white = addMaterial(s, glm::vec3(0.5f));
    // A floor ending at x = 0.5625, in the middle of voxel 4 (0.5 .. 0.625): 2 of 4 ray columns.
    addFloor(s, 0.51f, 0.0f, 0.5625f, 0.0f, 1.0f, white);
    const VoxelGrid g = voxelizeTriangles(s, unitRegion(8), {.supersampling = 4});
    const VoxelRegion& r = g.region;
    EXPECT_FLOAT_EQ(g.face(r.index(3, 4, 4), 2).a, 1.0f);
    EXPECT_FLOAT_EQ(g.face(r.index(4, 4, 4), 2).a, 0.5f);
    EXPECT_FLOAT_EQ(g.face(r.index(4, 4, 4), 3).a, 0.5f);
    EXPECT_FLOAT_EQ(g.face(r.index(5, 4, 4), 2).a, 0.0f);
    // An open floor does not fill the space under it.
    for (const auto f : g.flags)
        EXPECT_FALSE(f & kVoxelSolid);
}

TEST(Voxelize, CoverageChangesSmoothlyWhenGeometryMovesByLessThanAVoxel)
{
    // Moving a floor's edge across a voxel in 16 steps: the occupancy rises in steps of at most
    // 1/supersampling, never jumps from 0 to 1.
    float previous = 0.0f;
    for (int step = 0; step <= 16; ++step) {
        scene::RenderScene s;
        const auto white = addMaterial(s, glm::vec3(0.5f));
        addFloor(s, 0.51f, 0.0f, 0.5f + 0.125f * step / 16.0f, 0.0f, 1.0f, white);
        const VoxelGrid g = voxelizeTriangles(s, unitRegion(8), {.supersampling = 8});
        const float a = g.face(g.region.index(4, 4, 4), 2).a;
        EXPECT_LE(a - previous, 1.0f / 8.0f + 1e-6f);
        EXPECT_GE(a, previous);
        previous = a;
    }
    EXPECT_FLOAT_EQ(previous, 1.0f);
}

TEST(Voxelize, GeometryOnVoxelBoundariesIsCountedOnce)
{
    scene::RenderScene s;
    const auto white = addMaterial(s, glm::vec3(0.5f));
    // Faces exactly on voxel boundaries and a sample grid whose rays pass exactly through the
    // shared diagonal edges of the quads' triangles.
    addBox(s, glm::vec3(0.25f), glm::vec3(0.75f), white);
    VoxelizeStats stats;
    const VoxelGrid g = voxelizeTriangles(s, unitRegion(8), {.supersampling = 2}, &stats);
    // Per axis 8 x 8 rays cross the box, each meeting its two faces once: the rays through the
    // quads' diagonals are owned by one triangle only (top-left rule).
    EXPECT_EQ(stats.fragments, std::size_t(3 * 64 * 2));
    for (std::size_t v = 0; v < g.region.getVoxelCount(); ++v)
        for (int f = 0; f < kFaceCount; ++f) {
            const float a = g.faces[v * kFaceCount + std::size_t(f)].a;
            EXPECT_TRUE(a >= 0.0f && a <= 1.0f);
        }
    // Interior voxels 3..4 (centres inside 0.25 .. 0.75 on all axes, not surface) are solid.
    EXPECT_TRUE(g.flags[g.region.index(3, 3, 3)] & kVoxelSolid);
    EXPECT_TRUE(g.flags[g.region.index(4, 4, 4)] & kVoxelSolid);
}

TEST(Voxelize, HugeCoordinatesGiveTheSameVoxels)
{
    const glm::dvec3 far(1e5, -2e5, 3e5);
    scene::RenderScene a, b;
    // Faces at 10/32 and 22/32: exactly representable as floats at these offsets (spacing
    // 1/32 at 3e5), so the two boxes are the same box and the grids must be identical.
    addBox(a, glm::vec3(0.3125f), glm::vec3(0.6875f), addMaterial(a, glm::vec3(0.5f)));
    addBox(b, glm::vec3(far + 0.3125), glm::vec3(far + 0.6875), addMaterial(b, glm::vec3(0.5f)));
    const VoxelGrid ga = voxelizeTriangles(a, unitRegion(8), {.supersampling = 4});
    const VoxelGrid gb = voxelizeTriangles(b, unitRegion(8, far), {.supersampling = 4});
    EXPECT_EQ(ga.flags, gb.flags);
    for (std::size_t i = 0; i < ga.faces.size(); ++i)
        EXPECT_EQ(ga.faces[i].a, gb.faces[i].a);
}

TEST(Voxelize, DeterministicForAnyThreadCount)
{
    scene::RenderScene s;
    const auto m = addMaterial(s, {0.2f, 0.6f, 0.3f}, {0.0f, 1.0f, 0.0f});
    addRoom(s, glm::vec3(0.2f), glm::vec3(0.8f), 0.07f, m);
    addBox(s, glm::vec3(0.41f, 0.2f, 0.33f), glm::vec3(0.57f, 0.46f, 0.61f), m);
    VoxelGrid one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = voxelizeTriangles(s, unitRegion(16), {.supersampling = 3});
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = voxelizeTriangles(s, unitRegion(16), {.supersampling = 3});
    }
    EXPECT_EQ(one.flags, two.flags);
    EXPECT_EQ(one.surfaceVoxels, two.surfaceVoxels);
    for (std::size_t i = 0; i < one.faces.size(); ++i) {
        EXPECT_EQ(one.faces[i], two.faces[i]);
        EXPECT_EQ(one.emission[i], two.emission[i]);
    }
}

TEST(Voxelize, EmptyAndDegenerateInputGiveEmptyGridsOrClearErrors)
{
    scene::RenderScene empty;
    const VoxelGrid g = voxelizeTriangles(empty, unitRegion(4), {});
    EXPECT_TRUE(g.surfaceVoxels.empty());
    // A triangle with all three corners in one point, and one with NaN corners.
    scene::RenderScene degenerate;
    const auto m = addMaterial(degenerate, glm::vec3(0.5f));
    degenerate.positions = {{0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f},
                            {NAN, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}};
    degenerate.normals.assign(6, glm::vec3(0, 1, 0));
    degenerate.indices = {0, 1, 2, 3, 4, 5};
    degenerate.triangleMaterial = {m, m};
    EXPECT_TRUE(voxelizeTriangles(degenerate, unitRegion(4), {}).surfaceVoxels.empty());
    EXPECT_THROW(voxelizeTriangles(empty, {glm::dvec3(0.0), 0.0, 4}, {}), Error);
    EXPECT_THROW(voxelizeTriangles(empty, {glm::dvec3(0.0), 1.0, 0}, {}), Error);
    EXPECT_THROW(voxelizeTriangles(empty, unitRegion(4), {.supersampling = 0}), Error);
}

// listCellsMeetingTriangles: exact cases, then completeness against points sampled on random
// triangles (every cell holding a point of a triangle must be listed) and a bound on the extra
// cells (a listed cell lies within one cell of a sampled point).
scene::RenderScene oneTriangle(glm::vec3 a, glm::vec3 b, glm::vec3 c)
{
    scene::RenderScene s;
    s.positions = {a, b, c};
    s.indices = {0, 1, 2};
    s.triangleMaterial = {addMaterial(s, glm::vec3(0.5f))};
    return s;
}

TEST(SurfaceCells, AxisAlignedTrianglesMeetExactlyTheirLayer)
{
    // In the middle of layer z = 2 of a 4^3 lattice of unit cells: the 3 x 3 cells under it...
    const auto mid = listCellsMeetingTriangles(
        oneTriangle({0.5f, 0.5f, 2.5f}, {2.5f, 0.5f, 2.5f}, {0.5f, 2.5f, 2.5f}), glm::dvec3(0.0), 1.0,
        glm::ivec3(4));
    // ...that the triangle x + y <= 3 touches: (x, y) with x + y <= 3, x, y in 0..2.
    EXPECT_EQ(mid.size(), 8u); // all but (2, 2); (1, 2) and (2, 1) touch it at a corner
    for (const auto& c : mid) {
        EXPECT_EQ(c.z, 2);
        EXPECT_LE(c.x + c.y, 3);
    }
    // On the boundary between layers 1 and 2: both layers (closed cells).
    const auto onFace = listCellsMeetingTriangles(
        oneTriangle({0.5f, 0.5f, 2.0f}, {0.9f, 0.5f, 2.0f}, {0.5f, 0.9f, 2.0f}), glm::dvec3(0.0), 1.0,
        glm::ivec3(4));
    ASSERT_EQ(onFace.size(), 2u);
    EXPECT_EQ(onFace[0], glm::ivec3(0, 0, 1));
    EXPECT_EQ(onFace[1], glm::ivec3(0, 0, 2));
    // Outside the lattice: nothing; degenerate and NaN: nothing.
    EXPECT_TRUE(listCellsMeetingTriangles(oneTriangle({5, 5, 5}, {6, 5, 5}, {5, 6, 5}), glm::dvec3(0.0),
                                          1.0, glm::ivec3(4))
                    .empty());
    EXPECT_TRUE(listCellsMeetingTriangles(oneTriangle({1, 1, 1}, {2, 2, 2}, {3, 3, 3}), glm::dvec3(0.0),
                                          1.0, glm::ivec3(4))
                    .empty());
    EXPECT_TRUE(listCellsMeetingTriangles(oneTriangle({1, NAN, 1}, {2, 1, 1}, {1, 2, 1}), glm::dvec3(0.0),
                                          1.0, glm::ivec3(4))
                    .empty());
    EXPECT_THROW(listCellsMeetingTriangles(scene::RenderScene{}, glm::dvec3(0.0), 0.0, glm::ivec3(4)),
                 Error);
}

TEST(SurfaceCells, RandomTrianglesListEveryCellTheyPassThrough)
{
    std::uint32_t state = 12345u;
    auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return float(state >> 8) / float(1u << 24);
    };
    for (const glm::dvec3 origin : {glm::dvec3(0.0), glm::dvec3(1e5, -2e5, 3e5)}) {
        scene::RenderScene s;
        const auto m = addMaterial(s, glm::vec3(0.5f));
        for (int t = 0; t < 40; ++t) {
            for (int k = 0; k < 3; ++k)
                s.positions.push_back(glm::vec3(origin) +
                                      glm::vec3(0.2f + 7.6f * next(), 0.2f + 7.6f * next(), 0.2f + 7.6f * next()));
            s.indices.insert(s.indices.end(), {std::uint32_t(3 * t), std::uint32_t(3 * t + 1),
                                               std::uint32_t(3 * t + 2)});
            s.triangleMaterial.push_back(m);
        }
        const double cell = 0.5;
        const auto cells = listCellsMeetingTriangles(s, origin, cell, glm::ivec3(16));
        std::set<std::tuple<int, int, int>> listed;
        for (const auto& c : cells)
            listed.insert({c.x, c.y, c.z});
        EXPECT_EQ(listed.size(), cells.size()) << "unique";
        // Completeness: points on each triangle, away from cell faces by more than float error.
        std::set<std::tuple<int, int, int>> touched;
        int missing = 0;
        for (std::size_t t = 0; t < s.indices.size() / 3; ++t) {
            const glm::dvec3 a = glm::dvec3(s.positions[3 * t]) - origin,
                             b = glm::dvec3(s.positions[3 * t + 1]) - origin,
                             c = glm::dvec3(s.positions[3 * t + 2]) - origin;
            for (int i = 0; i <= 60; ++i)
                for (int j = 0; i + j <= 60; ++j) {
                    const glm::dvec3 p = (a + (b - a) * (i / 60.0) + (c - a) * (j / 60.0)) / cell;
                    const glm::dvec3 f = p - glm::floor(p);
                    if (glm::any(glm::lessThan(glm::min(f, 1.0 - f), glm::dvec3(1e-3))))
                        continue;
                    const glm::ivec3 q(glm::floor(p));
                    touched.insert({q.x, q.y, q.z});
                    missing += listed.count({q.x, q.y, q.z}) ? 0 : 1;
                }
        }
        EXPECT_EQ(missing, 0);
        // Soundness, loosely: a listed cell that no sampled point fell into must neighbour one
        // that did (the sampling spacing is below a cell).
        int far = 0;
        for (const auto& c : cells) {
            bool near = false;
            for (int dz = -1; dz <= 1 && !near; ++dz)
                for (int dy = -1; dy <= 1 && !near; ++dy)
                    for (int dx = -1; dx <= 1 && !near; ++dx)
                        near = touched.count({c.x + dx, c.y + dy, c.z + dz}) != 0;
            far += near ? 0 : 1;
        }
        EXPECT_EQ(far, 0);
    }
}

} // namespace
