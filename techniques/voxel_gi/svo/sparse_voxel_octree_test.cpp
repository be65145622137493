// Unit tests of the sparse voxel octree's structure: lookups agree with a dense grid of the same
// leaves at every level, the node count is that of the node tiles, the anisotropic filter's
// closed forms, quadrilinear sampling, the block-wise voxelization equals one voxelization of the
// whole cube (its surface voxels, and an inner layer of its solid voxels), and bad input is
// refused.

#include "sparse_voxel_octree.h"

#include "families/voxel_gi/voxel_gi_test_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>
#include <tuple>

using namespace rtlab;
using namespace rtlab::voxelgi;
using namespace rtlab::voxelgi::testing;

namespace {

OctreeLeaf makeLeaf(glm::ivec3 c, float alpha, glm::vec3 albedo = glm::vec3(0.5f))
{
    OctreeLeaf l;
    l.coord = c;
    for (auto& f : l.faces)
        f = glm::vec4(albedo, alpha);
    return l;
}

std::tuple<int, int, int> key(glm::ivec3 c)
{
    return {c.x, c.y, c.z};
}

} // namespace

TEST(SparseVoxelOctree, LookupsAgreeWithADenseGridAtEveryLevel)
{
    const int R = 32;
    std::mt19937 rng(7);
    std::uniform_int_distribution<int> coord(0, R - 1);
    std::uniform_real_distribution<float> alpha(0.05f, 1.0f);
    std::map<std::tuple<int, int, int>, float> dense;
    std::vector<OctreeLeaf> leaves;
    while (leaves.size() < 300) {
        const glm::ivec3 c(coord(rng), coord(rng), coord(rng));
        if (dense.count(key(c)))
            continue;
        const float a = alpha(rng);
        dense[key(c)] = a;
        leaves.push_back(makeLeaf(c, a));
    }
    SparseVoxelOctree tree({.resolution = R});
    tree.build(glm::dvec3(0.0), 1.0, leaves);
    ASSERT_EQ(tree.getDepth(), 5);
    for (int level = 0; level <= 5; ++level) {
        const int n = 1 << level;
        const int shift = 5 - level;
        std::set<std::tuple<int, int, int>> occupied;
        for (const auto& [c, a] : dense)
            occupied.insert({std::get<0>(c) >> shift, std::get<1>(c) >> shift, std::get<2>(c) >> shift});
        for (int z = -1; z <= n; ++z)
            for (int y = -1; y <= n; ++y)
                for (int x = -1; x <= n; ++x) {
                    const std::int64_t node = tree.findNode(level, {x, y, z});
                    if (occupied.count(key({x, y, z}))) {
                        ASSERT_GE(node, 0) << "level " << level;
                        if (level == 5)
                            EXPECT_EQ(tree.getAlpha(std::size_t(node), 0), dense[key({x, y, z})]);
                        else
                            EXPECT_GT(tree.getAlpha(std::size_t(node), 0), 0.0f);
                    } else if (node >= 0) {
                        // Empty siblings exist in their parent's tile, with nothing in them.
                        for (int f = 0; f < kFaceCount; ++f)
                            EXPECT_EQ(tree.getAlpha(std::size_t(node), f), 0.0f);
                    }
                }
    }
}

TEST(SparseVoxelOctree, NodeTilesAreTheWholeTopology)
{
    // One leaf: one subdivided node per level above it, each with a tile of 8 children.
    SparseVoxelOctree one({.resolution = 64});
    one.build(glm::dvec3(0.0), 1.0, {makeLeaf({5, 40, 63}, 1.0f)});
    EXPECT_EQ(one.getNodeCount(), 1u + 8u * 6u);
    EXPECT_EQ(one.getTopologyBytes(), (1u + 8u * 6u) * 4u);
    // A full 8^3 grid: every node subdivided, 1 + 8 + 64 + 512 nodes.
    std::vector<OctreeLeaf> full;
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x)
                full.push_back(makeLeaf({x, y, z}, 1.0f));
    SparseVoxelOctree grid({.resolution = 8});
    grid.build(glm::dvec3(0.0), 1.0, full);
    EXPECT_EQ(grid.getNodeCount(), 1u + 8u + 64u + 512u);
    for (int f = 0; f < kFaceCount; ++f)
        EXPECT_EQ(grid.getAlpha(0, f), 1.0f) << "a full grid is opaque from every side";
    // No leaves: the root alone, empty.
    SparseVoxelOctree empty({.resolution = 8});
    empty.build(glm::dvec3(0.0), 1.0, {});
    EXPECT_EQ(empty.getNodeCount(), 1u);
    EXPECT_EQ(empty.findNode(3, {1, 1, 1}), -1);
}

TEST(SparseVoxelOctree, AnisotropicFilterCompositesEachColumnFrontToBack)
{
    // Two leaves in one column along x under the same parent: occupancy a at x = 1 (the +x
    // child) and b at x = 0. Seen from +x the column is a over b: a + (1 - a) b; the same from
    // -x; the other three columns are empty, so the parent's x faces hold a quarter of that.
    // Seen from +y (or z) every column is one child deep: (a + b) / 4.
    const float a = 0.6f, b = 0.3f;
    SparseVoxelOctree tree({.resolution = 2});
    tree.build(glm::dvec3(0.0), 1.0, {makeLeaf({1, 0, 0}, a), makeLeaf({0, 0, 0}, b)});
    const float column = a + (1.0f - a) * b;
    EXPECT_FLOAT_EQ(tree.getAlpha(0, 0), 0.25f * column);
    EXPECT_FLOAT_EQ(tree.getAlpha(0, 1), 0.25f * (b + (1.0f - b) * a));
    for (int f = 2; f < kFaceCount; ++f)
        EXPECT_FLOAT_EQ(tree.getAlpha(0, f), 0.25f * (a + b));
}

TEST(SparseVoxelOctree, SamplesAreQuadrilinear)
{
    // A full 8^3 block of opaque leaves in a 16^3 cube (side 16, leaves of 1): at a leaf centre
    // inside the block with a footprint below a leaf, the sample is the leaf itself; at a point
    // on the block's face it is half; with a footprint of 2 leaves it is the level above.
    std::vector<OctreeLeaf> leaves;
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x)
                leaves.push_back(makeLeaf({x, y, z}, 1.0f));
    SparseVoxelOctree tree({.resolution = 16});
    tree.build(glm::dvec3(0.0), 16.0, leaves);
    const glm::dvec3 dir(1.0, 0.0, 0.0);
    ConeSample s;
    ASSERT_TRUE(tree.sampleGathered({3.5, 3.5, 3.5}, 0.5, dir, s));
    EXPECT_FLOAT_EQ(s.alpha, 1.0f);
    EXPECT_DOUBLE_EQ(s.voxelSize, 1.0);
    ASSERT_TRUE(tree.sampleGathered({8.0, 3.5, 3.5}, 0.5, dir, s));
    EXPECT_FLOAT_EQ(s.alpha, 0.5f); // between the last leaf of the block and an empty one
    // Footprint 2: level 3 (voxels of 2): at (9, 4, 4) the voxel centres at x = 7 (full) and
    // 9 (empty) are 1 apart from it: weights 0 and 1 -> 0; at (8, 4, 4): 0.5.
    ASSERT_TRUE(tree.sampleGathered({8.0, 4.0, 4.0}, 2.0, dir, s));
    EXPECT_FLOAT_EQ(s.alpha, 0.5f);
    EXPECT_DOUBLE_EQ(s.voxelSize, 2.0);
    // Footprint sqrt(2) * 1: halfway between the leaves and level 3.
    ASSERT_TRUE(tree.sampleGathered({3.5, 3.5, 3.5}, std::sqrt(2.0), dir, s));
    EXPECT_NEAR(s.alpha, 1.0f, 1e-6f);
    EXPECT_NEAR(s.voxelSize, std::sqrt(2.0), 1e-12);
    // Outside the cube: no sample (the cone escapes).
    EXPECT_FALSE(tree.sampleGathered({-0.1, 3.0, 3.0}, 0.5, dir, s));
    EXPECT_FALSE(tree.sampleGathered({3.0, 16.1, 3.0}, 0.5, dir, s));
}

TEST(SparseVoxelOctree, BlockwiseVoxelizationEqualsOneVoxelizationOfTheCube)
{
    // Blocks of 8 leaves in a 32^3 cube against the dense voxelization of the whole cube, two
    // boxes across several blocks. The cube is placed so that no face lies on a voxel boundary:
    // there a hit belongs to one voxel or the next by the rounding of the ray's position, which
    // is computed from the block's origin in one case and the cube's in the other.
    scene::RenderScene s;
    const auto m = addMaterial(s, glm::vec3(0.2f, 0.5f, 0.8f), glm::vec3(0.1f));
    addBox(s, glm::vec3(-0.5f), glm::vec3(0.5f), m);
    addBox(s, glm::vec3(-0.9f, -0.8f, -0.3f), glm::vec3(-0.2f, 0.9f, 0.95f), addMaterial(s, glm::vec3(0.7f)));
    const glm::dvec3 origin(-1.013, -1.021, -1.007);
    const double side = 2.1;
    OctreeSettings settings{.resolution = 32, .supersampling = 3, .chunk = 8};
    const std::vector<OctreeLeaf> leaves = SparseVoxelOctree::voxelizeLeaves(s, origin, side, settings);
    VoxelRegion region;
    region.origin = origin;
    region.voxelSize = side / 32.0;
    region.resolution = 32;
    const VoxelGrid dense = voxelizeTriangles(s, region, {.supersampling = 3, .solid = false});
    const VoxelGrid filled = voxelizeTriangles(s, region, {.supersampling = 3, .solid = true});
    std::map<std::tuple<int, int, int>, const OctreeLeaf*> byCoord;
    std::size_t surfaceLeaves = 0, innerLeaves = 0;
    for (const auto& l : leaves) {
        ASSERT_EQ(byCoord.count(key(l.coord)), 0u) << "one leaf per voxel";
        byCoord[key(l.coord)] = &l;
        if (l.inwardOf < 0) {
            ++surfaceLeaves;
            continue;
        }
        // The inner layer: solid in the whole cube's voxelization, beside the surface leaf it
        // mirrors.
        ++innerLeaves;
        const std::size_t v = region.index(l.coord.x, l.coord.y, l.coord.z);
        EXPECT_TRUE(filled.flags[v] & kVoxelSolid);
        const glm::ivec3 d = glm::abs(leaves[std::size_t(l.inwardOf)].coord - l.coord);
        EXPECT_EQ(d.x + d.y + d.z, 1);
    }
    EXPECT_EQ(surfaceLeaves, dense.surfaceVoxels.size());
    EXPECT_GT(innerLeaves, 1000u); // both boxes are closed: a layer inside each
    for (const std::uint32_t v : dense.surfaceVoxels) {
        const glm::ivec3 c(int(v % 32u), int((v / 32u) % 32u), int(v / 1024u));
        const auto it = byCoord.find(key(c));
        ASSERT_NE(it, byCoord.end()) << c.x << " " << c.y << " " << c.z;
        ASSERT_LT(it->second->inwardOf, 0);
        for (int f = 0; f < kFaceCount; ++f) {
            EXPECT_EQ(it->second->faces[std::size_t(f)], dense.face(v, f));
            EXPECT_EQ(it->second->emission[std::size_t(f)], dense.emission[std::size_t(v) * 6 + std::size_t(f)]);
        }
        EXPECT_EQ(it->second->normal, dense.normal[v]);
    }
}

TEST(SparseVoxelOctree, FarFromTheOriginTheSamplesAreUnchanged)
{
    // The same leaves in a cube at the origin and at 1e6: the same samples at the same relative
    // points (up to the double rounding of the positions).
    std::vector<OctreeLeaf> leaves;
    for (int x = 0; x < 16; ++x)
        for (int z = 0; z < 16; ++z)
            leaves.push_back(makeLeaf({x, 3, z}, 0.8f));
    const glm::dvec3 far(1e6, -1e6, 1e6);
    SparseVoxelOctree a({.resolution = 16}), b({.resolution = 16});
    a.build(glm::dvec3(0.0), 2.0, leaves);
    b.build(far, 2.0, leaves);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 2.0);
    for (int i = 0; i < 200; ++i) {
        const glm::dvec3 p(u(rng), u(rng), u(rng));
        const double d = 0.1 * u(rng);
        ConeSample sa, sb;
        ASSERT_TRUE(a.sampleGathered(p, d, {0.0, 1.0, 0.0}, sa));
        ASSERT_TRUE(b.sampleGathered(far + p, d, {0.0, 1.0, 0.0}, sb));
        EXPECT_NEAR(sa.alpha, sb.alpha, 1e-6f);
        EXPECT_TRUE(std::isfinite(sb.alpha));
    }
}

TEST(SparseVoxelOctree, RefusesBadInput)
{
    EXPECT_THROW(SparseVoxelOctree({.resolution = 48}), Error);
    EXPECT_THROW(SparseVoxelOctree({.resolution = 8192}), Error);
    EXPECT_THROW(SparseVoxelOctree({.resolution = 8, .bounces = 4}), Error);
    SparseVoxelOctree tree({.resolution = 8});
    EXPECT_THROW(tree.build(glm::dvec3(0.0), 1.0, {makeLeaf({8, 0, 0}, 1.0f)}), Error);
    EXPECT_THROW(tree.build(glm::dvec3(0.0), 1.0, {makeLeaf({-1, 0, 0}, 1.0f)}), Error);
    EXPECT_THROW(tree.build(glm::dvec3(0.0), 1.0, {makeLeaf({1, 2, 3}, 1.0f), makeLeaf({1, 2, 3}, 0.5f)}),
                 Error);
    EXPECT_THROW(tree.build(glm::dvec3(0.0), 0.0, {}), Error);
    EXPECT_THROW(tree.build(glm::dvec3(std::nan("")), 1.0, {}), Error);
    // A degenerate scene (one point) still gives a finite cube.
    glm::dvec3 origin;
    double side = 0.0;
    SparseVoxelOctree::computeCube(glm::dvec3(2.0), glm::dvec3(2.0), 8, origin, side);
    EXPECT_GT(side, 0.0);
    EXPECT_TRUE(std::isfinite(origin.x));
}

TEST(SparseVoxelOctree, CornerBricksHoldThePerNodeFieldAtTheNodeCornersAndAreContinuous)
{
    // Random leaves of random occupancy in a 16^3 cube. (a) A brick's corner value is the
    // per-node field sampled trilinearly at that corner, at every level: at the min corner of an
    // existing node the brick sample equals the per-node sample. (b) Across a face shared by two
    // existing nodes the brick samples on either side agree (shared borders). (c) In an absent
    // node the brick sample is empty.
    std::mt19937 rng(11);
    std::set<std::tuple<int, int, int>> seen;
    std::vector<OctreeLeaf> leaves;
    for (int i = 0; i < 600; ++i) {
        const glm::ivec3 c(int(rng() % 16u), int(rng() % 8u), int(rng() % 16u));
        if (seen.insert(key(c)).second)
            leaves.push_back(makeLeaf(c, 0.1f + 0.9f * float(rng() % 1000u) / 1000.0f));
    }
    SparseVoxelOctree plain({.resolution = 16});
    SparseVoxelOctree bricked({.resolution = 16, .cornerBricks = true});
    plain.build(glm::dvec3(0.0), 16.0, leaves);
    bricked.build(glm::dvec3(0.0), 16.0, leaves);
    ASSERT_EQ(bricked.getGatheredBricks().size(), bricked.getGathered().size() * 8);
    EXPECT_TRUE(plain.getGatheredBricks().empty());
    EXPECT_EQ(bricked.getPayloadBytes() - plain.getPayloadBytes(),
              bricked.getGatheredBricks().size() * sizeof(glm::vec4) +
                  bricked.getNodeCount() * sizeof(glm::ivec4));
    const glm::dvec3 dir = glm::normalize(glm::dvec3(0.3, -0.5, 0.8));
    int corners = 0, faces = 0, empty = 0;
    for (int level = 1; level <= 4; ++level) {
        const double size = 16.0 / double(1 << level);
        const double footprint = size; // exactly this level (m = 4 - level, no blend)
        const int n = 1 << level;
        for (int z = 0; z < n; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const glm::ivec3 c(x, y, z);
                    const bool exists = bricked.findNode(level, c) >= 0;
                    ConeSample a, b;
                    if (exists) {
                        // (a) the min corner, nudged inside the node
                        const glm::dvec3 p = glm::dvec3(c) * size + 1e-9;
                        ASSERT_TRUE(bricked.sampleGathered(p, footprint, dir, a));
                        ASSERT_TRUE(plain.sampleGathered(p, footprint, dir, b));
                        // float sums of 8 terms against 8 others: 1e-5 absolute on values <= 1
                        EXPECT_NEAR(a.alpha, b.alpha, 1e-5f) << "level " << level;
                        ++corners;
                        // (b) the +x face, if the neighbour exists
                        if (x + 1 < n && bricked.findNode(level, c + glm::ivec3(1, 0, 0)) >= 0) {
                            const glm::dvec3 q =
                                (glm::dvec3(c) + glm::dvec3(1.0, 0.37, 0.61)) * size;
                            ConeSample left, right;
                            ASSERT_TRUE(bricked.sampleGathered(q - glm::dvec3(1e-7, 0, 0),
                                                               footprint, dir, left));
                            ASSERT_TRUE(bricked.sampleGathered(q + glm::dvec3(1e-7, 0, 0),
                                                               footprint, dir, right));
                            EXPECT_NEAR(left.alpha, right.alpha, 1e-5f) << "level " << level;
                            ++faces;
                        }
                    } else {
                        // (c) the centre of an absent node
                        const glm::dvec3 p = (glm::dvec3(c) + 0.5) * size;
                        ASSERT_TRUE(bricked.sampleGathered(p, footprint, dir, a));
                        EXPECT_EQ(a.alpha, 0.0f);
                        ++empty;
                    }
                }
    }
    EXPECT_GT(corners, 300);
    EXPECT_GT(faces, 100);
    EXPECT_GT(empty, 100);
}
