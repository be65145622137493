#include "sparse_voxel_octree.h"

#include "core/error.h"

#include <glm/common.hpp>
#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <numeric>

namespace rtlab::voxelgi {

namespace {

// Interleaves the bits of x, y, z (x lowest): the octant of a child is its code's lowest 3 bits.
std::uint64_t encodeMorton(const glm::ivec3& c)
{
    std::uint64_t code = 0;
    for (int b = 0; b < 21; ++b)
        code |= ((std::uint64_t(c.x) >> b) & 1u) << (3 * b) |
                ((std::uint64_t(c.y) >> b) & 1u) << (3 * b + 1) |
                ((std::uint64_t(c.z) >> b) & 1u) << (3 * b + 2);
    return code;
}

} // namespace

SparseVoxelOctree::SparseVoxelOctree(OctreeSettings settings)
    : mSettings(settings), mCones(ConeSet::make(settings.coneHalfAngleDegrees))
{
    const int r = mSettings.resolution;
    if (r < 2 || r > 4096 || !std::has_single_bit(unsigned(r)))
        throw Error("svo: resolution must be a power of two in [2, 4096], found " + std::to_string(r));
    if (mSettings.bounces < 1 || mSettings.bounces > 3)
        throw Error("svo: bounces must be in [1, 3], found " + std::to_string(mSettings.bounces));
    if (mSettings.chunk < 1 || !std::has_single_bit(unsigned(mSettings.chunk)))
        throw Error("svo: chunk must be a power of two, found " + std::to_string(mSettings.chunk));
    mDepth = std::countr_zero(unsigned(r));
    mTopology.depth = mDepth;
    mTopology.child.assign(1, 0u);
    mPayload.gathered.assign(kFaceCount, glm::vec4(0.0f));
}

void SparseVoxelOctree::computeCube(const glm::dvec3& lo, const glm::dvec3& hi, int resolution,
                                    glm::dvec3& origin, double& side, double leafSize)
{
    if (leafSize > 0.0) {
        if (!std::isfinite(leafSize) || !std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z))
            throw Error("svo: the leaf size and the scene's bounds must be finite");
        side = leafSize * double(resolution);
        origin = 0.5 * (lo + hi) - 0.5 * side;
        return;
    }
    double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 0.0});
    if (!std::isfinite(extent))
        throw Error("svo: the scene's bounds are not finite");
    const glm::dvec3 centre = 0.5 * (lo + hi);
    if (!(extent > 0.0))
        extent = std::max(1e-6, 1e-6 * glm::length(centre));
    // One leaf of padding on each side: v = extent / (resolution - 2) (two leaves for tiny grids).
    const double leaf = extent / std::max(1.0, double(resolution) - 2.0);
    side = leaf * double(resolution);
    origin = centre - 0.5 * side;
}

std::vector<OctreeLeaf> SparseVoxelOctree::voxelizeLeaves(const scene::RenderScene& geometry,
                                                          const glm::dvec3& origin, double side,
                                                          const OctreeSettings& settings)
{
    LeafLattice lattice;
    lattice.origin = origin;
    lattice.leafSize = side / double(settings.resolution);
    lattice.cells = glm::ivec3(settings.resolution);
    lattice.supersampling = settings.supersampling;
    lattice.chunk = settings.chunk;
    lattice.innerLayers = settings.innerLayers;
    return voxelizeSurfaceLeaves(geometry, lattice, "svo");
}

OctreeTopology OctreeTopology::build(int depth, const std::vector<glm::ivec3>& leaves)
{
    const int R = 1 << depth;
    std::vector<std::uint64_t> codes(leaves.size());
    for (std::size_t i = 0; i < leaves.size(); ++i) {
        const glm::ivec3 c = leaves[i];
        if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, glm::ivec3(R))))
            throw Error("svo: leaf (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " +
                        std::to_string(c.z) + ") is outside the " + std::to_string(R) + "^3 lattice");
        codes[i] = encodeMorton(c);
    }
    std::vector<std::uint32_t> order(leaves.size());
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return codes[a] < codes[b]; });
    for (std::size_t i = 1; i < order.size(); ++i)
        if (codes[order[i]] == codes[order[i - 1]])
            throw Error("svo: two leaves at the same coordinates");

    // Top-down, level by level: every node that holds a leaf below it gets a tile of 8 children.
    OctreeTopology t;
    t.depth = depth;
    t.child.assign(1, 0u);
    t.levelNodes.assign(std::size_t(depth), {});
    std::vector<std::uint64_t> prefixes; // of the present nodes of the current level, ascending
    std::vector<std::uint32_t> nodes;    // their indices
    if (!leaves.empty()) {
        prefixes = {0};
        nodes = {0};
    }
    for (int level = 0; level < depth && !nodes.empty(); ++level) {
        t.levelNodes[std::size_t(level)] = nodes;
        if (t.child.size() + 8 * nodes.size() > (std::size_t(1) << 31))
            throw Error("svo: more than 2^31 nodes");
        std::vector<std::uint32_t> tiles(nodes.size());
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            tiles[i] = std::uint32_t(t.child.size());
            t.child[nodes[i]] = tiles[i];
            t.child.resize(t.child.size() + 8, 0u);
        }
        const int shift = 3 * (depth - level - 1);
        std::vector<std::uint64_t> nextPrefixes;
        std::vector<std::uint32_t> nextNodes;
        std::size_t parent = 0;
        for (const std::uint32_t leaf : order) {
            const std::uint64_t q = codes[leaf] >> shift;
            if (!nextPrefixes.empty() && nextPrefixes.back() == q)
                continue;
            while (prefixes[parent] != (q >> 3))
                ++parent;
            nextPrefixes.push_back(q);
            nextNodes.push_back(tiles[parent] + std::uint32_t(q & 7u));
        }
        prefixes = std::move(nextPrefixes);
        nodes = std::move(nextNodes);
    }
    // At the leaf level the present nodes are the leaves, in Morton order.
    t.leafNode.assign(leaves.size(), 0u);
    if (depth > 0)
        for (std::size_t i = 0; i < order.size(); ++i)
            t.leafNode[order[i]] = nodes[i];
    return t;
}

void SparseVoxelOctree::build(const glm::dvec3& origin, double side, std::vector<OctreeLeaf> leaves)
{
    if (!(side > 0.0) || !std::isfinite(side) || !std::isfinite(origin.x + origin.y + origin.z))
        throw Error("svo: the cube must have a finite position and a positive finite side");
    makeLeavesIsotropic(leaves, "svo");
    std::vector<glm::ivec3> coords(leaves.size());
    for (std::size_t i = 0; i < leaves.size(); ++i)
        coords[i] = leaves[i].coord;
    mTopology = OctreeTopology::build(mDepth, coords);
    mOrigin = origin;
    mSide = side;
    mLeaves = std::move(leaves);
    mPayload.gathered.assign(mTopology.child.size() * kFaceCount, glm::vec4(0.0f));
    for (std::size_t i = 0; i < mLeaves.size(); ++i)
        for (int f = 0; f < kFaceCount; ++f)
            mPayload.gathered[std::size_t(mTopology.leafNode[i]) * kFaceCount + std::size_t(f)].a =
                std::clamp(mLeaves[i].faces[std::size_t(f)].a, 0.0f, 1.0f);
    filterAlphaUp();
    for (auto& field : mPayload.fields)
        field.clear();
    mNodeCells.clear();
    mGatheredBricks.clear();
    if (mSettings.cornerBricks) {
        // Every node's cell and level, top down (a tile's children are tile + octant).
        mNodeCells.assign(mTopology.child.size(), glm::ivec4(0));
        for (int level = 0; level < mDepth; ++level)
            for (const std::uint32_t node : mTopology.levelNodes[std::size_t(level)]) {
                const std::uint32_t tile = mTopology.child[node];
                for (int octant = 0; octant < 8; ++octant)
                    mNodeCells[tile + std::uint32_t(octant)] =
                        glm::ivec4(glm::ivec3(mNodeCells[node]) * 2 +
                                       glm::ivec3(octant & 1, (octant >> 1) & 1, octant >> 2),
                                   level + 1);
            }
        makeGatheredBricks();
    }
    ++mStamp;
}

template <class T, class Get>
void SparseVoxelOctree::makeBricks(const Get& get, std::vector<T>& bricks) const
{
    // Corner (d) of node cell c is the point between the 8 cells c + d - 1 + o, o in {0, 1}^3:
    // its value is their mean, an absent cell empty (the trilinear sample of the per-node field
    // at that point).
    const std::size_t nodes = mNodeCells.size();
    bricks.assign(nodes * kFaceCount * 8, T(0.0f));
    tbb::parallel_for(std::size_t(0), nodes, [&](std::size_t n) {
        const glm::ivec3 cell(mNodeCells[n]);
        const int level = mNodeCells[n].w;
        std::array<std::int64_t, 27> around;
        for (int k = 0; k < 27; ++k)
            around[std::size_t(k)] =
                mTopology.find(level, cell + glm::ivec3(k % 3 - 1, (k / 3) % 3 - 1, k / 9 - 1));
        for (int corner = 0; corner < 8; ++corner) {
            const glm::ivec3 d(corner & 1, (corner >> 1) & 1, corner >> 2);
            for (int f = 0; f < kFaceCount; ++f) {
                T sum(0.0f);
                for (int o = 0; o < 8; ++o) {
                    const glm::ivec3 q = d + glm::ivec3(o & 1, (o >> 1) & 1, o >> 2); // in [0, 2]
                    const std::int64_t e = around[std::size_t(q.x + 3 * q.y + 9 * q.z)];
                    if (e >= 0)
                        sum += get(std::size_t(e) * kFaceCount + std::size_t(f));
                }
                bricks[(n * kFaceCount + std::size_t(f)) * 8 + std::size_t(corner)] = sum * 0.125f;
            }
        }
    });
}

void SparseVoxelOctree::makeGatheredBricks()
{
    makeBricks<glm::vec4>([this](std::size_t g) { return mPayload.gathered[g]; }, mGatheredBricks);
}

template <class Get>
void SparseVoxelOctree::filterUp(const Get& get)
{
    // Per parent: its tile of 2x2x2 children (sparse_leaves.h filterParentFaces); the children's
    // levels are final before their parents'.
    for (int level = mDepth - 1; level >= 0; --level) {
        const auto& nodes = mTopology.levelNodes[std::size_t(level)];
        tbb::parallel_for(std::size_t(0), nodes.size(), [&](std::size_t i) {
            const std::uint32_t node = nodes[i];
            const std::uint32_t tile = mTopology.child[node];
            std::array<std::int64_t, 8> children;
            for (std::uint32_t octant = 0; octant < 8; ++octant)
                children[octant] = std::int64_t(tile + octant);
            filterParentFaces<2>(children.data(), node, mPayload.gathered, get);
        });
    }
}

void SparseVoxelOctree::filterAlphaUp()
{
    filterUp([this](std::size_t i) -> float& { return mPayload.gathered[i].a; });
}

void SparseVoxelOctree::filterFieldUp(int field)
{
    auto& light = mPayload.fields[std::size_t(field)];
    filterUp([&light](std::size_t i) -> glm::vec3& { return light[i]; });
}

void SparseVoxelOctree::injectLight(const scene::RenderScene& geometry)
{
    LeafLightSettings s;
    s.origin = mOrigin;
    s.leafSize = getLeafSize();
    s.bounces = mSettings.bounces;
    s.startOffset = mSettings.injectOffset;
    s.stepScale = mSettings.stepScale;
    injectLeafLight(geometry, mCones, mLeaves, mTopology.leafNode, s, mPayload,
                    SparseFieldSampler<SparseVoxelOctree>{this}, [this](int field) {
                        filterFieldUp(field);
                        if (mSettings.cornerBricks) {
                            const auto& light = mPayload.fields[std::size_t(field)];
                            makeBricks<glm::vec3>([&light](std::size_t g) { return light[g]; },
                                                  mFieldBricks[std::size_t(field)]);
                        }
                    });
    for (auto& bricks : mFieldBricks)
        bricks = {};
    if (mSettings.cornerBricks)
        makeGatheredBricks();
    ++mStamp;
}

template <bool Gathered>
bool SparseVoxelOctree::sampleAt(const glm::dvec3& p, double diameter, const glm::dvec3& dir,
                                 ConeSample& out) const
{
    const glm::dvec3 rel = (p - mOrigin) / mSide;
    if (!(rel.x >= 0.0 && rel.y >= 0.0 && rel.z >= 0.0 && rel.x <= 1.0 && rel.y <= 1.0 && rel.z <= 1.0))
        return false;
    out.clear();
    const double leaf = getLeafSize();
    // The level whose voxels are as wide as the footprint (m levels above the leaves), and the
    // linear blend with the next coarser one (quadrilinear).
    const double m = std::min(double(mDepth), diameter > leaf ? std::log2(diameter / leaf) : 0.0);
    const int m0 = int(std::floor(m));
    const float frac = float(m - m0);
    const auto level = [&](int l, float weight) {
        if (mSettings.cornerBricks)
            sampleBrickLevel<Gathered>(l, p, dir, weight, out);
        else
            sampleSparseLevel<Gathered>([&](const glm::ivec3& c) { return mTopology.find(l, c); },
                                        mOrigin, mSide / double(std::int64_t(1) << l), mPayload, p,
                                        dir, weight, out);
    };
    level(mDepth - m0, 1.0f - frac);
    if (frac > 0.0f && m0 < mDepth)
        level(mDepth - m0 - 1, frac);
    out.voxelSize = leaf * std::exp2(m);
    return true;
}

template <bool Gathered>
void SparseVoxelOctree::sampleBrickLevel(int level, const glm::dvec3& p, const glm::dvec3& dir,
                                         float weight, ConeSample& out) const
{
    const double cells = double(std::int64_t(1) << level);
    const glm::dvec3 q = (p - mOrigin) / mSide * cells;
    // p lies in the cube (sampleAt checked): its cell, the last one on the far faces.
    const glm::ivec3 cell =
        glm::clamp(glm::ivec3(glm::floor(q)), glm::ivec3(0), glm::ivec3(int(cells) - 1));
    const glm::dvec3 t = glm::clamp(q - glm::dvec3(cell), 0.0, 1.0);
    const std::int64_t node = mTopology.find(level, cell);
    if (node < 0)
        return; // an empty region
    float cornerWeight[8];
    for (int corner = 0; corner < 8; ++corner)
        cornerWeight[corner] =
            float(((corner & 1) ? t.x : 1.0 - t.x) * (((corner >> 1) & 1) ? t.y : 1.0 - t.y) *
                  ((corner >> 2) ? t.z : 1.0 - t.z));
    for (int a = 0; a < 3; ++a) {
        const float aw = weight * float(dir[a] * dir[a]);
        if (aw == 0.0f)
            continue;
        const std::size_t brick =
            (std::size_t(node) * kFaceCount + std::size_t(getFaceSeen(a, dir[a]))) * 8;
        for (int corner = 0; corner < 8; ++corner) {
            const float w = aw * cornerWeight[corner];
            const glm::vec4& v = mGatheredBricks[brick + std::size_t(corner)];
            out.alpha += w * v.a;
            if (out.wantsDepth)
                out.depth += w * computeOpticalDepth(v.a);
            if constexpr (Gathered) {
                out.light[kDirect] += w * glm::vec3(v);
            } else {
                for (int field = 0; field < kFieldCount; ++field)
                    if (!mFieldBricks[std::size_t(field)].empty())
                        out.light[std::size_t(field)] +=
                            w * mFieldBricks[std::size_t(field)][brick + std::size_t(corner)];
            }
        }
    }
}

bool SparseVoxelOctree::sampleFields(const glm::dvec3& p, double diameter, const glm::dvec3& dir,
                                     ConeSample& out) const
{
    return sampleAt<false>(p, diameter, dir, out);
}

bool SparseVoxelOctree::sampleGathered(const glm::dvec3& p, double diameter, const glm::dvec3& dir,
                                       ConeSample& out) const
{
    return sampleAt<true>(p, diameter, dir, out);
}

bool SparseVoxelOctree::preparePixel(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& origin,
                                     glm::dvec3& n, ConeMarchSettings& march) const
{
    glm::dvec3 p;
    if (!readPixelSurface(gbuffer, x, y, p, n))
        return false;
    const glm::dvec3 rel = (p - mOrigin) / mSide;
    if (!(rel.x >= 0.0 && rel.y >= 0.0 && rel.z >= 0.0 && rel.x <= 1.0 && rel.y <= 1.0 && rel.z <= 1.0))
        return false;
    // Start a leaf out, along the normal and along the cone (as the cascades' finest level).
    const double v = getLeafSize();
    march.stepScale = mSettings.stepScale;
    march.startDistance = mSettings.startOffset * v;
    march.skyStartDistance = mSettings.skyStart * v;
    march.skyOpticalDepth = mSettings.skyOpticalDepth;
    march.skyPlaneNormal = n;
    march.skyPlaneHeight = 0.5 * mSettings.startOffset * v;
    origin = p + n * (0.5 * mSettings.startOffset * v);
    return true;
}

void SparseVoxelOctree::gatherCones(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                                           const ConeSkyOutput* sky)
{
    mMeanStepsPerCone = traceSparsePixelCones(*this, gbuffer, out, sky);
}

void SparseVoxelOctree::gatherRays(const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out,
                                   const scene::Sky* sky) const
{
    traceSparsePixelRays(*this, gbuffer, rays, out, sky);
}

std::size_t SparseVoxelOctree::getPayloadBytes() const
{
    return (mPayload.gathered.size() + mGatheredBricks.size()) * sizeof(glm::vec4) +
           mLeaves.size() * sizeof(OctreeLeaf) + mTopology.leafNode.size() * sizeof(std::uint32_t) +
           mNodeCells.size() * sizeof(glm::ivec4);
}

} // namespace rtlab::voxelgi
