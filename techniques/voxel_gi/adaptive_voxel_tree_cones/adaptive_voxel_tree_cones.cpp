// adaptive_voxel_tree_cones: Quantum Break's 64-ary adaptive voxel tree as the sparse structure of
// the family's 16-cone tracing, like-for-like with cascades and svo.
//
// Registry key: voxel_gi/adaptive_voxel_tree_cones
//
// Talk: A. Silvennoinen and V. Timonen, "Multi-Scale Global Illumination in Quantum Break",
// SIGGRAPH 2015 Advances in Real-Time Rendering (seed shared/seeds/002_2c73d3b2bb6f7a13.txt,
// "Adaptive Voxel Tree" to "world space cells"): the tree's nodes (64-bit child mask + offset,
// child index = offset + popcount, payload arrays indexed by that index, implicit leaves, a dense
// first level). The game used the tree for baked irradiance probes (technique
// adaptive_voxel_tree); here it holds the voxels that the Tomorrow Children's 16 cones are traced
// through (shared/seeds/000_3da000e866ebc485.txt), so that the three structures of the family are
// compared with the same light and the same gather.
//
// Quantity: indirect diffuse irradiance at the G-buffer pixels, E = sum over bounces k = 1..B of
// E_k (reference.h "indirect" with bounces = B), as cascades and svo compute it.
//
// Algorithm (voxel_tree_cones.h):
// 1. voxelize: the static scene's box (padded by a leaf) as root cells of 4^depth leaves; the
//    leaves are the surface voxels and the inner layers of closed surfaces (sparse_leaves.h, the
//    leaves of svo), made isotropic; the tree is built over them (no dilation: an absent
//    element is empty, exactly) and their occupancy filtered up per face (16 columns of 4
//    children composited front to back, averaged). Rebuilt only when the static geometry changes.
// 2. inject light: the family's 16-cone gather from every surface leaf through the tree, three
//    passes, each filtered up before the next (sparse_leaves.h injectLeafLight, as svo). Skipped
//    while the tree and lights are unchanged.
// 3. gather: per pixel one trace_step^2 block, the 16 cones above the surface through the tree,
//    each sample trilinear at the two levels around the footprint (4x apart) and linear between
//    them; upsampled by depth and normal and multiplied by the occlusion family's cone
//    visibilities and the characters' capsules (upsample.h), as cascades and svo.
// The gather runs on Vulkan (shaders/tree_cone_gather.comp, the 64-bit popcount as two 32-bit
// bitCounts) or in C++; build and injection in C++ (TBB). Declares surfacesOnly, like svo: the
// walls' interior beyond the inner layers is not stored.
// Not yet: a local rebuild after a dig.
//
// Parameters
// | name               | type  | default  | range / choices   | unit                       |
// |--------------------|-------|----------|-------------------|----------------------------|
// | resolution         | int   | 64       | [8, 4096]         | leaves along the longest side |
// | depth              | int   | 3        | [1, 6]            | levels below the root cells |
// | node_masks         | enum  | shared   | shared, inline    |                            |
// | voxel_size         | float | 0 (auto) | [0, 1e6]          | world units (leaf size)    |
// | supersampling      | int   | 4        | [1, 16]           | rays per leaf column, axis, side |
// | bounces            | int   | 2        | [1, 3]            |                            |
// | cone_angle         | float | 29       | [5, 60]           | degrees (half-angle)       |
// | start_offset       | float | 4        | [0, 8]            | leaves (pixel cones)       |
// | sky_start          | float | 8        | [0, 64]           | leaves (the sky)           |
// | sky_occlusion      | enum  | occupancy | optical_depth, occupancy | the sky's transmittance |
// | inject_offset      | float | 4        | [0, 8]            | leaves (the leaves' cones) |
// | step_scale         | float | 0.5      | [0.1, 2]          | of the voxel size sampled  |
// | trace_step         | int   | 4        | [1, 8]            | pixels                     |
// | device             | enum  | auto     | auto, vulkan, cpu |                            |
// | capsule_resolution | enum  | traced   | traced, full      |                            |
// | inner_layers       | int   | 4        | [1, 8]            | leaves of solid inside walls |
//
// node_masks: shared keeps the node records' child masks in one table of the tree's distinct
// masks (voxel_tree.h), inline in each record (the talk's 12 bytes); the gather reads the same
// elements either way. device: where the pixel gather runs (auto: Vulkan on a GPU, C++ where
// Vulkan runs on the CPU). capsule_resolution: the characters' capsules tested at the traced
// pixels or at every pixel.
//
// start_offset 4 as svo (the same leaves, the same self-occlusion at a smaller offset);
// inject_offset 4 as svo: at 1 / 2 / 4 leaves, leak room with 0.5-leaf walls 0.52 / 0.70 / 0.91
// inside, cornell_box RMSE 0.166 / 0.133 / 0.133, tomorrow_town 0.178 / 0.149 / 0.118.
// inner_layers 4 (svo's default is 1): a wall stored at least as thick as the cones' start
// distance, so that no cone starts beyond it; the coarse levels, 4x apart, see through thin
// stored walls sooner than the octree's. Family furnace at 64 leaves: -14.4 % with 4 layers,
// -20.9 % with 1 (the suite's bound for surface-only structures is -20 %).
// voxel_size 0 fits the lattice to the scene's box; > 0 centres a cube of resolution leaves of
// that size on the box (what lies outside is left out).
//
// Config example:
//   techniques:
//     voxel_gi: {technique: adaptive_voxel_tree_cones, params: {resolution: 128, depth: 3}}

#include "tree_cone_gather_gpu.h"
#include "voxel_tree_cones.h"

#include "families/voxel_gi/sparse_cone_technique.h"

#include <string>

namespace {

using namespace rtlab;

class AdaptiveVoxelTreeCones final
    : public voxelgi::SparseConeTechnique<voxelgi::VoxelTreeCones, voxelgi::TreeConeGatherGpu> {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "64-ary adaptive voxel tree (Quantum Break) as the structure of the 16-cone tracing",
                .reference = "Silvennoinen & Timonen, Multi-Scale Global Illumination in Quantum Break, "
                             "SIGGRAPH 2015",
                .seed = "002_2c73d3b2bb6f7a13.txt"};
    }

    static config::ParamSchema declareParams()
    {
        config::ParamSchema schema;
        voxelgi::SparseConeParams::declare(schema, "leaves along the longest side of the static scene's box", 4,
                                           "occupancy");
        schema.addInt("depth", 3, 1, 6, "", "tree levels below the dense root cells (4^depth leaves per root cell and axis)");
        schema.addEnum(
            "node_masks", "shared", {"shared", "inline"},
            "the node records' child masks in one table of the distinct masks, or in each record "
            "(the talk's 12 bytes); the gather reads the same elements");
        return schema;
    }

    explicit AdaptiveVoxelTreeCones(const config::ParamSet& p) : SparseConeTechnique(p)
    {
        voxelgi::TreeConeSettings settings;
        settings.depth = int(p.getInt("depth"));
        settings.nodeMasks = p.getString("node_masks") == "inline" ? voxelgi::NodeMasks::Inline
                                                                   : voxelgi::NodeMasks::Shared;
        settings.supersampling = mParams.supersampling;
        settings.bounces = mParams.bounces;
        settings.coneHalfAngleDegrees = mParams.coneAngle;
        settings.startOffset = mParams.startOffset;
        settings.injectOffset = mParams.injectOffset;
        settings.skyStart = mParams.skyStart;
        settings.skyOpticalDepth = mParams.skyOpticalDepth;
        settings.stepScale = mParams.stepScale;
        settings.innerLayers = mParams.innerLayers;
        mStructure.emplace(settings); // checks the settings
    }

private:
    std::string build(const scene::RenderScene& g) override
    {
        voxelgi::VoxelTreeCones& tree = *mStructure;
        const voxelgi::TreeConeSettings& s = tree.getSettings();
        glm::dvec3 origin(0.0);
        double leaf = 1.0;
        glm::ivec3 roots(1);
        if (g.triangleCount() == 0) {
            tree.build(origin, leaf, roots, {});
        } else {
            voxelgi::VoxelTreeCones::computeLattice(glm::dvec3(g.boundsMin), glm::dvec3(g.boundsMax), mParams.resolution,
                                                    s.depth, mParams.voxelSize, origin, leaf, roots);
            voxelgi::LeafLattice lattice;
            lattice.origin = origin;
            lattice.leafSize = leaf;
            lattice.cells = roots * (1 << (2 * s.depth));
            lattice.supersampling = s.supersampling;
            lattice.chunk = s.chunk;
            lattice.innerLayers = s.innerLayers;
            tree.build(origin, leaf, roots, voxelgi::voxelizeSurfaceLeaves(g, lattice, "adaptive_voxel_tree_cones"));
        }
        return std::to_string(tree.getLeaves().size()) + " leaves, " + std::to_string(tree.getTree()->getNodeCount()) +
               " nodes (" + std::to_string(roots.x) + "x" + std::to_string(roots.y) + "x" + std::to_string(roots.z) +
               " root cells)";
    }

    void writeStructureParams(config::ParamSet& p) const override
    {
        p.set("depth", std::int64_t(mStructure->getSettings().depth));
        p.set("node_masks",
              std::string(mStructure->getSettings().nodeMasks == voxelgi::NodeMasks::Inline
                              ? "inline"
                              : "shared"));
    }

    std::vector<std::pair<std::string, double>> structureCounters() const override
    {
        return {{"nodes", double(mStructure->getTree()->getNodeCount())},
                {"mask_table", double(mStructure->getTree()->getMaskTable().size())},
                {"elements", double(mStructure->getTree()->getElementCount())}};
    }
};

} // namespace

RTLAB_REGISTER_TECHNIQUE(voxel_gi, adaptive_voxel_tree_cones, AdaptiveVoxelTreeCones)
