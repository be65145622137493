#include "voxel_tree.h"

#include "core/error.h"

#include <glm/geometric.hpp>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

namespace rtlab::voxelgi {

namespace {

std::string toString(const glm::ivec3& c)
{
    return "(" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " + std::to_string(c.z) + ")";
}

bool inside(const glm::ivec3& c, const glm::ivec3& cells)
{
    return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < cells.x && c.y < cells.y && c.z < cells.z;
}

// Sort key of a cell of `level`: root cell index, then one 6-bit child digit per level below the
// root. Sorting by it gives the breadth-first order of each level in which children are packed.
std::uint64_t makeKey(const VoxelTreeLayout& layout, int level, const glm::ivec3& c)
{
    const glm::ivec3 root = c >> (2 * level);
    std::uint64_t key = std::uint64_t(root.x) +
                        std::uint64_t(layout.rootCells.x) *
                            (std::uint64_t(root.y) + std::uint64_t(layout.rootCells.y) * std::uint64_t(root.z));
    for (int l = 1; l <= level; ++l)
        key = (key << 6) | std::uint64_t(getChildBit(c >> (2 * (level - l))));
    return key;
}

glm::ivec3 decodeKey(const VoxelTreeLayout& layout, int level, std::uint64_t key)
{
    glm::ivec3 below(0);
    for (int l = 0; l < level; ++l) {
        const int bit = int(key & 63u);
        below += glm::ivec3(bit & 3, (bit >> 2) & 3, bit >> 4) << (2 * l);
        key >>= 6;
    }
    const auto rx = std::uint64_t(layout.rootCells.x), ry = std::uint64_t(layout.rootCells.y);
    const glm::ivec3 root(int(key % rx), int((key / rx) % ry), int(key / (rx * ry)));
    return (root << (2 * level)) + below;
}

void sortUnique(std::vector<std::uint64_t>& keys)
{
    tbb::parallel_sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

} // namespace

AdaptiveVoxelTree AdaptiveVoxelTree::build(const VoxelTreeLayout& layout, std::vector<glm::ivec3> leaves,
                                           const VoxelTreeBuildOptions& options)
{
    const bool dilate = options.dilate;
    if (layout.depth < 1 || layout.depth > 8)
        throw Error("adaptive voxel tree: depth " + std::to_string(layout.depth) +
                    " is outside [1, 8]");
    if (layout.rootCells.x < 1 || layout.rootCells.y < 1 || layout.rootCells.z < 1)
        throw Error("adaptive voxel tree: root cells " + toString(layout.rootCells) +
                    " must be at least 1 per axis");
    const double rootCount =
        double(layout.rootCells.x) * double(layout.rootCells.y) * double(layout.rootCells.z);
    // Keys hold the root index and 6 bits per level; leaf coordinates must fit an int.
    if (rootCount * std::ldexp(1.0, 6 * layout.depth) >= std::ldexp(1.0, 63) ||
        double(std::max({layout.rootCells.x, layout.rootCells.y, layout.rootCells.z})) *
                std::ldexp(1.0, 2 * layout.depth) >= 2147483647.0)
        throw Error("adaptive voxel tree: " + toString(layout.rootCells) + " root cells of depth " +
                    std::to_string(layout.depth) + " address more cells than 63-bit keys hold");

    // The dense first level is a node per root cell: 2^24 of them take 200 MB already.
    if (rootCount > double(1 << 24))
        throw Error("adaptive voxel tree: " + toString(layout.rootCells) +
                    " root cells are more than 2^24 for the dense first level; use a larger depth");
    AdaptiveVoxelTree tree;
    tree.mLayout = layout;
    tree.mDilated = dilate;
    const int depth = layout.depth;
    std::vector<std::vector<std::uint64_t>> keys(std::size_t(depth) + 1);

    const glm::ivec3 leafCells = layout.getCells(depth);
    keys[std::size_t(depth)].reserve(leaves.size());
    for (const glm::ivec3& c : leaves) {
        if (!inside(c, leafCells))
            throw Error("adaptive voxel tree: leaf " + toString(c) + " is outside the grid of " +
                        toString(leafCells) + " leaf cells");
        keys[std::size_t(depth)].push_back(makeKey(layout, depth, c));
    }
    leaves.clear();
    leaves.shrink_to_fit();
    sortUnique(keys[std::size_t(depth)]);

    // Upper levels: the parents of the level below, dilated by one cell (a 3x3x3 block) when
    // asked, except at level 0, which is dense.
    for (int level = depth - 1; level >= 1; --level) {
        auto& out = keys[std::size_t(level)];
        const auto& below = keys[std::size_t(level) + 1];
        std::vector<std::uint64_t> parents;
        parents.reserve(below.size() / 8 + 1);
        for (std::uint64_t k : below)
            if (parents.empty() || parents.back() != (k >> 6))
                parents.push_back(k >> 6); // below is sorted, so equal parents are adjacent
        if (!dilate) {
            out = std::move(parents);
            continue;
        }
        const glm::ivec3 cells = layout.getCells(level);
        out.reserve(parents.size() * 4);
        for (std::uint64_t k : parents) {
            const glm::ivec3 c = decodeKey(layout, level, k);
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const glm::ivec3 n = c + glm::ivec3(dx, dy, dz);
                        if (inside(n, cells))
                            out.push_back(makeKey(layout, level, n));
                    }
        }
        sortUnique(out);
    }
    auto& roots = keys[0];
    roots.resize(std::size_t(rootCount));
    for (std::size_t i = 0; i < roots.size(); ++i)
        roots[i] = i;

    tree.mLevelBegin.assign(std::size_t(depth) + 2, 0);
    for (int level = 0; level <= depth; ++level)
        tree.mLevelBegin[std::size_t(level) + 1] =
            tree.mLevelBegin[std::size_t(level)] + keys[std::size_t(level)].size();
    if (tree.mLevelBegin.back() >= std::numeric_limits<std::uint32_t>::max())
        throw Error("adaptive voxel tree: " + std::to_string(tree.mLevelBegin.back()) +
                    " elements do not fit 32-bit indices");

    // Node records for the root cells and the elements with children, in element order; the
    // rank words mark which elements those are.
    const std::size_t upper = tree.mLevelBegin[std::size_t(depth)];
    tree.mRanks.assign((upper + 63) / 64, VoxelTreeRank{});
    tree.mNodes.reserve(upper);
    for (int level = 0; level < depth; ++level) {
        const auto& parents = keys[std::size_t(level)];
        const auto& children = keys[std::size_t(level) + 1];
        std::size_t j = 0;
        for (std::size_t i = 0; i < parents.size(); ++i) {
            const std::uint32_t first = std::uint32_t(tree.mLevelBegin[std::size_t(level) + 1] + j);
            std::uint64_t mask = 0;
            while (j < children.size() && (children[j] >> 6) == parents[i]) {
                mask |= std::uint64_t(1) << (children[j] & 63u);
                ++j;
            }
            if (mask == 0 && level > 0)
                continue; // implicit; root cells keep their record (the dense first level)
            const std::size_t e = tree.mLevelBegin[std::size_t(level)] + i;
            VoxelTreeRank& word = tree.mRanks[e >> 6];
            if ((e & 63u) < 32)
                word.bitsLo |= 1u << (e & 31u);
            else
                word.bitsHi |= 1u << (e & 31u);
            tree.mNodes.push_back({std::uint32_t(mask), std::uint32_t(mask >> 32), first});
        }
    }
    tree.mNodes.shrink_to_fit();
    tree.mRecordCount = tree.mNodes.size();
    tree.mEveryUpperHasRecord = tree.mRecordCount == upper;
    std::uint32_t before = 0;
    for (VoxelTreeRank& word : tree.mRanks) {
        word.base = before;
        before += std::uint32_t(std::popcount(word.getBits()));
    }
    tree.mLeafCount = keys[std::size_t(depth)].size();
    if (options.masks == NodeMasks::Shared)
        tree.shareMasks(std::min(options.maxSharedMasks, std::size_t(1) << (32 - kOffsetBits)));
    return tree;
}

namespace {

// Writes `field` (at most 32 bits) at bit `bit` of a packed array, low bits first.
void writeField(std::vector<std::uint32_t>& words, std::uint64_t bit, std::uint64_t field)
{
    const std::size_t word = std::size_t(bit >> 5);
    const std::uint64_t shifted = field << (bit & 31u);
    words[word] |= std::uint32_t(shifted);
    words[word + 1] |= std::uint32_t(shifted >> 32);
}

} // namespace

void AdaptiveVoxelTree::shareMasks(std::size_t maxMasks)
{
    const std::size_t records = mNodes.size();
    // A dilated tree: the upper records (levels < depth - 1, the first ones in element order)
    // also get the mask of their children that have a record and the record of the first of
    // those, so that a descent finds the next record without the rank words.
    std::size_t upper = 0;
    std::vector<std::uint64_t> realMasks;
    std::vector<std::uint32_t> realOffsets;
    if (!mEveryUpperHasRecord && mLayout.depth >= 2) {
        const auto recordsBefore = [this](std::size_t e) {
            const VoxelTreeRank& word = mRanks[e >> 6];
            return std::size_t(word.base) +
                   std::size_t(
                       std::popcount(word.getBits() & ((std::uint64_t(1) << (e & 63u)) - 1)));
        };
        upper = recordsBefore(mLevelBegin[std::size_t(mLayout.depth) - 1]);
        realMasks.resize(upper);
        realOffsets.resize(upper);
        for (std::size_t r = 0; r < upper; ++r) {
            std::uint64_t mask = mNodes[r].getMask(), real = 0;
            std::uint32_t child = mNodes[r].offset;
            realOffsets[r] = std::uint32_t(recordsBefore(child));
            while (mask != 0) {
                const int bit = std::countr_zero(mask);
                mask &= mask - 1;
                if (findRecord(child++) >= 0)
                    real |= std::uint64_t(1) << bit;
            }
            realMasks[r] = real;
        }
    }
    // The table of distinct masks, the most frequent first (they then share cache lines).
    std::vector<std::uint64_t> masks(records + upper);
    for (std::size_t r = 0; r < records; ++r)
        masks[r] = mNodes[r].getMask();
    std::copy(realMasks.begin(), realMasks.end(), masks.begin() + std::ptrdiff_t(records));
    sortUnique(masks);
    if (masks.size() > maxMasks)
        return; // the talk's records stay
    std::vector<std::uint32_t> uses(masks.size(), 0);
    const auto indexOf = [&masks](std::uint64_t m) {
        return std::size_t(std::lower_bound(masks.begin(), masks.end(), m) - masks.begin());
    };
    for (const VoxelTreeNode& node : mNodes)
        ++uses[indexOf(node.getMask())];
    for (const std::uint64_t m : realMasks)
        ++uses[indexOf(m)];
    std::vector<std::uint32_t> order(masks.size());
    for (std::uint32_t i = 0; i < order.size(); ++i)
        order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&uses](std::uint32_t a, std::uint32_t b) { return uses[a] > uses[b]; });
    std::vector<std::uint32_t> id(masks.size());
    mMaskTable.resize(masks.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) {
        id[order[i]] = i;
        mMaskTable[i] = masks[order[i]];
    }
    // A field: the offset from the group's base, then as many index bits as the table needs
    // (>= 1). Within a group of 64 records an offset exceeds the group's first by at most
    // 63 * 64 < 2^kOffsetBits: records are in element order and children are packed in it, so
    // a record's offset is the previous record's plus its popcount (and the same holds for the
    // records of the children that have one).
    mRecordWidth = kOffsetBits + unsigned(std::max(1, int(std::bit_width(masks.size() - 1))));
    mRecordFieldMask = mRecordWidth >= 32 ? ~0u : (1u << mRecordWidth) - 1u;
    const auto pack = [&](std::size_t count, const auto& maskOf, const auto& offsetOf,
                          std::vector<std::uint32_t>& bits, std::vector<std::uint32_t>& bases) {
        bits.assign((std::uint64_t(count) * mRecordWidth + 31) / 32 + 2, 0u);
        bases.resize((count + 63) / 64);
        for (std::size_t r = 0; r < count; ++r) {
            if ((r & 63u) == 0)
                bases[r >> 6] = offsetOf(r);
            const std::uint32_t delta = offsetOf(r) - bases[r >> 6];
            if (delta > kOffsetMask)
                throw Error("adaptive voxel tree: record " + std::to_string(r) +
                            " lies outside its group's offset range (internal error)");
            writeField(bits, std::uint64_t(r) * mRecordWidth,
                       (std::uint64_t(id[indexOf(maskOf(r))]) << kOffsetBits) | delta);
        }
    };
    pack(
        records, [this](std::size_t r) { return mNodes[r].getMask(); },
        [this](std::size_t r) { return mNodes[r].offset; }, mRecordBits, mRecordBases);
    if (upper > 0)
        pack(
            upper, [&realMasks](std::size_t r) { return realMasks[r]; },
            [&realOffsets](std::size_t r) { return realOffsets[r]; }, mUpperBits, mUpperBases);
    mNodes.clear();
    mNodes.shrink_to_fit();
    mNodeMasks = NodeMasks::Shared;
}

GpuTreeTopology packTopologyForGpu(const AdaptiveVoxelTree& tree)
{
    GpuTreeTopology out;
    const auto& ranks = tree.getRanks();
    out.words.reserve(3 * ranks.size() + tree.getTopologyBytes() / sizeof(std::uint32_t));
    for (const VoxelTreeRank& r : ranks)
        out.words.insert(out.words.end(), {r.bitsLo, r.bitsHi, r.base});
    out.recordStart = std::uint32_t(out.words.size());
    if (tree.getNodeMasks() == NodeMasks::Inline) {
        for (const VoxelTreeNode& n : tree.getInlineRecords())
            out.words.insert(out.words.end(), {n.maskLo, n.maskHi, n.offset});
        return out;
    }
    out.words.insert(out.words.end(), tree.getRecordBits().begin(), tree.getRecordBits().end());
    const auto baseStart = std::uint32_t(out.words.size());
    out.words.insert(out.words.end(), tree.getRecordBases().begin(), tree.getRecordBases().end());
    const auto tableStart = std::uint32_t(out.words.size());
    for (const std::uint64_t m : tree.getMaskTable())
        out.words.insert(out.words.end(), {std::uint32_t(m), std::uint32_t(m >> 32)});
    out.masks = glm::ivec4(int(tree.getRecordWidth()), int(baseStart), int(tableStart), 0);
    return out;
}

std::vector<glm::ivec4> AdaptiveVoxelTree::listElementCells() const
{
    std::vector<glm::ivec4> cells(getElementCount());
    const glm::ivec3& roots = mLayout.rootCells;
    for (int z = 0; z < roots.z; ++z)
        for (int y = 0; y < roots.y; ++y)
            for (int x = 0; x < roots.x; ++x)
                cells[std::size_t(x + roots.x * (y + roots.y * z))] = glm::ivec4(x, y, z, 0);
    // Elements are in breadth-first order, so an element's cell is known before its children's;
    // node records are in element order.
    std::size_t record = 0;
    const std::size_t upper = mLevelBegin[std::size_t(mLayout.depth)];
    for (std::size_t i = 0; i < upper; ++i) {
        if (((mRanks[i >> 6].getBits() >> (i & 63u)) & 1u) == 0)
            continue;
        const glm::ivec4 parent = cells[i];
        const VoxelTreeNode node = getRecord(record++);
        std::uint64_t mask = node.getMask();
        std::uint32_t child = node.offset;
        while (mask != 0) {
            const int bit = std::countr_zero(mask);
            mask &= mask - 1;
            const glm::ivec3 c = glm::ivec3(parent) * 4 + glm::ivec3(bit & 3, (bit >> 2) & 3, bit >> 4);
            cells[child++] = glm::ivec4(c, parent.w + 1);
        }
    }
    return cells;
}

AdaptiveVoxelTree::Deepest AdaptiveVoxelTree::findDeepest(const glm::ivec3& leafCell) const
{
    const int depth = mLayout.depth;
    const glm::ivec3 c = glm::clamp(leafCell, glm::ivec3(0), mLayout.getCells(depth) - 1);
    const glm::ivec3 root = c >> (2 * depth);
    std::uint32_t index = std::uint32_t(
        root.x + mLayout.rootCells.x * (root.y + mLayout.rootCells.y * root.z));
    for (int l = 1; l <= depth; ++l) {
        const std::optional<VoxelTreeNode> node = getNode(index);
        const std::uint64_t mask = node ? node->getMask() : 0;
        const int bit = getChildBit(c >> (2 * (depth - l)));
        if (((mask >> bit) & 1u) == 0)
            return {l - 1, std::int64_t(index), mask != 0};
        index = node->offset + std::uint32_t(std::popcount(mask & ((std::uint64_t(1) << bit) - 1)));
    }
    return {depth, std::int64_t(index), false};
}

namespace {

struct StencilBuilder {
    const AdaptiveVoxelTree& tree;
    const TreeQuery& query;
    glm::dvec3 p;
    TreeStencil& out;
    double dropped = 0.0;

    double getCellSize(int level) const
    {
        return query.leafSize * std::ldexp(1.0, 2 * (tree.getDepth() - level));
    }

    void emit(std::uint32_t index, int level, const glm::ivec3& cell, double w)
    {
        if (glm::dot(query.normal, query.normal) > 0.0) {
            const glm::dvec3 x = query.origin + (glm::dvec3(cell) + 0.5) * getCellSize(level);
            const glm::dvec3 d = x - p;
            const double len = glm::length(d);
            if (len > 0.0) {
                const double wrap = 0.5 * (1.0 + glm::dot(query.normal, d) / len);
                w *= std::max(1e-3, wrap * wrap);
            }
        }
        for (int i = 0; i < out.count; ++i)
            if (out.index[std::size_t(i)] == index) {
                out.weight[std::size_t(i)] += float(w);
                return;
            }
        if (out.count == TreeStencil::kMax)
            return; // cannot happen: see kMax
        out.index[std::size_t(out.count)] = index;
        out.weight[std::size_t(out.count)] = float(w);
        ++out.count;
    }

    // Trilinear neighbourhood at `level` of the point q (continuous cell coordinates of that
    // level, cell centres at integer + 0.5), each corner weighted by w times its trilinear weight.
    void addNeighbourhood(int level, const glm::dvec3& q, double w)
    {
        const glm::ivec3 cells = tree.getLayout().getCells(level);
        const glm::dvec3 s = q - 0.5;
        const glm::dvec3 base = glm::floor(s);
        const glm::dvec3 f = s - base;
        for (int corner = 0; corner < 8; ++corner) {
            const glm::ivec3 o(corner & 1, (corner >> 1) & 1, corner >> 2);
            const double cw = (o.x ? f.x : 1.0 - f.x) * (o.y ? f.y : 1.0 - f.y) *
                              (o.z ? f.z : 1.0 - f.z);
            if (cw <= 0.0)
                continue;
            const glm::ivec3 cell = glm::clamp(glm::ivec3(base) + o, glm::ivec3(0), cells - 1);
            addCorner(level, cell, w * cw);
        }
    }

    void addCorner(int level, const glm::ivec3& cell, double w)
    {
        const std::int64_t index = tree.find(level, cell);
        if (index != AdaptiveVoxelTree::kAbsent) {
            emit(std::uint32_t(index), level, cell, w);
            return;
        }
        if (query.mode == TreeInterpolation::Plain || level == 0) {
            dropped += w;
            return;
        }
        // The missing corner takes the value the parent level interpolates at its centre.
        out.levelsUsed = std::max(out.levelsUsed, out.level - level + 2);
        addNeighbourhood(level - 1, (glm::dvec3(cell) + 0.5) * 0.25, w);
    }
};

} // namespace

TreeStencil interpolate(const AdaptiveVoxelTree& tree, const TreeQuery& query, const glm::dvec3& p)
{
    TreeStencil out;
    const int depth = tree.getDepth();
    const glm::dvec3 leafCells(tree.getLayout().getCells(depth));
    glm::dvec3 u = (p - query.origin) / query.leafSize;
    for (int a = 0; a < 3; ++a)
        u[a] = std::isfinite(u[a]) ? std::clamp(u[a], 0.0, leafCells[a] * (1.0 - 1e-12)) : 0.0;
    const AdaptiveVoxelTree::Deepest deepest = tree.findDeepest(glm::ivec3(glm::floor(u)));
    // The level of the neighbourhood: the leaves where the point's leaf exists, else the children
    // of the deepest node holding it when it has any, else that node's own level. Every corner
    // missing there has a complete neighbourhood one level up (the partial dilation).
    out.level = deepest.level == depth ? depth
                                       : (deepest.hasChildren ? deepest.level + 1 : deepest.level);
    StencilBuilder b{tree, query, glm::clamp(p, query.origin, query.origin + leafCells * query.leafSize),
                     out};
    b.addNeighbourhood(out.level, u * std::ldexp(1.0, -2 * (depth - out.level)), 1.0);
    double sum = 0.0;
    for (int i = 0; i < out.count; ++i)
        sum += out.weight[std::size_t(i)];
    if (out.count == 0 || !(sum > 0.0)) {
        // Plain mode with every corner missing: the deepest element holding the point.
        out.count = 1;
        out.index[0] = std::uint32_t(deepest.index);
        out.weight[0] = 1.0f;
        return out;
    }
    for (int i = 0; i < out.count; ++i)
        out.weight[std::size_t(i)] = float(out.weight[std::size_t(i)] / sum);
    return out;
}

} // namespace rtlab::voxelgi
