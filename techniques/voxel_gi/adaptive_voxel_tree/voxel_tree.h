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
//  * Shared masks (NodeMasks::Shared, the default; not in the talk): the records' 64-bit masks are
//    kept once each in a mask table, and a record is a bit field of 12 + b bits: its children's
//    offset relative to a base kept per 64 records (12 bits: 63 records of at most 64 children
//    each lie before it in its group), and the mask's table index (b bits, as many as the table
//    needs, at most 20). The records are packed back to back in 32-bit words. This is possible
//    because a record's offset is implied by the records before it: children are packed in the
//    records' order, so record r's offset is levelBegin(1) + the popcounts of records 0..r-1.
//    Voxelized surfaces repeat few patterns: tomorrow_town at 512 has 57,292 records with 6,215
//    distinct masks, cornell_box 113,286 with 710 (voxel_structure_benchmark's `masks` counter),
//    so a record costs about 3 bytes + 1/16 of a base + its share of the table, where the talk's
//    record costs 12. The child index is the same offset + popcount, read in two more loads that
//    stay in cache (the bases and a table of at most a few thousand masks). When the masks need
//    more than 20-bit indices the tree keeps the talk's records (getNodeMasks() says which).
//    In a dilated tree, each record above level depth - 1 has a second field of the same form:
//    the mask of its children that have a record (the same table) and the record of the first
//    of them. A descent needs nothing else above the target level (every ancestor of an element
//    has children), so it goes from record to record without the rank words, which stay for
//    getNode(element).
//
// Element coordinates are integer cells of their level: level l has rootCells * 4^l cells per
// axis, and level `depth` cells are the leaves.

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
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

//! How a node record stores its child mask: inline (the talk's 12-byte record) or as an index into
//! a table of the tree's distinct masks (a bit field of 12 + log2(table size) bits).
enum class NodeMasks { Shared, Inline };

struct VoxelTreeBuildOptions {
    bool dilate = true;                 //!< partial dilation of the upper levels
    NodeMasks masks = NodeMasks::Shared;
    //! Shared masks fall back to inline ones when the tree has more distinct masks than this
    //! (at most 2^20, the index bits of a record's field; lower only to test the fallback).
    std::size_t maxSharedMasks = std::size_t(1) << 20;
};

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
                                   const VoxelTreeBuildOptions& options = {});
    static AdaptiveVoxelTree build(const VoxelTreeLayout& layout, std::vector<glm::ivec3> leaves,
                                   bool dilate)
    {
        return build(layout, std::move(leaves), VoxelTreeBuildOptions{.dilate = dilate});
    }

    //! Low bits of a shared-mask record that hold the offset from its group's base.
    static constexpr unsigned kOffsetBits = 12;
    static constexpr std::uint32_t kOffsetMask = (1u << kOffsetBits) - 1u;

    const VoxelTreeLayout& getLayout() const { return mLayout; }
    int getDepth() const { return mLayout.depth; }
    //! How the records hold their masks (Inline also where Shared fell back).
    NodeMasks getNodeMasks() const { return mNodeMasks; }
    //! Record r (in element order) decoded: its mask and its children's offset.
    VoxelTreeNode getRecord(std::size_t r) const
    {
        if (mNodeMasks == NodeMasks::Inline)
            return mNodes[r];
        const std::uint32_t word = readRecordField(r);
        const std::uint64_t mask = mMaskTable[word >> kOffsetBits];
        return {std::uint32_t(mask), std::uint32_t(mask >> 32),
                mRecordBases[r >> 6] + (word & kOffsetMask)};
    }
    //! Inline masks: the 12-byte records (empty for shared masks).
    const std::vector<VoxelTreeNode>& getInlineRecords() const { return mNodes; }
    //! Shared masks: the records' bit fields (mask table index << kOffsetBits | offset from the
    //! group's base) of getRecordWidth() bits each, record r at bit r * width, low bits first,
    //! with two words of padding at the end; the base of each 64 records; the distinct masks.
    const std::vector<std::uint32_t>& getRecordBits() const { return mRecordBits; }
    unsigned getRecordWidth() const { return mRecordWidth; }
    const std::vector<std::uint32_t>& getRecordBases() const { return mRecordBases; }
    const std::vector<std::uint64_t>& getMaskTable() const { return mMaskTable; }
    //! The rank words over the upper-level elements [0, getLevelBegin(depth)).
    const std::vector<VoxelTreeRank>& getRanks() const { return mRanks; }
    //! Node records: the root cells and the elements with children.
    std::size_t getNodeCount() const { return mRecordCount; }
    std::size_t getLeafCount() const { return mLeafCount; }
    //! Every element (root cells, upper-level cells with or without children, leaves): the
    //! length of a payload array.
    std::size_t getElementCount() const { return mLevelBegin.back(); }
    //! First element index of each level (levelBegin[depth + 1] = element count).
    std::size_t getLevelBegin(int level) const { return mLevelBegin[std::size_t(level)]; }
    bool isDilated() const { return mDilated; }

    //! The node record of element e, or nothing when e has none (a leaf, a childless cell below
    //! the roots; a root cell always has one, its mask 0 when it has no children).
    std::optional<VoxelTreeNode> getNode(std::uint32_t e) const
    {
        if (e >= mLevelBegin[std::size_t(mLayout.depth)])
            return std::nullopt;
        const std::int64_t record = findRecord(e);
        if (record < 0)
            return std::nullopt;
        return getRecord(std::size_t(record));
    }

    //! Index of the element at cell c of `level`, or kAbsent (also for c outside the grid).
    //! Inline: it is the lookup every use of the tree spends its time in.
    std::int64_t find(int level, const glm::ivec3& c) const
    {
        if (unsigned(level) > unsigned(mLayout.depth))
            return kAbsent;
        const int shift = 2 * level;
        // A negative coordinate stays negative when shifted: as unsigned, it is past any bound.
        const unsigned rx = unsigned(c.x >> shift), ry = unsigned(c.y >> shift), rz = unsigned(c.z >> shift);
        const glm::ivec3& roots = mLayout.rootCells;
        if (rx >= unsigned(roots.x) || ry >= unsigned(roots.y) || rz >= unsigned(roots.z))
            return kAbsent;
        const std::uint32_t root = rx + unsigned(roots.x) * (ry + unsigned(roots.y) * rz);
        // One branch per lookup, not per level: each descent is specialised.
        if (mNodeMasks == NodeMasks::Shared) {
            if (!mEveryUpperHasRecord) {
                if (shift == 4)
                    return descend<true, true, 4>(root, shift, c);
                if (shift == 6)
                    return descend<true, true, 6>(root, shift, c);
                return descend<true, true>(root, shift, c);
            }
            return descend<true, false>(root, shift, c);
        }
        return mEveryUpperHasRecord ? descend<false, false>(root, shift, c) : descend<false, true>(root, shift, c);
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

    //! Topology bytes: the node records (with shared masks: their words, bases and mask table)
    //! and the rank words (the root cells' records are the dense first level, so there is no
    //! other table).
    std::size_t getTopologyBytes() const
    {
        return mNodes.size() * sizeof(VoxelTreeNode) +
               (mRecordBits.size() + mRecordBases.size() + mUpperBits.size() + mUpperBases.size()) *
                   sizeof(std::uint32_t) +
               mMaskTable.size() * sizeof(std::uint64_t) + mRanks.size() * sizeof(VoxelTreeRank);
    }

private:
    //! Replaces the inline records by shared masks when they need at most maxMasks entries.
    void shareMasks(std::size_t maxMasks);
    //! The bit field of `mask` bits at bit `bit` of a packed array of 32-bit words: one unaligned
    //! 8-byte read (width <= 32, shift <= 7; the two padding words keep it inside the array).
    static std::uint32_t readField(const std::uint32_t* words, std::uint64_t bit,
                                   std::uint32_t mask)
    {
        std::uint64_t bytes;
        std::memcpy(&bytes, reinterpret_cast<const unsigned char*>(words) + (bit >> 3),
                    sizeof bytes);
        return std::uint32_t(bytes >> (bit & 7u)) & mask;
    }
    //! Shared masks: record r's bit field.
    std::uint32_t readRecordField(std::size_t r) const
    {
        return readField(mRecordBits.data(), std::uint64_t(r) * mRecordWidth, mRecordFieldMask);
    }
    //! find() below root cell `root`. Shared: the records' masks are in the table. Ranked: some
    //! upper-level elements have no record (a dilated tree), so the next record is found through
    //! the upper fields (shared masks) or by rank (inline masks); otherwise record = element
    //! (every upper-level element of an undilated tree has children).
    template <bool Shared, bool Ranked, int FixedShift = -1>
    std::int64_t descend(std::uint32_t root, int shift, const glm::ivec3& c) const
    {
        if constexpr (FixedShift >= 0)
            shift = FixedShift; // a known depth: the loop unrolls, its shifts are constants
        const VoxelTreeNode* nodes = mNodes.data();
        const std::uint32_t* fields = mRecordBits.data();
        const std::uint32_t* upperFields = mUpperBits.data();
        const std::uint32_t* bases = mRecordBases.data();
        const std::uint32_t* upperBases = mUpperBases.data();
        const std::uint64_t* table = mMaskTable.data();
        const std::uint64_t width = mRecordWidth;
        const std::uint32_t fieldMask = mRecordFieldMask;
        std::uint32_t index = root;
        std::uint32_t record = root; // the dense first level: every root cell has a record
        for (int s = shift - 2; s >= 0; s -= 2) {
            const int bit = ((c.x >> s) & 3) | (((c.y >> s) & 3) << 2) | (((c.z >> s) & 3) << 4);
            if constexpr (Shared && Ranked) {
                if (s > 0) {
                    // Above the target level only the children with a record matter (every
                    // ancestor of an element has children): the next record without the ranks.
                    const std::uint32_t field = readField(upperFields, record * width, fieldMask);
                    const std::uint64_t real = table[field >> kOffsetBits];
                    if (((real >> bit) & 1u) == 0)
                        return kAbsent;
                    record = upperBases[record >> 6] + (field & kOffsetMask) +
                             std::uint32_t(std::popcount(real & ((std::uint64_t(1) << bit) - 1)));
                    continue;
                }
            }
            std::uint64_t mask;
            std::uint32_t offset;
            if constexpr (Shared) {
                const std::uint32_t field = readField(fields, record * width, fieldMask);
                mask = table[field >> kOffsetBits];
                offset = bases[record >> 6] + (field & kOffsetMask);
            } else {
                mask = nodes[record].getMask();
                offset = nodes[record].offset;
            }
            if (((mask >> bit) & 1u) == 0)
                return kAbsent;
            // The talk's child index: offset + the set bits below this one (one POPCNT).
            index = offset + std::uint32_t(std::popcount(mask & ((std::uint64_t(1) << bit) - 1)));
            if (s > 0) {
                if constexpr (Ranked) {
                    // The child's node record; none: no children at all.
                    const std::int64_t next = findRecord(index);
                    if (next < 0)
                        return kAbsent;
                    record = std::uint32_t(next);
                } else {
                    record = index;
                }
            }
        }
        return std::int64_t(index);
    }
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
    NodeMasks mNodeMasks = NodeMasks::Inline;
    bool mEveryUpperHasRecord = false; //!< record = element for every upper-level element
    std::size_t mRecordCount = 0;
    std::vector<VoxelTreeNode> mNodes; // inline masks
    std::vector<std::uint32_t> mRecordBits, mRecordBases;
    //! Shared masks of a dilated tree: for each record above level depth - 1, the mask of its
    //! children that have a record and the record of the first one (fields and bases as above).
    std::vector<std::uint32_t> mUpperBits, mUpperBases;
    unsigned mRecordWidth = 32;
    std::uint32_t mRecordFieldMask = ~0u;
    std::vector<std::uint64_t> mMaskTable; // shared masks
    std::vector<VoxelTreeRank> mRanks;
    std::size_t mLeafCount = 0;
    std::vector<std::size_t> mLevelBegin;
    bool mDilated = true;
};

//! The tree's topology as one buffer of 32-bit words for the Vulkan lookup (shaders of
//! adaptive_voxel_tree_cones: tree_find.glsl): the rank words (3 words each), then the node
//! records as the tree holds them: inline (3 words each), or the shared masks' record fields,
//! their bases and the mask table (2 words per mask).
struct GpuTreeTopology {
    std::vector<std::uint32_t> words;
    std::uint32_t recordStart = 0; //!< the first record's word
    //! x: the shared masks' record bits (0: inline), y: the first base's word, z: the table's.
    glm::ivec4 masks{0};
};
GpuTreeTopology packTopologyForGpu(const AdaptiveVoxelTree& tree);

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
