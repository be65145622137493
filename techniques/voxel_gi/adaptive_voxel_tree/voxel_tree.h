#pragma once
// The adaptive voxel tree of Quantum Break (Silvennoinen & Timonen, SIGGRAPH 2015;
// shared/seeds/002_2c73d3b2bb6f7a13.txt, "Adaptive Voxel Tree" to "world space cells"):
//
//  * The box is a dense grid of root cells (the "dense first level" instead of OpenVDB's hash);
//    each cell is split into 4x4x4 children, down to `depth` levels below the roots.
//  * A node is a 64-bit child mask and the offset of its children, which are packed tightly: the
//    child with bit b has index offset + popcount(mask & ((1 << b) - 1)).
//  * That child index is also the index into every payload array (no links, payloads can be
//    added without touching the tree). Indices form one space: nodes of every level in
//    breadth-first order (the root cells first, index = cell), then the leaves.
//  * Leaves are implicit: a leaf exists only as its parent's mask bit and as payload index.
//  * Partial dilation of the upper levels: a level l (1 <= l < depth) node exists for each of the
//    27 cells around the parent of every level l + 1 element, so the trilinear neighbourhood of
//    any point (interpolate() below) needs at most the level of the point and the one above it.
//  * Below the root cells (which all have a node record: the dense first level, record = cell),
//    only elements with children have a node record. An element without children (a dilated
//    cell) is implicit like a leaf: it is a bit in its parent's mask and a payload index. A
//    record is found by rank (Jacobson, "Space-efficient static trees and graphs", FOCS 1989):
//    one bit per upper-level element saying whether it has a record, and the count of records
//    before each 64-bit word, so that element e's record is
//        base[e / 64] + popcount(bits[e / 64] & ((1 << (e % 64)) - 1)).
//    That costs 12 bytes per 64 upper-level elements, where a record per dilated cell cost 12
//    bytes each: the talk's "partial dilation increases the total memory only by a few percent"
//    then holds for the topology as well.
//
// Element coordinates are integer cells of their level: level l has rootCells * 4^l cells per
// axis, and level `depth` cells are the leaves.

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rtlab::voxelgi {

//! One node: 64-bit child mask and the index of its first child (12 bytes, no padding).
struct VoxelTreeNode {
    std::uint32_t maskLo = 0;
    std::uint32_t maskHi = 0;
    std::uint32_t offset = 0;
    std::uint64_t getMask() const { return std::uint64_t(maskLo) | (std::uint64_t(maskHi) << 32); }
};
static_assert(sizeof(VoxelTreeNode) == 12);

//! 64 upper-level elements: which of them have a node record (bit e % 64), and how many elements
//! before this word have one (the index of the first one's record). 12 bytes.
struct VoxelTreeRank {
    std::uint32_t bitsLo = 0;
    std::uint32_t bitsHi = 0;
    std::uint32_t base = 0;
    std::uint64_t getBits() const { return std::uint64_t(bitsLo) | (std::uint64_t(bitsHi) << 32); }
};
static_assert(sizeof(VoxelTreeRank) == 12);

//! The child bit of cell c (integer coordinates of the child's level) inside its parent.
inline int getChildBit(const glm::ivec3& c)
{
    return (c.x & 3) | ((c.y & 3) << 2) | ((c.z & 3) << 4);
}

struct VoxelTreeLayout {
    glm::ivec3 rootCells{1}; //!< dense first level, cells per axis (each >= 1)
    int depth = 3;           //!< levels below the roots; leaves are level `depth` (1..8)
    //! Cells of level `level` per axis: rootCells * 4^level.
    glm::ivec3 getCells(int level) const { return rootCells * (1 << (2 * level)); }
};

class AdaptiveVoxelTree {
public:
    static constexpr std::int64_t kAbsent = -1;

    //! Builds the tree holding the given leaves (level `depth` cells; duplicates are merged),
    //! with partial dilation of the upper levels when `dilate`. Throws rtlab::Error for a bad
    //! layout (depth outside [1, 8], more than 2^24 root cells), a leaf outside the grid, or more
    //! than 2^32 - 1 elements.
    static AdaptiveVoxelTree build(const VoxelTreeLayout& layout, std::vector<glm::ivec3> leaves,
                                   bool dilate = true);

    const VoxelTreeLayout& getLayout() const { return mLayout; }
    int getDepth() const { return mLayout.depth; }
    //! The node records of the root cells and the elements with children, in element order.
    const std::vector<VoxelTreeNode>& getNodes() const { return mNodes; }
    //! The rank words over the upper-level elements [0, getLevelBegin(depth)).
    const std::vector<VoxelTreeRank>& getRanks() const { return mRanks; }
    //! Node records: the root cells and the elements with children.
    std::size_t getNodeCount() const { return mNodes.size(); }
    std::size_t getLeafCount() const { return mLeafCount; }
    //! Every element (root cells, upper-level cells with or without children, leaves): the
    //! length of a payload array.
    std::size_t getElementCount() const { return mLevelBegin.back(); }
    //! First element index of each level (levelBegin[depth + 1] = element count).
    std::size_t getLevelBegin(int level) const { return mLevelBegin[std::size_t(level)]; }
    bool isDilated() const { return mDilated; }

    //! The node record of element e, or nullptr when e has none (a leaf, a childless cell below
    //! the roots; a root cell always has one, its mask 0 when it has no children).
    const VoxelTreeNode* getNode(std::uint32_t e) const
    {
        if (e >= mLevelBegin[std::size_t(mLayout.depth)])
            return nullptr;
        const std::int64_t record = findRecord(e);
        return record < 0 ? nullptr : &mNodes[std::size_t(record)];
    }

    //! Index of the element at cell c of `level`, or kAbsent (also for c outside the grid).
    //! Inline: it is the lookup every use of the tree spends its time in.
    std::int64_t find(int level, const glm::ivec3& c) const
    {
        if (unsigned(level) > unsigned(mLayout.depth) || c.x < 0 || c.y < 0 || c.z < 0)
            return kAbsent;
        const int shift = 2 * level;
        const int rx = c.x >> shift, ry = c.y >> shift, rz = c.z >> shift;
        const glm::ivec3& roots = mLayout.rootCells;
        if (rx >= roots.x || ry >= roots.y || rz >= roots.z)
            return kAbsent;
        std::uint32_t index = std::uint32_t(rx + roots.x * (ry + roots.y * rz));
        std::uint32_t record = index; // the dense first level: every root cell has a record
        for (int s = shift - 2; s >= 0; s -= 2) {
            const VoxelTreeNode& node = mNodes[record];
            const std::uint64_t mask = node.getMask();
            const int bit = ((c.x >> s) & 3) | (((c.y >> s) & 3) << 2) | (((c.z >> s) & 3) << 4);
            if (((mask >> bit) & 1u) == 0)
                return kAbsent;
            // The talk's child index: offset + the set bits below this one (one POPCNT).
            index = node.offset +
                    std::uint32_t(std::popcount(mask & ((std::uint64_t(1) << bit) - 1)));
            if (s > 0) {
                // The child's node record; none: no children at all.
                const std::int64_t next = findRecord(index);
                if (next < 0)
                    return kAbsent;
                record = std::uint32_t(next);
            }
        }
        return std::int64_t(index);
    }
    //! Every element's cell (xyz) and level (w), in index order (the inverse of find).
    std::vector<glm::ivec4> listElementCells() const;

    //! The deepest element containing leaf-level cell `leaf` (clamped to the grid): its level and
    //! index, and whether it has children.
    struct Deepest {
        int level = 0;
        std::int64_t index = 0;
        bool hasChildren = false;
    };
    Deepest findDeepest(const glm::ivec3& leaf) const;

    //! Topology bytes: the node records and the rank words (the root cells' records are the
    //! dense first level, so there is no other table).
    std::size_t getTopologyBytes() const
    {
        return mNodes.size() * sizeof(VoxelTreeNode) + mRanks.size() * sizeof(VoxelTreeRank);
    }

private:
    //! The node record of upper-level element e by rank, or -1 when it has none.
    std::int64_t findRecord(std::uint32_t e) const
    {
        const VoxelTreeRank& word = mRanks[e >> 6];
        const std::uint64_t bits = word.getBits();
        const unsigned b = e & 63u;
        if (((bits >> b) & 1u) == 0)
            return -1;
        return std::int64_t(word.base) + std::popcount(bits & ((std::uint64_t(1) << b) - 1));
    }

    VoxelTreeLayout mLayout;
    std::vector<VoxelTreeNode> mNodes;
    std::vector<VoxelTreeRank> mRanks;
    std::size_t mLeafCount = 0;
    std::vector<std::size_t> mLevelBegin;
    bool mDilated = true;
};

//! Where an interpolated value comes from: element indices and weights (summing to 1).
struct TreeStencil {
    //! Distinct elements: 8 corners, then at most 27 cells per level above (the parent-level
    //! neighbourhoods of 8 adjacent corners span at most 3 cells per axis).
    static constexpr int kMax = 8 + 27 * 8;
    std::array<std::uint32_t, kMax> index{};
    std::array<float, kMax> weight{};
    int count = 0;
    int level = 0;      //!< the level the trilinear neighbourhood was taken at
    int levelsUsed = 1; //!< 1, or 2 where a corner was interpolated from the parent level
};

enum class TreeInterpolation {
    //! Quantum Break's: the trilinear neighbourhood at the level below the deepest node that
    //! holds the point, corners missing there interpolated from the parent level.
    Seamless,
    //! Per level: the same neighbourhood, missing corners dropped and the weights renormalised
    //! (jumps where the level changes).
    Plain,
};

struct TreeQuery {
    glm::dvec3 origin{0.0}; //!< world position of the grid's min corner
    double leafSize = 1.0;  //!< world size of a leaf cell
    TreeInterpolation mode = TreeInterpolation::Seamless;
    //! Surface normal for the anti-leak weight (zero vector: none). Quantum Break multiplies the
    //! trilinear weights by "a geometry term, which takes the surface normal into account"; the
    //! term used here is ((1 + cos t) / 2)^2 with t the angle between the normal and the
    //! direction to the data point (the wrap weight of Majercik et al. 2019, JCGT 8(2), "Dynamic
    //! Diffuse Global Illumination with Ray-Traced Irradiance Fields"), floored at 1e-3 so that a
    //! point with every data point behind it still gets a value. It is continuous in the point.
    glm::dvec3 normal{0.0};
};

//! The stencil of the value at world position p (clamped into the grid's box): data points are
//! element centres. With a dilated tree the seamless mode never needs more than two levels; on
//! an undilated tree it climbs further (correct, slower). Throws nothing; out-of-box points take
//! the value at the nearest point of the box.
TreeStencil interpolate(const AdaptiveVoxelTree& tree, const TreeQuery& query, const glm::dvec3& p);

} // namespace rtlab::voxelgi
