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
// 2. inject light: per surface leaf, the family's 16-cone gather through the octree (emission, sky as 16
//    lobes, point lights with shadow cones), three passes (direct, bounce 1, bounce 2), each
//    filtered up the tree before the next reads it. Skipped while the tree and lights are
//    unchanged.
// 3. gather: per pixel one trace_step^2 block, the 16 cones above the surface through the
//    octree, each sample quadrilinear at the cone footprint's level; upsampled by depth and
//    normal and multiplied by the occlusion family's cone visibilities and the characters'
//    capsules (families/voxel_gi/upsample.h), as cascades.
// The gather runs on Vulkan (shaders/svo_gather.comp) or in C++; build and injection in C++ (TBB).
// Declares surfacesOnly: the walls' interior beyond the inner layer is not stored, so coarse cone
// samples see through thick walls (the family's furnace loses light; the leak rooms leak).
// Not yet: bricks (3^3 with shared borders), empty-space skipping, constant (solid) nodes, a
// start level chosen by the distance to the camera, a local rebuild after a dig.
//
// Parameters
// | name          | type  | default | range / choices | unit                          |
// |---------------|-------|---------|-----------------|-------------------------------|
// | resolution    | int   | 64      | [8, 4096], power of two | leaves along the cube's side |
// | voxel_size    | float | 0 (auto)| [0, 1e6]        | world units (leaf size)       |
// | supersampling | int   | 4       | [1, 16]         | rays per leaf column and axis, per side |
// | bounces       | int   | 2       | [1, 3]          |                               |
// | cone_angle    | float | 29      | [5, 60]         | degrees (half-angle)          |
// | start_offset  | float | 4       | [0, 8]          | leaves (pixel cones)          |
// | inject_offset | float | 4       | [0, 8]          | leaves (the leaves' cones)    |
// | step_scale    | float | 0.5     | [0.1, 2]        | of the voxel size sampled     |
// | trace_step    | int   | 4       | [1, 8]          | pixels                        |
// | device        | enum  | vulkan  | vulkan, cpu     | where the pixel gather runs   |
// | inner_layers  | int   | 1       | [1, 8]          | leaves of solid kept inside closed surfaces |
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
#include "families/voxel_gi/sparse_cone_params.h"
#include "families/voxel_gi/upsample.h"
#include "families/voxel_gi/voxel_gi.h"

#include <bit>
#include <cmath>
#include <optional>

namespace {

using namespace rtlab;

class Svo final : public plugin::VoxelGiTechnique {
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
        voxelgi::SparseConeParams::declare(schema, "leaves along the cube's side (a power of two)", 1);
        return schema;
    }

    explicit Svo(const config::ParamSet& p) : mParams(voxelgi::SparseConeParams::read(p))
    {
        if (!std::has_single_bit(unsigned(mParams.resolution)))
            throw Error("svo: resolution must be a power of two, found " + std::to_string(mParams.resolution));
        mSettings.resolution = mParams.resolution;
        mSettings.supersampling = mParams.supersampling;
        mSettings.bounces = mParams.bounces;
        mSettings.coneHalfAngleDegrees = mParams.coneAngle;
        mSettings.startOffset = mParams.startOffset;
        mSettings.injectOffset = mParams.injectOffset;
        mSettings.stepScale = mParams.stepScale;
        mSettings.innerLayers = mParams.innerLayers;
    }

    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p;
        mParams.write(p);
        return p;
    }

    plugin::VoxelGiDefinition definition() const override
    {
        return {.bounces = mSettings.bounces, .surfacesOnly = true};
    }

    plugin::VoxelGiStep voxelize(const plugin::VoxelGiFrame& frame) override
    {
        if (mTree && frame.geometryKey == mGeometryKey && !frame.force)
            return plugin::VoxelGiStep::skipped("the static geometry is unchanged since the build");
        const std::string why = !mTree ? "first build"
                                : frame.geometryKey != mGeometryKey ? "geometry changed"
                                                                    : "culling off";
        if (!mTree)
            mTree.emplace(mSettings);
        glm::dvec3 origin;
        double side = 0.0;
        const scene::RenderScene& g = *frame.geometry;
        if (g.triangleCount() == 0) {
            mTree->build(glm::dvec3(0.0), 1.0, {});
        } else {
            voxelgi::SparseVoxelOctree::computeCube(glm::dvec3(g.boundsMin), glm::dvec3(g.boundsMax),
                                                    mSettings.resolution, origin, side, mParams.voxelSize);
            mTree->build(origin, side,
                         voxelgi::SparseVoxelOctree::voxelizeLeaves(g, origin, side, mSettings));
        }
        mGeometryKey = frame.geometryKey;
        mLightsKey.clear();
        return plugin::VoxelGiStep::done(why + ": " + std::to_string(mTree->getLeaves().size()) +
                                         " leaves, " + std::to_string(mTree->getNodeCount()) + " nodes");
    }

    plugin::VoxelGiStep injectLight(const plugin::VoxelGiFrame& frame) override
    {
        const std::string lightsKey = voxelgi::computeLightsKey(*frame.geometry);
        if (lightsKey == mLightsKey && !frame.force)
            return plugin::VoxelGiStep::skipped("the tree and the lights are unchanged since it was lit");
        mTree->injectLight(*frame.geometry);
        mLightsKey = lightsKey;
        return plugin::VoxelGiStep::done("lit " + std::to_string(mTree->getLeaves().size()) + " leaves, " +
                                         std::to_string(mSettings.bounces) + " passes");
    }

    void gather(const plugin::VoxelGiInput& input, Image<glm::vec3>& irradiance) override
    {
        mGatheredOnGpu = mParams.onGpu && input.gpu != nullptr;
        irradiance = voxelgi::gatherConesReduced(
            *input.gbuffer, mParams.traceStep, mTree->getCones().halfAngle, input.coneVisibility,
            input.capsules, [&](const scene::GBuffer& reduced, std::vector<glm::vec3>& cones) {
                if (mGatheredOnGpu)
                    mGpu.gatherCones(*input.gpu, *mTree, reduced, cones);
                else
                    mTree->gatherCones(reduced, cones);
            });
    }

    bool traceVoxelRays(const plugin::VoxelGiInput& input, int raysPerPixel,
                        Image<glm::vec3>& irradiance) override
    {
        irradiance = voxelgi::traceRaysReduced(*input.gbuffer, mParams.traceStep,
                                               [&](const scene::GBuffer& reduced, Image<glm::vec3>& low) {
                                                   mTree->gatherRays(reduced, raysPerPixel, low);
                                               });
        return true;
    }

    plugin::VoxelGiMemory memory() const override
    {
        if (!mTree)
            return {};
        return {.topologyBytes = mTree->getTopologyBytes(), .payloadBytes = mTree->getPayloadBytes()};
    }

    std::vector<std::pair<std::string, double>> counters() const override
    {
        if (!mTree)
            return {};
        return {{"voxel_size", mTree->getLeafSize()},
                {"leaves", double(mTree->getLeaves().size())},
                {"nodes", double(mTree->getNodeCount())},
                {"steps_per_cone", mGatheredOnGpu ? std::nan("") : mTree->getMeanStepsPerCone()},
                {"gather_on_gpu", mGatheredOnGpu ? 1.0 : 0.0},
                {"gather_gpu_ms", mGatheredOnGpu && mGpu.getLastGpuMs() ? *mGpu.getLastGpuMs() : std::nan("")},
                {"gather_upload_bytes", mGatheredOnGpu ? double(mGpu.getLastUploadBytes()) : 0.0}};
    }

private:
    voxelgi::SparseConeParams mParams;
    voxelgi::OctreeSettings mSettings;
    std::optional<voxelgi::SparseVoxelOctree> mTree;
    voxelgi::OctreeGatherGpu mGpu;
    std::string mGeometryKey, mLightsKey;
    bool mGatheredOnGpu = false;
};

} // namespace

RTLAB_REGISTER_TECHNIQUE(voxel_gi, svo, Svo)
