#pragma once
// The sparse voxel octree of Crassin et al., "Interactive Indirect Illumination Using Voxel Cone
// Tracing", Pacific Graphics 2011 (section 3, "Our hierarchical voxel structure"; section 4,
// "Voxel cone tracing"), on the voxel_gi family's machinery (voxelize.h, cone_tracing.h).
//
// Structure (the paper's node pool):
//  * A cube over the scene's box, split in 2x2x2 down to `resolution`^3 leaves. Only the nodes
//    that hold geometry are subdivided: a subdivided node points to a tile of 8 consecutive
//    child nodes (its children are tile + octant, octant = x | y << 1 | z << 2); an empty or
//    deepest node points to nothing. One 32-bit child pointer per node is the whole topology.
//  * The leaves are the voxel fragments: the surface voxels of the family's voxelization
//    (albedo and emission per axis face, occupancy, normal), plus the layer of solid voxels just
//    inside closed surfaces (the family's solid voxelization, "surface attributes propagated one
//    layer inward"), which mirror the light of the surface leaf beside them. A surface one leaf
//    thick, trilinearly filtered, lets e^-2 (13.5 %) of a ray through (the integral of
//    ln(1 - tent)); two layers stop it, so closed walls do not leak at the finest level. The
//    solid interior beyond that layer is not stored (the paper's octree holds surfaces).
//  * Payload per node and face (the paper's anisotropic voxels, section 5.1 of Crassin's thesis):
//    the occupancy and the light buffers of cone_tracing.h, premultiplied. An interior node's
//    face is filtered bottom-up from its 8 children: along the face's axis the two children of
//    each of the 4 columns are composited front to back as the face's viewer sees them, and the
//    4 columns averaged ("mipmapping ... anisotropic", section 5).
//  * Sampling at a point for a cone footprint d: the level whose voxels are d wide, trilinear
//    between the 8 voxel centres around the point at that level and linear between the two
//    levels around d (quadrilinear, section 4). Voxels that do not exist are empty.
// One value per node by default: a trilinear sample descends the tree once per corner. With
// `cornerBricks` (the paper's bricks with shared borders, section 3: "bricks of voxels ... the
// voxel centers are located at the node corners" in their 2^3 form) every node also keeps a
// 2x2x2 brick per face, the values at its 8 corners. A corner's value is the mean of the 8 node
// centres around it at the node's level (absent nodes empty): the one-value-per-node field
// sampled trilinearly at the corner, so neighbouring bricks share their border values and the
// field stays continuous across nodes that exist. A sample is then one descent to the node
// holding the point and a trilinear blend of its brick: 8x the payload for 1/8 of the descents.
// A point in an absent node is empty (the paper's empty regions), where the per-node sample
// still blends in the centres of the existing neighbours.

#include "families/voxel_gi/cone_tracing.h"
#include "families/voxel_gi/sparse_leaves.h"
#include "families/voxel_gi/voxelize.h"
#include "core/image.h"
#include "scene/gbuffer.h"
#include "scene/render_scene.h"

#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace rtlab::voxelgi {

struct OctreeSettings {
    int resolution = 64;    //!< leaves along the cube's side, a power of two in [2, 4096]
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
    bool cornerBricks = false; //!< 2^3 bricks per node and face (see the header comment)
};

//! The octree's topology alone (the node pool of the paper): what every payload is indexed by.
struct OctreeTopology {
    int depth = 0;                      //!< levels below the root (the leaves are at `depth`)
    std::vector<std::uint32_t> child;   //!< [node]: first of its 8 children, 0 = none (root = 0)
    std::vector<std::vector<std::uint32_t>> levelNodes; //!< [level < depth]: the subdivided nodes
    std::vector<std::uint32_t> leafNode; //!< [i]: the node of leaf coordinate i of the input

    //! The tree over `leaves` (coordinates in [0, 2^depth), unique, any order), built top-down
    //! level by level from their Morton order. Throws rtlab::Error for a coordinate outside the
    //! lattice or repeated, or more than 2^31 nodes.
    static OctreeTopology build(int depth, const std::vector<glm::ivec3>& leaves);

    //! The node holding voxel `coord` of `level` (0 = the root, depth = the leaves), or -1 when
    //! the voxel is outside the lattice or in an empty region.
    std::int64_t find(int level, const glm::ivec3& coord) const
    {
        if (coord.x < 0 || coord.y < 0 || coord.z < 0 || (coord.x >> level) != 0 ||
            (coord.y >> level) != 0 || (coord.z >> level) != 0)
            return -1;
        std::uint32_t node = 0;
        for (int k = level - 1; k >= 0; --k) {
            const std::uint32_t first = child[node];
            if (first == 0)
                return -1;
            node = first + std::uint32_t(((coord.x >> k) & 1) | (((coord.y >> k) & 1) << 1) |
                                         (((coord.z >> k) & 1) << 2));
        }
        return std::int64_t(node);
    }
    std::size_t getBytes() const { return child.size() * sizeof(std::uint32_t); }
};

//! One surface voxel of the scene: the octree's input (a "voxel fragment").
using OctreeLeaf = SurfaceLeaf;

class SparseVoxelOctree {
public:
    explicit SparseVoxelOctree(OctreeSettings settings);

    //! The cube a scene with bounds [lo, hi] is built in: the box padded by one leaf on every
    //! side, or, for `leafSize` > 0, resolution leaves of that size centred on the box (geometry
    //! outside it is left out).
    static void computeCube(const glm::dvec3& lo, const glm::dvec3& hi, int resolution,
                            glm::dvec3& origin, double& side, double leafSize = 0.0);
    //! The surface voxels of `geometry` in the cube (origin, side), voxelized block by block.
    static std::vector<OctreeLeaf> voxelizeLeaves(const scene::RenderScene& geometry,
                                                  const glm::dvec3& origin, double side,
                                                  const OctreeSettings& settings);

    //! Builds the tree over the cube (origin, side) from its leaves (any order; coordinates in
    //! [0, resolution), unique) and filters their occupancy and emission up the tree. Throws
    //! rtlab::Error for coordinates outside the lattice or repeated.
    void build(const glm::dvec3& origin, double side, std::vector<OctreeLeaf> leaves);
    //! Light injection: `bounces` passes (direct, then each bounce from the previous buffer),
    //! each cone traced from every leaf through the tree, then filtered up the tree.
    void injectLight(const scene::RenderScene& geometry);

    const OctreeSettings& getSettings() const { return mSettings; }
    const ConeSet& getCones() const { return mCones; }
    int getDepth() const { return mDepth; }
    glm::dvec3 getOrigin() const { return mOrigin; }
    double getSide() const { return mSide; }
    double getLeafSize() const { return mSide / double(mSettings.resolution); }
    std::size_t getNodeCount() const { return mTopology.child.size(); }
    const std::vector<OctreeLeaf>& getLeaves() const { return mLeaves; }
    //! [node]: index of the first of its 8 children, 0 when it has none (the root is node 0).
    const std::vector<std::uint32_t>& getChildPointers() const { return mTopology.child; }
    //! [node * 6 + face]: rgb = the light a pixel gathers (the reflected fields up to `bounces`,
    //! premultiplied; 0 until injectLight), a = occupancy (filtered from the leaves by build).
    const std::vector<glm::vec4>& getGathered() const { return mPayload.gathered; }
    //! With corner bricks: [(node * 6 + face) * 8 + corner], corner = x | y << 1 | z << 2, the
    //! gathered light and occupancy at the node's corners (empty without bricks).
    const std::vector<glm::vec4>& getGatheredBricks() const { return mGatheredBricks; }
    //! [element * 6 + face]: the emitted radiance premultiplied by the occupancy, for the pixels'
    //! cones that meet emitters; empty when no leaf emits.
    const std::vector<glm::vec3>& getEmission() const { return mPayload.fields[kEmission]; }
    std::uint64_t getStamp() const { return mStamp; } //!< changes when the tree or its light change

    //! The node holding voxel `coord` of `level`, or -1 (OctreeTopology::find).
    std::int64_t findNode(int level, const glm::ivec3& coord) const { return mTopology.find(level, coord); }
    //! Occupancy of `face` of a node (filtered for interior nodes).
    float getAlpha(std::size_t node, int face) const
    {
        return mPayload.gathered[node * kFaceCount + std::size_t(face)].a;
    }

    //! Quadrilinear sample (see the header comment): the light fields (injection) or the
    //! gathered light (pixels). False outside the cube.
    bool sampleFields(const glm::dvec3& p, double diameter, const glm::dvec3& dir, ConeSample& out) const;
    bool sampleGathered(const glm::dvec3& p, double diameter, const glm::dvec3& dir, ConeSample& out) const;

    //! The radiance of each of the 16 cones at every pixel, [pixel * 16 + cone]; 0 for cones
    //! below the surface and pixels without a surface or outside the cube.
    //! With `sky`, also the sky and emitters each cone sees (pixel_cones.h ConeSkyOutput).
    void gatherCones(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out,
                     const ConeSkyOutput* sky = nullptr);
    //! The gathered light along `rays` cosine-distributed rays per pixel (zero aperture: the
    //! leaves), E = pi * mean radiance (the error split of voxel_gi.h traceVoxelRays).
    //! With `sky`: the sky and emitters the rays see (pixel_cones.h traceGBufferRays).
    void gatherRays(const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out,
                    const scene::Sky* sky = nullptr) const;
    //! Where a pixel's cones start; false without a surface or outside the cube.
    bool preparePixel(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& origin,
                      glm::dvec3& n, ConeMarchSettings& march) const;

    std::size_t getTopologyBytes() const { return mTopology.getBytes(); }
    //! What is kept between frames: the gathered light and occupancy of every node, and the
    //! leaves' volumetric G-buffer (needed to re-light). The light fields exist during
    //! injection only.
    std::size_t getPayloadBytes() const;
    double getMeanStepsPerCone() const { return mMeanStepsPerCone; }

private:
    template <bool Gathered>
    bool sampleAt(const glm::dvec3& p, double diameter, const glm::dvec3& dir, ConeSample& out) const;
    //! Corner bricks: the trilinear blend of the brick of the node of `level` holding p.
    template <bool Gathered>
    void sampleBrickLevel(int level, const glm::dvec3& p, const glm::dvec3& dir, float weight,
                          ConeSample& out) const;
    //! Corner bricks of every node from the per-node values get(node * 6 + face).
    template <class T, class Get> void makeBricks(const Get& get, std::vector<T>& bricks) const;
    void makeGatheredBricks();
    template <class Get>
    void filterUp(const Get& get);
    //! Filters the occupancy (the gathered payload's a) up the tree.
    void filterAlphaUp();
    //! Filters light field `field` up the tree (front-to-back composite with the filtered
    //! occupancy of the children).
    void filterFieldUp(int field);

    OctreeSettings mSettings;
    ConeSet mCones;
    int mDepth = 0;
    glm::dvec3 mOrigin{0.0};
    double mSide = 1.0;
    OctreeTopology mTopology;     //!< leafNode indexes mLeaves
    std::vector<OctreeLeaf> mLeaves;
    //! [node * 6 + face]: gathered light and occupancy; the light fields during injectLight.
    SparsePayload mPayload;
    std::vector<glm::ivec4> mNodeCells; //!< corner bricks: [node] = its cell (xyz) and level (w)
    std::vector<glm::vec4> mGatheredBricks;
    //! Corner bricks of the light fields, during injection only.
    std::array<std::vector<glm::vec3>, kFieldCount> mFieldBricks;
    std::uint64_t mStamp = 0;
    double mMeanStepsPerCone = 0.0;
};

} // namespace rtlab::voxelgi
