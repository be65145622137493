#include "voxel_tree_cones.h"

#include "core/error.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>

namespace rtlab::voxelgi {

VoxelTreeCones::VoxelTreeCones(TreeConeSettings settings)
    : mSettings(settings), mCones(ConeSet::make(settings.coneHalfAngleDegrees))
{
    if (mSettings.depth < 1 || mSettings.depth > 6)
        throw Error("adaptive_voxel_tree_cones: depth must be in [1, 6], found " + std::to_string(mSettings.depth));
    if (mSettings.bounces < 1 || mSettings.bounces > 3)
        throw Error("adaptive_voxel_tree_cones: bounces must be in [1, 3], found " +
                    std::to_string(mSettings.bounces));
    mPayload.gathered.clear();
}

void VoxelTreeCones::computeLattice(const glm::dvec3& lo, const glm::dvec3& hi, int resolution, int depth,
                                    double leafSize, glm::dvec3& origin, double& leaf, glm::ivec3& rootCells)
{
    if (!std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z))
        throw Error("adaptive_voxel_tree_cones: the scene's bounds are not finite");
    if (resolution < 1)
        throw Error("adaptive_voxel_tree_cones: resolution must be positive, found " + std::to_string(resolution));
    const glm::dvec3 centre = 0.5 * (lo + hi);
    glm::dvec3 span(0.0);
    if (leafSize > 0.0) {
        if (!std::isfinite(leafSize))
            throw Error("adaptive_voxel_tree_cones: the leaf size must be finite");
        // A cube of `resolution` leaves centred on the box (what lies outside is left out).
        leaf = leafSize;
        span = glm::dvec3(leafSize * double(resolution));
    } else {
        double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z, 0.0});
        if (!(extent > 0.0))
            extent = std::max(1e-6, 1e-6 * glm::length(centre));
        // `resolution` leaves along the longest side, one of them padding on each side.
        leaf = extent / std::max(1.0, double(resolution) - 2.0);
        span = glm::max(hi - lo, glm::dvec3(0.0)) + 2.0 * leaf;
    }
    const double rootSize = leaf * std::ldexp(1.0, 2 * depth);
    for (int a = 0; a < 3; ++a)
        rootCells[a] = std::max(1, int(std::ceil(span[a] / rootSize - 1e-9)));
    origin = centre - 0.5 * glm::dvec3(rootCells) * rootSize;
}

void VoxelTreeCones::build(const glm::dvec3& origin, double leafSize, const glm::ivec3& rootCells,
                           std::vector<SurfaceLeaf> leaves)
{
    if (!(leafSize > 0.0) || !std::isfinite(leafSize) || !std::isfinite(origin.x + origin.y + origin.z))
        throw Error("adaptive_voxel_tree_cones: the lattice needs a finite origin and a positive finite leaf size");
    makeLeavesIsotropic(leaves, "adaptive_voxel_tree_cones");
    VoxelTreeLayout layout;
    layout.rootCells = rootCells;
    layout.depth = mSettings.depth;
    std::vector<glm::ivec3> coords(leaves.size());
    for (std::size_t i = 0; i < leaves.size(); ++i)
        coords[i] = leaves[i].coord;
    mTree.emplace(
        AdaptiveVoxelTree::build(layout, coords, {.dilate = false, .masks = mSettings.nodeMasks}));
    mOrigin = origin;
    mLeafSize = leafSize;
    mBoxSize = glm::dvec3(layout.getCells(mSettings.depth)) * leafSize;
    mLeaves = std::move(leaves);
    // The leaves' element indices; a repeated leaf would give two leaves one element.
    mLeafElement.assign(mLeaves.size(), 0u);
    std::vector<bool> taken(mTree->getElementCount(), false);
    for (std::size_t i = 0; i < mLeaves.size(); ++i) {
        const std::int64_t e = mTree->find(mSettings.depth, mLeaves[i].coord);
        if (e < 0 || taken[std::size_t(e)])
            throw Error("adaptive_voxel_tree_cones: two leaves at (" + std::to_string(mLeaves[i].coord.x) + ", " +
                        std::to_string(mLeaves[i].coord.y) + ", " + std::to_string(mLeaves[i].coord.z) + ")");
        taken[std::size_t(e)] = true;
        mLeafElement[i] = std::uint32_t(e);
    }
    mPayload.gathered.assign(mTree->getElementCount() * kFaceCount, glm::vec4(0.0f));
    for (auto& field : mPayload.fields)
        field.clear();
    for (std::size_t i = 0; i < mLeaves.size(); ++i)
        for (int f = 0; f < kFaceCount; ++f)
            mPayload.gathered[std::size_t(mLeafElement[i]) * kFaceCount + std::size_t(f)].a =
                std::clamp(mLeaves[i].faces[std::size_t(f)].a, 0.0f, 1.0f);
    filterUp([this](std::size_t g) -> float& { return mPayload.gathered[g].a; });
    ++mStamp;
}

template <class Get>
void VoxelTreeCones::filterUp(const Get& get)
{
    // Level by level from the leaves' parents up; a node's 64 children are offset + popcount of
    // the mask bits below theirs, bit = x + 4 (y + 4 z), filterParentFaces<4>'s order.
    for (int level = mSettings.depth - 1; level >= 0; --level) {
        const std::size_t begin = mTree->getLevelBegin(level), end = mTree->getLevelBegin(level + 1);
        tbb::parallel_for(begin, end, [&](std::size_t n) {
            std::array<std::int64_t, 64> children;
            const std::optional<VoxelTreeNode> node = mTree->getNode(std::uint32_t(n));
            const std::uint64_t mask = node ? node->getMask() : 0;
            std::uint32_t next = node ? node->offset : 0;
            for (int bit = 0; bit < 64; ++bit)
                children[std::size_t(bit)] = ((mask >> bit) & 1u) ? std::int64_t(next++) : -1;
            filterParentFaces<4>(children.data(), n, mPayload.gathered, get);
        });
    }
}

void VoxelTreeCones::injectLight(const scene::RenderScene& geometry)
{
    if (!mTree)
        return;
    LeafLightSettings s;
    s.origin = mOrigin;
    s.leafSize = mLeafSize;
    s.bounces = mSettings.bounces;
    s.startOffset = mSettings.injectOffset;
    s.stepScale = mSettings.stepScale;
    injectLeafLight(geometry, mCones, mLeaves, mLeafElement, s, mPayload, SparseFieldSampler<VoxelTreeCones>{this}, [this](int field) {
        auto& light = mPayload.fields[std::size_t(field)];
        filterUp([&light](std::size_t g) -> glm::vec3& { return light[g]; });
    });
    ++mStamp;
}

template <bool Gathered>
bool VoxelTreeCones::sampleAt(const glm::dvec3& p, double diameter, const glm::dvec3& dir, ConeSample& out) const
{
    if (!mTree)
        return false;
    const glm::dvec3 rel = (p - mOrigin) / mBoxSize;
    if (!(rel.x >= 0.0 && rel.y >= 0.0 && rel.z >= 0.0 && rel.x <= 1.0 && rel.y <= 1.0 && rel.z <= 1.0))
        return false;
    out.clear();
    const int depth = mSettings.depth;
    // m = log4(d / leaf) levels above the leaves, linear between the two levels around it.
    const double m = std::min(double(depth), diameter > mLeafSize ? 0.5 * std::log2(diameter / mLeafSize) : 0.0);
    const int m0 = int(std::floor(m));
    const float frac = float(m - m0);
    const auto level = [&](int l, float weight) {
        sampleSparseLevel<Gathered>([&](const glm::ivec3& c) { return mTree->find(l, c); }, mOrigin,
                                    mLeafSize * std::ldexp(1.0, 2 * (depth - l)), mPayload, p, dir, weight, out);
    };
    level(depth - m0, 1.0f - frac);
    if (frac > 0.0f && m0 < depth)
        level(depth - m0 - 1, frac);
    out.voxelSize = mLeafSize * std::exp2(2.0 * m);
    return true;
}

bool VoxelTreeCones::sampleFields(const glm::dvec3& p, double diameter, const glm::dvec3& dir, ConeSample& out) const
{
    return sampleAt<false>(p, diameter, dir, out);
}

bool VoxelTreeCones::sampleGathered(const glm::dvec3& p, double diameter, const glm::dvec3& dir,
                                    ConeSample& out) const
{
    return sampleAt<true>(p, diameter, dir, out);
}

bool VoxelTreeCones::preparePixel(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& origin, glm::dvec3& n,
                                  ConeMarchSettings& march) const
{
    glm::dvec3 p;
    if (!mTree || !readPixelSurface(gbuffer, x, y, p, n))
        return false;
    const glm::dvec3 rel = (p - mOrigin) / mBoxSize;
    if (!(rel.x >= 0.0 && rel.y >= 0.0 && rel.z >= 0.0 && rel.x <= 1.0 && rel.y <= 1.0 && rel.z <= 1.0))
        return false;
    march.stepScale = mSettings.stepScale;
    march.startDistance = mSettings.startOffset * mLeafSize;
    march.skyStartDistance = mSettings.skyStart * mLeafSize;
    march.skyOpticalDepth = mSettings.skyOpticalDepth;
    march.skyPlaneNormal = n;
    march.skyPlaneHeight = 0.5 * mSettings.startOffset * mLeafSize;
    origin = p + n * (0.5 * mSettings.startOffset * mLeafSize);
    return true;
}

void VoxelTreeCones::gatherCones(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                                        const ConeSkyOutput* sky)
{
    mMeanStepsPerCone = traceSparsePixelCones(*this, gbuffer, out, sky);
}

void VoxelTreeCones::gatherRays(const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out,
                                   const scene::Sky* sky) const
{
    traceSparsePixelRays(*this, gbuffer, rays, out, sky);
}

std::size_t VoxelTreeCones::getPayloadBytes() const
{
    return mPayload.gathered.size() * sizeof(glm::vec4) + mLeaves.size() * sizeof(SurfaceLeaf) +
           mLeafElement.size() * sizeof(std::uint32_t);
}

} // namespace rtlab::voxelgi
