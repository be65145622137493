// Unit tests of the adaptive voxel tree as a cone-tracing structure: the filtered occupancy of
// every element equals a dense recomputation of the same filter at every level (the popcount
// indexing and the 4x4x4 front-to-back filter together), samples are trilinear at a level and
// linear between levels 4x apart, the lattice fits the box, and bad or degenerate input.

#include "voxel_tree_cones.h"

#include "core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <tuple>

using namespace rtlab;
using namespace rtlab::voxelgi;

namespace {

SurfaceLeaf makeLeaf(glm::ivec3 c, float alpha)
{
    SurfaceLeaf l;
    l.coord = c;
    for (auto& f : l.faces)
        f = glm::vec4(0.5f, 0.5f, 0.5f, alpha);
    return l;
}

// Dense occupancy of one level: [cell * 6 + face].
struct DenseLevel {
    glm::ivec3 cells{0};
    std::vector<float> alpha;
    float at(const glm::ivec3& c, int f) const
    {
        if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, cells)))
            return 0.0f;
        return alpha[(std::size_t(c.x) + std::size_t(cells.x) * (std::size_t(c.y) + std::size_t(cells.y) * std::size_t(c.z))) * 6 + std::size_t(f)];
    }
};

// The same filter on dense grids: per parent face, 16 columns of 4 children composited front to
// back (the -axis face's viewer looks along +axis: low children first), averaged.
DenseLevel filterDense(const DenseLevel& fine)
{
    DenseLevel coarse;
    coarse.cells = fine.cells / 4;
    coarse.alpha.assign(std::size_t(coarse.cells.x) * std::size_t(coarse.cells.y) * std::size_t(coarse.cells.z) * 6, 0.0f);
    for (int z = 0; z < coarse.cells.z; ++z)
        for (int y = 0; y < coarse.cells.y; ++y)
            for (int x = 0; x < coarse.cells.x; ++x)
                for (int f = 0; f < 6; ++f) {
                    const int axis = f / 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
                    double sum = 0.0;
                    for (int j = 0; j < 4; ++j)
                        for (int i = 0; i < 4; ++i) {
                            double transmit = 1.0, column = 0.0;
                            for (int s = 0; s < 4; ++s) {
                                glm::ivec3 c(0);
                                c[axis] = (f % 2 == 1) ? s : 3 - s;
                                c[u] = i;
                                c[v] = j;
                                const double a = fine.at(glm::ivec3(x, y, z) * 4 + c, f);
                                column += transmit * a;
                                transmit *= 1.0 - a;
                            }
                            sum += column;
                        }
                    coarse.alpha[(std::size_t(x) + std::size_t(coarse.cells.x) * (std::size_t(y) + std::size_t(coarse.cells.y) * std::size_t(z))) * 6 + std::size_t(f)] =
                        float(sum / 16.0);
                }
    return coarse;
}

} // namespace

TEST(VoxelTreeCones, FilteredOccupancyEqualsADenseFilterAtEveryLevel)
{
    const glm::ivec3 roots(2, 1, 3);
    const int depth = 2;
    const glm::ivec3 cells = roots * 16;
    std::mt19937 rng(11);
    std::uniform_int_distribution<int> cx(0, cells.x - 1), cy(0, cells.y - 1), cz(0, cells.z - 1);
    std::uniform_real_distribution<float> alpha(0.05f, 1.0f);
    std::set<std::tuple<int, int, int>> used;
    std::vector<SurfaceLeaf> leaves;
    DenseLevel dense;
    dense.cells = cells;
    dense.alpha.assign(std::size_t(cells.x) * std::size_t(cells.y) * std::size_t(cells.z) * 6, 0.0f);
    // Random leaves, and a full 4x4x4 block (every mask bit of its parent set).
    auto add = [&](glm::ivec3 c, float a) {
        if (!used.insert({c.x, c.y, c.z}).second)
            return;
        leaves.push_back(makeLeaf(c, a));
        for (int f = 0; f < 6; ++f)
            dense.alpha[(std::size_t(c.x) + std::size_t(cells.x) * (std::size_t(c.y) + std::size_t(cells.y) * std::size_t(c.z))) * 6 + std::size_t(f)] = a;
    };
    for (int z = 4; z < 8; ++z)
        for (int y = 8; y < 12; ++y)
            for (int x = 20; x < 24; ++x)
                add({x, y, z}, 0.7f);
    while (leaves.size() < 600)
        add({cx(rng), cy(rng), cz(rng)}, alpha(rng));
    VoxelTreeCones tree({.depth = depth});
    tree.build(glm::dvec3(0.0), 1.0, roots, leaves);
    const AdaptiveVoxelTree& t = *tree.getTree();
    EXPECT_EQ(t.getLeafCount(), leaves.size());
    std::vector<DenseLevel> levels(depth + 1);
    levels[depth] = dense;
    for (int l = depth - 1; l >= 0; --l)
        levels[std::size_t(l)] = filterDense(levels[std::size_t(l + 1)]);
    int present = 0;
    for (int l = 0; l <= depth; ++l) {
        const glm::ivec3 n = roots * (1 << (2 * l));
        for (int z = 0; z < n.z; ++z)
            for (int y = 0; y < n.y; ++y)
                for (int x = 0; x < n.x; ++x) {
                    const std::int64_t e = t.find(l, {x, y, z});
                    for (int f = 0; f < 6; ++f) {
                        const float expected = levels[std::size_t(l)].at({x, y, z}, f);
                        if (e < 0) {
                            ASSERT_EQ(expected, 0.0f) << "absent element with occupancy, level " << l;
                            continue;
                        }
                        ++present;
                        // float accumulation of <= 64 terms against double: 1e-5 absolute
                        ASSERT_NEAR(tree.getAlpha(std::size_t(e), f), expected, 1e-5)
                            << "level " << l << " cell " << x << "," << y << "," << z << " face " << f;
                    }
                }
    }
    EXPECT_GT(present, 600 * 6);
    // The full block's parent is opaque from every side (each column holds 4 leaves of 0.7).
    const std::int64_t parent = t.find(depth - 1, {5, 2, 1});
    ASSERT_GE(parent, 0);
    ASSERT_TRUE(t.getNode(std::uint32_t(parent)).has_value());
    EXPECT_EQ(t.getNode(std::uint32_t(parent))->getMask(), ~std::uint64_t(0));
    EXPECT_NEAR(tree.getAlpha(std::size_t(parent), 0), 1.0 - std::pow(0.3, 4), 1e-6);
}

TEST(VoxelTreeCones, SamplesAreTrilinearAtALevelAndLinearBetweenLevels)
{
    // A wall of opaque leaves at x = 7 across a 16^3 lattice (one root cell, depth 2).
    std::vector<SurfaceLeaf> leaves;
    for (int z = 0; z < 16; ++z)
        for (int y = 0; y < 16; ++y)
            leaves.push_back(makeLeaf({7, y, z}, 1.0f));
    VoxelTreeCones tree({.depth = 2});
    tree.build(glm::dvec3(0.0), 1.0, glm::ivec3(1), leaves);
    const glm::dvec3 alongX(1.0, 0.0, 0.0);
    ConeSample s;
    // Leaf level (footprint <= a leaf): linear across the wall's centre at x = 7.5.
    for (const double x : {6.5, 7.0, 7.5, 8.0, 8.5, 9.0}) {
        ASSERT_TRUE(tree.sampleGathered({x, 8.0, 8.0}, 0.5, alongX, s));
        EXPECT_NEAR(s.alpha, std::max(0.0, 1.0 - std::abs(x - 7.5)), 1e-6) << x;
        EXPECT_DOUBLE_EQ(s.voxelSize, 1.0);
    }
    // Footprint 4: the level of 4-leaf cells; the wall's cell (4..8) has one opaque leaf in each
    // column along x, so alpha 1 at its centre x = 6; the next cell's centre x = 10 is empty.
    ASSERT_TRUE(tree.sampleGathered({6.0, 8.0, 8.0}, 4.0, alongX, s));
    EXPECT_NEAR(s.alpha, 1.0, 1e-6);
    EXPECT_DOUBLE_EQ(s.voxelSize, 4.0);
    ASSERT_TRUE(tree.sampleGathered({8.0, 8.0, 8.0}, 4.0, alongX, s));
    EXPECT_NEAR(s.alpha, 0.5, 1e-6);
    // Seen along y, that cell's columns along y: 4 of 16 hold the wall: alpha 0.25.
    ASSERT_TRUE(tree.sampleGathered({6.0, 6.0, 6.0}, 4.0, glm::dvec3(0.0, 1.0, 0.0), s));
    EXPECT_NEAR(s.alpha, 0.25, 1e-6);
    // Footprint 2 = halfway (in log4) between the leaves and the 4-leaf cells: the mean.
    ConeSample fine, coarse;
    ASSERT_TRUE(tree.sampleGathered({7.2, 8.0, 8.0}, 1.0, alongX, fine));
    ASSERT_TRUE(tree.sampleGathered({7.2, 8.0, 8.0}, 4.0, alongX, coarse));
    ASSERT_TRUE(tree.sampleGathered({7.2, 8.0, 8.0}, 2.0, alongX, s));
    EXPECT_NEAR(s.alpha, 0.5 * (fine.alpha + coarse.alpha), 1e-6);
    EXPECT_NEAR(s.voxelSize, 2.0, 1e-12);
    // Outside the lattice: no sample (the cone has left the structure).
    EXPECT_FALSE(tree.sampleGathered({-0.1, 8.0, 8.0}, 1.0, alongX, s));
    EXPECT_FALSE(tree.sampleGathered({8.0, 16.01, 8.0}, 1.0, alongX, s));
    // Footprints wider than a root cell read the root cells.
    ASSERT_TRUE(tree.sampleGathered({8.0, 8.0, 8.0}, 1e6, alongX, s));
    EXPECT_NEAR(s.voxelSize, 16.0, 1e-12);
    EXPECT_TRUE(std::isfinite(s.alpha));
}

TEST(VoxelTreeCones, LatticeFitsTheBoxWithALeafOfPadding)
{
    glm::dvec3 origin;
    double leaf = 0.0;
    glm::ivec3 roots;
    VoxelTreeCones::computeLattice({0, 0, 0}, {6.2, 1.0, 3.1}, 64, 3, 0.0, origin, leaf, roots);
    EXPECT_NEAR(leaf, 6.2 / 62.0, 1e-12);
    EXPECT_EQ(roots, glm::ivec3(1, 1, 1));
    for (int a = 0; a < 3; ++a) {
        EXPECT_LE(origin[a], -leaf + 1e-12);
        EXPECT_GE(origin[a] + roots[a] * 64 * leaf, glm::dvec3(6.2, 1.0, 3.1)[a] + leaf - 1e-12);
    }
    // An extreme aspect ratio: many root cells along the long axis, one across.
    VoxelTreeCones::computeLattice({0, 0, 0}, {1000.0, 1.0, 1.0}, 4096, 2, 0.0, origin, leaf, roots);
    EXPECT_EQ(roots.y, 1);
    EXPECT_EQ(roots.z, 1);
    EXPECT_GE(roots.x * 16, 4096);
    // A point: a finite, tiny lattice.
    VoxelTreeCones::computeLattice({2, 2, 2}, {2, 2, 2}, 8, 1, 0.0, origin, leaf, roots);
    EXPECT_GT(leaf, 0.0);
    EXPECT_TRUE(std::isfinite(origin.x));
    // A fixed leaf size: a cube of resolution leaves centred on the box.
    VoxelTreeCones::computeLattice({1e5, 0, 0}, {1e5 + 2.0, 2.0, 2.0}, 64, 3, 0.05, origin, leaf, roots);
    EXPECT_EQ(leaf, 0.05);
    EXPECT_EQ(roots, glm::ivec3(1));
    EXPECT_NEAR(origin.x, 1e5 + 1.0 - 1.6, 1e-9);
    EXPECT_THROW(VoxelTreeCones::computeLattice({0, 0, 0}, {INFINITY, 1, 1}, 64, 3, 0.0, origin, leaf, roots), Error);
}

TEST(VoxelTreeCones, OneLeafEmptyTreeAndLeavesOnTheFaces)
{
    VoxelTreeCones empty({.depth = 2});
    empty.build(glm::dvec3(0.0), 1.0, glm::ivec3(1), {});
    ConeSample s;
    ASSERT_TRUE(empty.sampleGathered({8, 8, 8}, 3.0, {0, 0, 1}, s));
    EXPECT_EQ(s.alpha, 0.0f);
    // One leaf in each corner of the lattice (on the box's faces): seen at the leaf level, and
    // filtered up: a level-1 cell holding one opaque leaf is 1/16 opaque from any side; at the
    // root, 4 of its 16 columns along x hold two such cells: (1/16)(1 + 15/16) each.
    std::vector<SurfaceLeaf> corners;
    for (int i = 0; i < 8; ++i)
        corners.push_back(makeLeaf({(i & 1) ? 15 : 0, (i & 2) ? 15 : 0, (i & 4) ? 15 : 0}, 1.0f));
    VoxelTreeCones tree({.depth = 2});
    tree.build(glm::dvec3(-8.0), 1.0, glm::ivec3(1), corners);
    for (const SurfaceLeaf& l : corners) {
        ASSERT_TRUE(tree.sampleGathered(glm::dvec3(-8.0) + glm::dvec3(l.coord) + 0.5, 0.5, {1, 0, 0}, s));
        EXPECT_NEAR(s.alpha, 1.0, 1e-6);
    }
    EXPECT_NEAR(tree.getAlpha(0, 0), 4.0 * (1.0 / 16.0) * (1.0 + 15.0 / 16.0) / 16.0, 1e-7);
    // Duplicates and leaves outside the lattice are refused.
    VoxelTreeCones bad({.depth = 1});
    EXPECT_THROW(bad.build(glm::dvec3(0.0), 1.0, glm::ivec3(1), {makeLeaf({1, 1, 1}, 1.0f), makeLeaf({1, 1, 1}, 0.5f)}),
                 Error);
    EXPECT_THROW(bad.build(glm::dvec3(0.0), 1.0, glm::ivec3(1), {makeLeaf({4, 0, 0}, 1.0f)}), Error);
    EXPECT_THROW(bad.build(glm::dvec3(0.0), 0.0, glm::ivec3(1), {}), Error);
    EXPECT_THROW(VoxelTreeCones({.depth = 7}), Error);
    EXPECT_THROW(VoxelTreeCones({.bounces = 4}), Error);
}
