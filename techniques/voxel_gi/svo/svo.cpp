// svo: the sparse voxel octree of Crassin et al. 2011, lit and cone traced in the 16 directions.
//
// Registry key: voxel_gi/svo
//
// Paper: C. Crassin, F. Neyret, M. Sainz, S. Green, E. Eisemann, "Interactive Indirect
// Illumination Using Voxel Cone Tracing", Pacific Graphics 2011 (the structure the Tomorrow
// Children moved away from: shared/seeds/000_3da000e866ebc485.txt, "Voxel Cone Tracing ... we
// started with SVO"). Lit with the family's 16-cone injection so that it differs from cascades
// only in its structure.
//
// Quantity: indirect diffuse irradiance at the G-buffer pixels, E = sum over bounces k = 1..B of
// E_k (reference.h "indirect" with bounces = B), as cascades computes it.
//
// Algorithm (sparse_voxel_octree.h):
// 1. voxelize: the static scene's box (padded by a leaf) as a cube of resolution^3 leaves; the
//    blocks of 32^3 leaves a triangle meets are voxelized (families/voxel_gi/voxelize.h,
//    supersampled coverage); their surface voxels are the voxel fragments, and the solid voxels
//    just inside closed surfaces join them as an inner layer that mirrors the surface's light;
//    leaves are isotropic (the paper's); the octree is built top-down over them (node tiles of
//    2x2x2, one child pointer per node) and their occupancy filtered up the tree anisotropically
//    (6 faces, front-to-back per column). Rebuilt only when the static geometry changes.
// 2. inject light: per surface leaf, the family's 16-cone gather through the octree (emission,
//    sky as 16 lobes, point lights with shadow cones), three passes (direct, bounce 1, bounce
//    2), each filtered up the tree before the next reads it. Skipped while the tree and lights are
//    unchanged.
// 3. gather: per pixel one trace_step^2 block, the 16 cones above the surface through the
//    octree, each sample quadrilinear at the cone footprint's level; upsampled by depth and
//    normal and multiplied by the occlusion family's cone visibilities and the characters'
//    capsules (families/voxel_gi/upsample.h), as cascades.
// The gather runs on Vulkan (shaders/svo_gather.comp) or in C++; build and injection in C++ (TBB).
// Declares surfacesOnly: the walls' interior beyond the inner layer is not stored, so coarse cone
// samples see through thick walls (the family's furnace loses light; the leak rooms leak).
// bricks: corner gives every node a 2x2x2 brick per face, the values at its corners with borders
// shared between neighbours (sparse_voxel_octree.h; the paper's bricks in their 2^3 form).
// Not yet: 3^3 bricks, empty-space skipping, constant (solid) nodes, a
// start level chosen by the distance to the camera, a local rebuild after a dig.
//
// Parameters
// | name               | type  | default  | range / choices         | unit                      |
// |--------------------|-------|----------|-------------------------|---------------------------|
// | resolution         | int   | 64       | [8, 4096], power of two | leaves along the cube side |
// | voxel_size         | float | 0 (auto) | [0, 1e6]                | world units (leaf size)   |
// | supersampling      | int   | 4        | [1, 16]                 | rays per leaf column/side |
// | bounces            | int   | 2        | [1, 3]                  |                           |
// | cone_angle         | float | 29       | [5, 60]                 | degrees (half-angle)      |
// | start_offset       | float | 4        | [0, 8]                  | leaves (pixel cones)      |
// | sky_start          | float | 8        | [0, 64]                 | leaves (the sky)          |
// | sky_occlusion      | enum  | occupancy | optical_depth, occupancy | the sky's transmittance |
// | inject_offset      | float | 4        | [0, 8]                  | leaves (the leaves' cones) |
// | step_scale         | float | 0.5      | [0.1, 2]                | of the voxel size sampled |
// | trace_step         | int   | 4        | [1, 8]                  | pixels                    |
// | device             | enum  | auto     | auto, vulkan, cpu       |                           |
// | capsule_resolution | enum  | traced   | traced, full            |                           |
// | inner_layers       | int   | 1        | [1, 8]                  | solid leaves inside walls |
// | bricks             | enum  | none     | none, corner            |                           |
//
// device: where the pixel gather runs (auto: Vulkan on a GPU, C++ where Vulkan runs on the CPU).
// capsule_resolution: the characters' capsules tested at the traced pixels or at every pixel.
//
// resolution 64: the pixel's cones start a fixed number of leaves out (there is no start level
// chosen by the distance to the camera), so finer leaves bring the self-occlusion back and the
// error grows with the resolution (experiments/voxel_gi.yaml: cornell_box 0.128, 0.224, 0.360 at
// 64, 128, 256 leaves; tomorrow_town 0.121, 0.141, 0.173).
// start_offset 4: at 1 leaf a pixel's cones sample the leaves of their own surface and its
// neighbours (self-occlusion; beside cornell_box's ceiling light, the light's own reflected
// light as a halo); measured indirect RMSE at 64 / 128 leaves, offsets 1, 3, 4: cornell_box
// 0.40, 0.16, 0.13 / 0.69, 0.27, 0.22; tomorrow_town 0.19, 0.13, 0.12 / 0.21, 0.16, 0.14.
// inject_offset 4: the leaves' injection cones start that far out too. Smaller offsets let less
// light through thin walls but sample the leaf's own surface (experiments/voxel_gi.yaml, 1 / 2 / 4
// leaves: leak room with 0.5-leaf walls, mean inside 0.55 / 0.76 / 1.00; cornell_box RMSE 0.233 /
// 0.169 / 0.128; tomorrow_town 0.187 / 0.151 / 0.121).
// voxel_size 0 fits the cube to the scene's box (padded by a leaf); > 0 centres resolution
// leaves of that size on the box (what lies outside is left out).
//
// Config example:
//   techniques:
//     voxel_gi: {technique: svo, params: {resolution: 128}}

#include "sparse_voxel_octree.h"
#include "svo_gather_gpu.h"

#include "core/error.h"
#include "families/voxel_gi/sparse_cone_technique.h"

#include <bit>
#include <string>

namespace {

using namespace rtlab;

class Svo final : public voxelgi::SparseConeTechnique<voxelgi::SparseVoxelOctree, voxelgi::OctreeGatherGpu> {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "sparse voxel octree (Crassin 2011), anisotropic filtering, 16 cones",
                .reference = "Crassin et al., Interactive Indirect Illumination Using Voxel Cone "
                             "Tracing, Pacific Graphics 2011",
                .seed = "000_3da000e866ebc485.txt"};
    }

    static config::ParamSchema declareParams()
    {
        config::ParamSchema schema;
        voxelgi::SparseConeParams::declare(schema, "leaves along the cube's side (a power of two)", 1,
                                           "occupancy");
        schema.addEnum(
            "bricks", "none", {"none", "corner"},
            "none: one value per node and face, 8 descents per trilinear sample; corner: "
            "also a 2x2x2 brick of corner values with shared borders (8x the payload, one "
            "descent per sample)");
        return schema;
    }

    explicit Svo(const config::ParamSet& p) : SparseConeTechnique(p)
    {
        if (!std::has_single_bit(unsigned(mParams.resolution)))
            throw Error("svo: resolution must be a power of two, found " + std::to_string(mParams.resolution));
        voxelgi::OctreeSettings settings;
        settings.resolution = mParams.resolution;
        settings.supersampling = mParams.supersampling;
        settings.bounces = mParams.bounces;
        settings.coneHalfAngleDegrees = mParams.coneAngle;
        settings.startOffset = mParams.startOffset;
        settings.injectOffset = mParams.injectOffset;
        settings.skyStart = mParams.skyStart;
        settings.skyOpticalDepth = mParams.skyOpticalDepth;
        settings.stepScale = mParams.stepScale;
        settings.innerLayers = mParams.innerLayers;
        settings.cornerBricks = p.getString("bricks") == "corner";
        mStructure.emplace(settings); // checks the settings
    }

private:
    std::string build(const scene::RenderScene& g) override
    {
        voxelgi::SparseVoxelOctree& tree = *mStructure;
        if (g.triangleCount() == 0) {
            tree.build(glm::dvec3(0.0), 1.0, {});
        } else {
            glm::dvec3 origin;
            double side = 0.0;
            voxelgi::SparseVoxelOctree::computeCube(glm::dvec3(g.boundsMin), glm::dvec3(g.boundsMax),
                                                    mParams.resolution, origin, side, mParams.voxelSize);
            tree.build(origin, side, voxelgi::SparseVoxelOctree::voxelizeLeaves(g, origin, side, tree.getSettings()));
        }
        return std::to_string(tree.getLeaves().size()) + " leaves, " + std::to_string(tree.getNodeCount()) + " nodes";
    }

    void writeStructureParams(config::ParamSet& p) const override
    {
        p.set("bricks", std::string(mStructure->getSettings().cornerBricks ? "corner" : "none"));
    }

    std::vector<std::pair<std::string, double>> structureCounters() const override
    {
        return {{"nodes", double(mStructure->getNodeCount())}};
    }
};

} // namespace

RTLAB_REGISTER_TECHNIQUE(voxel_gi, svo, Svo)
