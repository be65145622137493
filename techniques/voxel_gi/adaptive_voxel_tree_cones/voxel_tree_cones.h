#pragma once
// Quantum Break's 64-ary adaptive voxel tree (voxel_tree.h) as the sparse structure of the
// family's 16-cone tracing, like-for-like with cascades and the sparse octree: the same leaves
// (the surface voxels and the inner layer, sparse_leaves.h), the same light injection, the same
// pixel gather; only the structure differs.
//
//  * Topology: the tree of voxel_tree.h over the leaves (dense root cells, 4x4x4 children per
//    node, 64-bit mask + offset, child index = offset + popcount). Built without the partial
//    dilation: a cone sample treats an absent element as empty, which is exact (it holds no
//    geometry), so the dilated elements would only cost memory.
//  * Payload, indexed by the tree's element index (the talk's "payload arrays indexed by the
//    child index"): per element and face the gathered light and occupancy, premultiplied
//    (sparse_leaves.h SparsePayload); interior elements filtered from their 64 children per face
//    (16 columns of 4 composited front to back, averaged).
//  * Sampling at a cone footprint d: the level whose cells are d wide, m = log4(d / leaf) levels
//    above the leaves, trilinear at the two levels around it and linear in m between them
//    (levels are 4x apart, so the blend spans a factor 4 of footprint where the octree's spans 2).

#include "voxel_tree.h"

#include "families/voxel_gi/cone_tracing.h"
#include "families/voxel_gi/sparse_leaves.h"
#include "core/image.h"
#include "scene/gbuffer.h"
#include "scene/render_scene.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace rtlab::voxelgi {

struct TreeConeSettings {
    int depth = 3;          //!< levels below the root cells (4^depth leaves per root cell and axis)
    int supersampling = 4;  //!< voxelization rays per leaf column and axis, per side
    int bounces = 2;        //!< reflections gathered at the pixel (1..3)
    double coneHalfAngleDegrees = 29.0;
    double startOffset = 4.0; //!< leaves: the pixel cones' start distance and origin offset along the normal
    double injectOffset = 4.0; //!< leaves: the same for the leaves' cones of light injection
    double skyStart = 8.0;    //!< leaves along a pixel cone from which its voxels shadow the sky
    bool skyOpticalDepth = false; //!< cone_tracing.h ConeMarchSettings::skyOpticalDepth
    double stepScale = 0.5;   //!< march step / size of the voxels sampled
    int chunk = 32;           //!< leaves per side of the blocks voxelized independently
    int innerLayers = 1;      //!< layers of solid leaves inside closed surfaces (sparse_leaves.h)
    NodeMasks nodeMasks =
        NodeMasks::Shared; //!< where the node records keep their masks (voxel_tree.h)
};

class VoxelTreeCones {
public:
    explicit VoxelTreeCones(TreeConeSettings settings);

    //! The lattice for a scene with bounds [lo, hi]: `resolution` leaves along the box's longest
    //! side plus one leaf of padding on every side, or, for leafSize > 0, leaves of that size with
    //! the lattice centred on the box; root cells of 4^depth leaves cover it. Throws rtlab::Error
    //! for non-finite bounds or leaf size.
    static void computeLattice(const glm::dvec3& lo, const glm::dvec3& hi, int resolution, int depth,
                               double leafSize, glm::dvec3& origin, double& leaf, glm::ivec3& rootCells);

    //! Builds the tree over `leaves` (coordinates in the lattice of `rootCells` root cells, unique)
    //! and filters their occupancy up. Throws rtlab::Error for a leaf outside the lattice, a
    //! repeated leaf, or a bad layout.
    void build(const glm::dvec3& origin, double leafSize, const glm::ivec3& rootCells,
               std::vector<SurfaceLeaf> leaves);
    //! Light injection: sparse_leaves.h injectLeafLight through the tree.
    void injectLight(const scene::RenderScene& geometry);

    const TreeConeSettings& getSettings() const { return mSettings; }
    const ConeSet& getCones() const { return mCones; }
    const AdaptiveVoxelTree* getTree() const { return mTree ? &*mTree : nullptr; }
    const std::vector<SurfaceLeaf>& getLeaves() const { return mLeaves; }
    const std::vector<glm::vec4>& getGathered() const { return mPayload.gathered; }
    glm::dvec3 getOrigin() const { return mOrigin; }
    double getLeafSize() const { return mLeafSize; }
    glm::dvec3 getBoxSize() const { return mBoxSize; } //!< the lattice's extent
    //! [element * 6 + face]: the emitted radiance premultiplied by the occupancy, for the pixels'
    //! cones that meet emitters; empty when no leaf emits.
    const std::vector<glm::vec3>& getEmission() const { return mPayload.fields[kEmission]; }
    std::uint64_t getStamp() const { return mStamp; }  //!< changes when the tree or its light change
    //! Filtered occupancy of `face` of element `element`.
    float getAlpha(std::size_t element, int face) const
    {
        return mPayload.gathered[element * kFaceCount + std::size_t(face)].a;
    }

    //! Quadrilinear sample (see the header comment). False outside the lattice.
    bool sampleFields(const glm::dvec3& p, double diameter, const glm::dvec3& dir, ConeSample& out) const;
    bool sampleGathered(const glm::dvec3& p, double diameter, const glm::dvec3& dir, ConeSample& out) const;

    //! The radiance of each of the 16 cones at every pixel, [pixel * 16 + cone] (pixel_cones.h).
    //! With `sky`, also the sky and emitters each cone sees (pixel_cones.h ConeSkyOutput).
    void gatherCones(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                     const ConeSkyOutput* sky = nullptr);
    //! Zero-aperture rays through the leaves (the error split of voxel_gi.h traceVoxelRays).
    //! With `sky`: the sky and emitters the rays see (pixel_cones.h traceGBufferRays).
    void gatherRays(const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out,
                    const scene::Sky* sky = nullptr) const;
    bool preparePixel(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& origin, glm::dvec3& n,
                      ConeMarchSettings& march) const;

    std::size_t getTopologyBytes() const { return mTree ? mTree->getTopologyBytes() : 0; }
    //! Kept between frames: the gathered light and occupancy of every element, the leaves'
    //! volumetric G-buffer and their element indices.
    std::size_t getPayloadBytes() const;
    double getMeanStepsPerCone() const { return mMeanStepsPerCone; }

private:
    template <bool Gathered>
    bool sampleAt(const glm::dvec3& p, double diameter, const glm::dvec3& dir, ConeSample& out) const;
    template <class Get>
    void filterUp(const Get& get);

    TreeConeSettings mSettings;
    ConeSet mCones;
    std::optional<AdaptiveVoxelTree> mTree;
    glm::dvec3 mOrigin{0.0};
    double mLeafSize = 1.0;
    glm::dvec3 mBoxSize{0.0};
    std::vector<SurfaceLeaf> mLeaves;
    std::vector<std::uint32_t> mLeafElement; //!< [leaf]: its element index in the tree
    SparsePayload mPayload;
    double mMeanStepsPerCone = 0.0;
    std::uint64_t mStamp = 0;
};

} // namespace rtlab::voxelgi
