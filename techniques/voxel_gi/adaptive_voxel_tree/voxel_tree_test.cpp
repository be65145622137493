// Unit tests of the 64-ary adaptive voxel tree (voxel_tree.h): lookups agree exactly with dense
// grids holding the same elements and payload (randomised, every level, with and without
// dilation); the edge cases (one voxel, a full grid, voxels on the box faces, queries outside,
// extreme aspect ratios); the partial dilation keeps every interpolation within two levels; and
// seamless interpolation reproduces a linear field across level transitions where the plain
// per-level interpolation does not.

#include "voxel_tree.h"

#include "core/error.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <tuple>

using namespace rtlab;
using namespace rtlab::voxelgi;

namespace {

using Cell = std::tuple<int, int, int>;
Cell key(const glm::ivec3& c) { return {c.z, c.y, c.x}; }

// The element sets the tree must hold, computed the direct way: leaves as given, each upper level
// the parents of the level below, grown by one cell in every direction when dilated; level 0 all.
std::vector<std::set<Cell>> expectedLevels(const VoxelTreeLayout& layout,
                                           const std::vector<glm::ivec3>& leaves, bool dilate)
{
    std::vector<std::set<Cell>> levels(std::size_t(layout.depth) + 1);
    for (const auto& c : leaves)
        levels[std::size_t(layout.depth)].insert(key(c));
    for (int l = layout.depth - 1; l >= 0; --l) {
        const glm::ivec3 cells = layout.getCells(l);
        for (const auto& [z, y, x] : levels[std::size_t(l) + 1]) {
            const glm::ivec3 parent = glm::ivec3(x, y, z) / 4;
            const int r = dilate ? 1 : 0;
            for (int dz = -r; dz <= r; ++dz)
                for (int dy = -r; dy <= r; ++dy)
                    for (int dx = -r; dx <= r; ++dx) {
                        const glm::ivec3 n = parent + glm::ivec3(dx, dy, dz);
                        if (glm::all(glm::greaterThanEqual(n, glm::ivec3(0))) &&
                            glm::all(glm::lessThan(n, cells)))
                            levels[std::size_t(l)].insert(key(n));
                    }
        }
    }
    const glm::ivec3 roots = layout.rootCells;
    for (int z = 0; z < roots.z; ++z)
        for (int y = 0; y < roots.y; ++y)
            for (int x = 0; x < roots.x; ++x)
                levels[0].insert(key({x, y, z}));
    return levels;
}

// A payload value that names its element (level, cell) uniquely.
double payloadOf(int level, const glm::ivec3& c)
{
    return double(level) * 1e9 + double(c.z) * 1e6 + double(c.y) * 1e3 + double(c.x);
}

void expectMatchesDenseGrids(const VoxelTreeLayout& layout, const std::vector<glm::ivec3>& leaves,
                             const VoxelTreeBuildOptions& options, const std::string& what)
{
    const AdaptiveVoxelTree tree = AdaptiveVoxelTree::build(layout, leaves, options);
    const auto expected = expectedLevels(layout, leaves, options.dilate);
    // Payload array filled from the tree's own element list, as a structure's user does.
    const std::vector<glm::ivec4> cells = tree.listElementCells();
    ASSERT_EQ(cells.size(), tree.getElementCount()) << what;
    std::vector<double> payload(cells.size());
    for (std::size_t i = 0; i < cells.size(); ++i)
        payload[i] = payloadOf(cells[i].w, glm::ivec3(cells[i]));
    std::size_t total = 0;
    for (int l = 0; l <= layout.depth; ++l) {
        // The dense grid of level l holds the payload where an element is expected.
        const glm::ivec3 n = layout.getCells(l);
        std::size_t present = 0, wrong = 0;
        for (int z = 0; z < n.z; ++z)
            for (int y = 0; y < n.y; ++y)
                for (int x = 0; x < n.x; ++x) {
                    const glm::ivec3 c(x, y, z);
                    const bool want = expected[std::size_t(l)].count(key(c)) != 0;
                    const std::int64_t index = tree.find(l, c);
                    if (want != (index != AdaptiveVoxelTree::kAbsent) ||
                        (want && payload[std::size_t(index)] != payloadOf(l, c)))
                        ++wrong;
                    present += want ? 1 : 0;
                }
        EXPECT_EQ(wrong, 0u) << what << ", level " << l;
        EXPECT_EQ(tree.getLevelBegin(l + 1) - tree.getLevelBegin(l), present) << what << ", level " << l;
        total += present;
    }
    EXPECT_EQ(total, tree.getElementCount()) << what;
    EXPECT_EQ(tree.getLeafCount(), expected.back().size()) << what;

    // Node records exactly for the root cells and the elements with an expected child, each
    // holding its children's bits; the topology is those records and one rank word per 64
    // upper-level elements.
    std::size_t inner = 0, wrongRecords = 0;
    std::set<std::uint64_t> distinctMasks;
    struct Record {
        int level;
        std::uint64_t mask;
        glm::ivec3 cell;
    };
    std::vector<Record> childMasks;
    for (std::size_t e = 0; e < tree.getElementCount(); ++e) {
        const int l = cells[e].w;
        std::uint64_t want = 0;
        if (l < layout.depth)
            for (int bit = 0; bit < 64; ++bit) {
                const glm::ivec3 child =
                    glm::ivec3(cells[e]) * 4 + glm::ivec3(bit & 3, (bit >> 2) & 3, bit >> 4);
                if (expected[std::size_t(l) + 1].count(key(child)) != 0)
                    want |= std::uint64_t(1) << bit;
            }
        const std::optional<VoxelTreeNode> node = tree.getNode(std::uint32_t(e));
        const bool record = want != 0 || l == 0; // every root cell has one
        inner += record ? 1 : 0;
        if (record) {
            distinctMasks.insert(want);
            childMasks.push_back({l, want, glm::ivec3(cells[e])});
        }
        if (node.has_value() != record || (node && node->getMask() != want))
            ++wrongRecords;
    }
    EXPECT_EQ(wrongRecords, 0u) << what;
    EXPECT_EQ(tree.getNodeCount(), inner) << what;
    // Inline: 12 bytes per record. Shared: a field of 12 bits + the bits of a table index per
    // record, packed in 32-bit words (two more of padding), a 4-byte base per 64 records, 8 bytes
    // per distinct mask.
    const std::size_t ranks = 12 * ((tree.getLevelBegin(layout.depth) + 63) / 64);
    // A dilated tree's shared masks also hold, for each record above level depth - 1, the mask
    // of its children that have a record.
    std::size_t upper = 0;
    if (options.masks == NodeMasks::Shared && inner < tree.getLevelBegin(layout.depth))
        for (const Record& r : childMasks) {
            if (r.level >= layout.depth - 1)
                continue;
            ++upper;
            std::uint64_t real = 0;
            for (int bit = 0; bit < 64; ++bit) {
                const glm::ivec3 child = r.cell * 4 + glm::ivec3(bit & 3, (bit >> 2) & 3, bit >> 4);
                for (const Record& c : childMasks)
                    if (c.level == r.level + 1 && c.cell == child)
                        real |= std::uint64_t(1) << bit;
            }
            distinctMasks.insert(real);
        }
    const bool shared = options.masks == NodeMasks::Shared && distinctMasks.size() <= options.maxSharedMasks;
    EXPECT_EQ(tree.getNodeMasks(), shared ? NodeMasks::Shared : NodeMasks::Inline) << what;
    std::size_t indexBits = 1;
    while ((std::size_t(1) << indexBits) < distinctMasks.size())
        ++indexBits;
    const std::size_t fieldWords = (inner * (12 + indexBits) + 31) / 32 + 2;
    const std::size_t upperWords =
        upper == 0 ? 0 : (upper * (12 + indexBits) + 31) / 32 + 2 + (upper + 63) / 64;
    EXPECT_EQ(tree.getTopologyBytes(), shared
                                           ? 4 * fieldWords + 4 * ((inner + 63) / 64) +
                                                 4 * upperWords + 8 * distinctMasks.size() + ranks
                                           : 12 * inner + ranks)
        << what;
    if (shared) {
        EXPECT_EQ(tree.getRecordWidth(), 12 + indexBits) << what;
    }
}

void expectMatchesDenseGrids(const VoxelTreeLayout& layout, const std::vector<glm::ivec3>& leaves,
                             bool dilate, const std::string& what)
{
    for (const NodeMasks masks : {NodeMasks::Shared, NodeMasks::Inline})
        expectMatchesDenseGrids(layout, leaves, {.dilate = dilate, .masks = masks},
                                what + (masks == NodeMasks::Shared ? ", shared masks" : ", inline masks"));
}

TEST(VoxelTree, RandomisedLookupsAgreeWithDenseGridsAtEveryLevel)
{
    std::mt19937 rng(7);
    for (int trial = 0; trial < 24; ++trial) {
        VoxelTreeLayout layout;
        layout.depth = 1 + trial % 3;
        layout.rootCells = glm::ivec3(1 + int(rng() % 3), 1 + int(rng() % 2), 1 + int(rng() % 3));
        const glm::ivec3 n = layout.getCells(layout.depth);
        std::vector<glm::ivec3> leaves;
        // Clusters (surfaces) and scattered voxels, with duplicates.
        const int count = 1 + int(rng() % 300);
        for (int i = 0; i < count; ++i) {
            glm::ivec3 c(int(rng() % unsigned(n.x)), int(rng() % unsigned(n.y)), int(rng() % unsigned(n.z)));
            leaves.push_back(c);
            if (i % 3 == 0)
                leaves.push_back(glm::min(c + 1, n - 1));
        }
        for (bool dilate : {true, false})
            expectMatchesDenseGrids(layout, leaves, dilate,
                                    "trial " + std::to_string(trial) + (dilate ? " dilated" : ""));
    }
}

TEST(VoxelTree, OneVoxel)
{
    VoxelTreeLayout layout{.rootCells = glm::ivec3(2, 1, 1), .depth = 2};
    const AdaptiveVoxelTree tree = AdaptiveVoxelTree::build(layout, {glm::ivec3(17, 3, 9)}, false);
    EXPECT_EQ(tree.getLeafCount(), 1u);
    EXPECT_EQ(tree.getNodeCount(), 3u); // two root cells and the leaf's parent
    EXPECT_EQ(tree.getElementCount(), 4u);
    ASSERT_TRUE(tree.getNode(0).has_value()); // x = 17 lies in root cell 1: cell 0 has no children
    EXPECT_EQ(tree.getNode(0)->getMask(), 0u);
    EXPECT_NE(tree.find(2, {17, 3, 9}), AdaptiveVoxelTree::kAbsent);
    EXPECT_EQ(tree.find(2, {17, 3, 8}), AdaptiveVoxelTree::kAbsent);
    expectMatchesDenseGrids(layout, {glm::ivec3(17, 3, 9)}, true, "one voxel");
}

std::vector<glm::ivec3> everyCell(int n)
{
    std::vector<glm::ivec3> all;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                all.push_back({x, y, z});
    return all;
}

TEST(VoxelTree, FullGridSetsEveryMaskBit)
{
    VoxelTreeLayout layout{.rootCells = glm::ivec3(1), .depth = 2};
    const std::vector<glm::ivec3> all = everyCell(16);
    const AdaptiveVoxelTree tree = AdaptiveVoxelTree::build(layout, all, true);
    EXPECT_EQ(tree.getLeafCount(), 4096u);
    EXPECT_EQ(tree.getNodeCount(), 65u);
    for (std::size_t r = 0; r < tree.getNodeCount(); ++r)
        EXPECT_EQ(tree.getRecord(r).getMask(), ~std::uint64_t(0));
    EXPECT_EQ(tree.getMaskTable().size(), 1u); // one mask shared by all 65 records
    expectMatchesDenseGrids(layout, all, true, "full grid");
}

TEST(VoxelTree, SharedMaskOffsetsHoldAcrossRecordGroups)
{
    // 4,161 full records: every group of 64 reaches the largest offset from its base (63 * 64).
    const VoxelTreeLayout full{.rootCells = glm::ivec3(1), .depth = 3};
    expectMatchesDenseGrids(full, everyCell(64), true, "full 64^3");
    // Scattered voxels under 64 root cells: hundreds of records with hundreds of masks.
    const VoxelTreeLayout scattered{.rootCells = glm::ivec3(4), .depth = 2};
    std::mt19937 rng(3);
    std::vector<glm::ivec3> leaves;
    for (int i = 0; i < 3000; ++i)
        leaves.emplace_back(int(rng() % 64u), int(rng() % 64u), int(rng() % 64u));
    expectMatchesDenseGrids(scattered, leaves, false, "scattered");
}

TEST(VoxelTree, TooManyDistinctMasksKeepTheInlineRecords)
{
    const VoxelTreeLayout layout{.rootCells = glm::ivec3(2, 1, 1), .depth = 2};
    const std::vector<glm::ivec3> leaves = {{1, 2, 3}, {17, 3, 9}, {18, 3, 9}, {30, 15, 15}};
    for (const std::size_t limit : {std::size_t(1), std::size_t(2), std::size_t(1000)})
        expectMatchesDenseGrids(layout, leaves,
                                {.dilate = true, .masks = NodeMasks::Shared, .maxSharedMasks = limit},
                                "at most " + std::to_string(limit) + " shared masks");
}

TEST(VoxelTree, VoxelsOnTheBoxFacesAndQueriesOutside)
{
    VoxelTreeLayout layout{.rootCells = glm::ivec3(2, 3, 1), .depth = 2};
    const glm::ivec3 n = layout.getCells(2);
    const std::vector<glm::ivec3> corners = {{0, 0, 0}, {n.x - 1, 0, 0}, {0, n.y - 1, n.z - 1},
                                             n - 1};
    expectMatchesDenseGrids(layout, corners, true, "box corners");
    const AdaptiveVoxelTree tree = AdaptiveVoxelTree::build(layout, corners, true);
    for (const glm::ivec3& c : {glm::ivec3(-1, 0, 0), glm::ivec3(n.x, 0, 0), glm::ivec3(0, n.y, 0),
                                glm::ivec3(0, 0, -5)})
        EXPECT_EQ(tree.find(2, c), AdaptiveVoxelTree::kAbsent);
    EXPECT_EQ(tree.find(3, glm::ivec3(0)), AdaptiveVoxelTree::kAbsent); // no such level
    // Interpolation outside the box takes the nearest point of the box: finite, weights sum to 1.
    TreeQuery q{.origin = glm::dvec3(0.0), .leafSize = 0.5};
    for (const glm::dvec3& p : {glm::dvec3(-100.0), glm::dvec3(1e30, -1e30, 0.0),
                                glm::dvec3(NAN, 1.0, 1.0), glm::dvec3(3.0, 1e-300, 7.9)}) {
        const TreeStencil s = interpolate(tree, q, p);
        double sum = 0.0;
        for (int i = 0; i < s.count; ++i) {
            EXPECT_LT(s.index[std::size_t(i)], tree.getElementCount());
            sum += s.weight[std::size_t(i)];
        }
        EXPECT_NEAR(sum, 1.0, 1e-6);
    }
}

TEST(VoxelTree, ExtremeAspectRatios)
{
    VoxelTreeLayout layout{.rootCells = glm::ivec3(200, 1, 1), .depth = 1};
    std::vector<glm::ivec3> line;
    for (int x = 0; x < 800; x += 3)
        line.push_back({x, x % 4, 3 - x % 4});
    expectMatchesDenseGrids(layout, line, true, "200 x 1 x 1 roots");
    VoxelTreeLayout tall{.rootCells = glm::ivec3(1, 1, 1), .depth = 4};
    expectMatchesDenseGrids(tall, {glm::ivec3(0, 255, 0), glm::ivec3(255, 0, 255)}, true, "depth 4");
}

TEST(VoxelTree, RejectsBadInput)
{
    EXPECT_THROW(AdaptiveVoxelTree::build({.rootCells = glm::ivec3(1), .depth = 0}, {}), Error);
    EXPECT_THROW(AdaptiveVoxelTree::build({.rootCells = glm::ivec3(0, 1, 1), .depth = 2}, {}), Error);
    EXPECT_THROW(AdaptiveVoxelTree::build({.rootCells = glm::ivec3(1), .depth = 2}, {glm::ivec3(16, 0, 0)}),
                 Error);
    EXPECT_THROW(AdaptiveVoxelTree::build({.rootCells = glm::ivec3(1 << 20), .depth = 8}, {}), Error);
    EXPECT_THROW(AdaptiveVoxelTree::build({.rootCells = glm::ivec3(512), .depth = 1}, {}), Error);
}

// A tree with level transitions: a dense blob of leaves in one corner, a sparse scatter elsewhere.
AdaptiveVoxelTree makeTransitionTree(bool dilate)
{
    VoxelTreeLayout layout{.rootCells = glm::ivec3(3, 2, 2), .depth = 2};
    std::vector<glm::ivec3> leaves;
    for (int z = 12; z < 17; ++z)
        for (int y = 13; y < 18; ++y)
            for (int x = 10; x < 22; ++x)
                leaves.push_back({x, y, z});
    std::mt19937 rng(3);
    for (int i = 0; i < 40; ++i)
        leaves.push_back({int(rng() % 48u), int(rng() % 32u), int(rng() % 32u)});
    return AdaptiveVoxelTree::build(layout, leaves, dilate);
}

TEST(VoxelTree, DilationKeepsEveryNeighbourhoodWithinTwoLevels)
{
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int maxLevelsDilated = 0, maxLevelsUndilated = 0;
    const AdaptiveVoxelTree dilated = makeTransitionTree(true), undilated = makeTransitionTree(false);
    for (int i = 0; i < 20000; ++i) {
        const glm::dvec3 p(48.0 * u(rng), 32.0 * u(rng), 32.0 * u(rng));
        const TreeQuery q{.origin = glm::dvec3(0.0), .leafSize = 1.0};
        maxLevelsDilated = std::max(maxLevelsDilated, interpolate(dilated, q, p).levelsUsed);
        maxLevelsUndilated = std::max(maxLevelsUndilated, interpolate(undilated, q, p).levelsUsed);
    }
    EXPECT_LE(maxLevelsDilated, 2);
    EXPECT_GT(maxLevelsUndilated, 2); // without it the fill climbs further (the recursion)
}

// A linear field sampled at the element centres: trilinear interpolation reproduces it exactly
// on one level, and the seamless scheme keeps that across levels (a missing corner gets the
// parent level's exact value); the plain scheme drops the corner and is off by up to a cell's
// gradient.
double linearField(const glm::dvec3& x) { return 0.3 * x.x - 0.7 * x.y + 0.2 * x.z + 5.0; }

TEST(VoxelTree, SeamlessInterpolationReproducesALinearFieldAcrossLevels)
{
    for (bool dilate : {true, false}) {
        const AdaptiveVoxelTree tree = makeTransitionTree(dilate);
        const double leaf = 0.25;
        const glm::dvec3 origin(-3.0, 1.0, 2.0);
        std::vector<double> payload(tree.getElementCount());
        const auto cells = tree.listElementCells();
        for (std::size_t i = 0; i < cells.size(); ++i) {
            const double size = leaf * std::ldexp(1.0, 2 * (tree.getDepth() - cells[i].w));
            payload[i] = linearField(origin + (glm::dvec3(glm::ivec3(cells[i])) + 0.5) * size);
        }
        std::mt19937 rng(5);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        double seamlessErr = 0.0, plainErr = 0.0;
        for (int i = 0; i < 20000; ++i) {
            // Away from the box's faces by 14 leaves: a corner filled from the root level needs
            // the root cells on both sides of it, whose centres lie 8 leaves in.
            const glm::dvec3 p = origin + leaf * glm::dvec3(14.0 + 20.0 * u(rng), 14.0 + 4.0 * u(rng),
                                                            14.0 + 4.0 * u(rng));
            for (auto mode : {TreeInterpolation::Seamless, TreeInterpolation::Plain}) {
                const TreeStencil s = interpolate(tree, {.origin = origin, .leafSize = leaf, .mode = mode}, p);
                double v = 0.0;
                for (int k = 0; k < s.count; ++k)
                    v += double(s.weight[std::size_t(k)]) * payload[s.index[std::size_t(k)]];
                double& err = mode == TreeInterpolation::Seamless ? seamlessErr : plainErr;
                err = std::max(err, std::abs(v - linearField(p)));
            }
        }
        // Float weights: 1e-5 of a field of magnitude ~10.
        EXPECT_LT(seamlessErr, 1e-4) << (dilate ? "dilated" : "undilated");
        EXPECT_GT(plainErr, 0.1) << (dilate ? "dilated" : "undilated");
    }
}

TEST(VoxelTree, AntiLeakWeightFavoursDataPointsInFrontOfTheSurface)
{
    // Full grid of 16^3 leaves; a surface at x = 8 facing +x; data points behind it hold 100.
    VoxelTreeLayout layout{.rootCells = glm::ivec3(1), .depth = 2};
    const std::vector<glm::ivec3> all = everyCell(16);
    const AdaptiveVoxelTree tree = AdaptiveVoxelTree::build(layout, all, true);
    const auto cells = tree.listElementCells();
    auto value = [&](const TreeQuery& q) {
        const TreeStencil s = interpolate(tree, q, glm::dvec3(8.0, 8.3, 8.6));
        double v = 0.0;
        for (int k = 0; k < s.count; ++k) {
            const glm::ivec4 c = cells[s.index[std::size_t(k)]];
            v += double(s.weight[std::size_t(k)]) * (c.w == 2 && c.x < 8 ? 100.0 : 1.0);
        }
        return v;
    };
    const double plain = value({.origin = glm::dvec3(0.0), .leafSize = 1.0});
    const double guarded = value({.origin = glm::dvec3(0.0), .leafSize = 1.0, .normal = glm::dvec3(1, 0, 0)});
    EXPECT_NEAR(plain, 50.5, 1e-3);   // halfway between the two layers
    EXPECT_LT(guarded, 0.1 * plain);  // computed by hand: 3.23 (behind: ((1 + cos)/2)^2 < 0.1)
    EXPECT_GT(guarded, 1.0);          // continuous: they still count a little
}

} // namespace
