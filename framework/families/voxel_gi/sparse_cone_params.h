#pragma once
// The parameters of the sparse cone-traced structures (svo, adaptive_voxel_tree_cones): the same
// names, ranges and meaning in both, so that a sweep over one sweeps the other like for like.

#include "config/param.h"
#include "families/voxel_gi/upsample.h"

#include <string>

namespace rtlab::voxelgi {

struct SparseConeParams {
    int resolution = 64;      //!< leaves along the scene's box
    double voxelSize = 0.0;   //!< leaf size in world units; 0 = fit the scene's box
    int supersampling = 4;    //!< voxelization rays per leaf column and axis, per side
    int bounces = 2;          //!< reflections gathered at the pixel (1..3)
    double coneAngle = 29.0;  //!< degrees, half-angle
    double startOffset = 4.0; //!< leaves: the pixel cones' start distance and origin offset along the normal
    double injectOffset = 4.0; //!< leaves: the same for the leaves' cones of light injection
    double skyStart = 8.0;    //!< leaves along a pixel cone from which its voxels shadow the sky
    bool skyOpticalDepth = false; //!< sky_occlusion (declareSkyOcclusion)
    double stepScale = 0.5;   //!< march step / size of the voxels sampled
    int traceStep = 4;        //!< pixels: one traced per trace_step^2 block, then upsampled
    //! The pixel gather's device: vulkan, cpu or auto (cone_combine_gpu.h shouldGatherOnGpu).
    std::string device = "auto";
    CapsuleResolution capsules = CapsuleResolution::Traced; //!< capsule_resolution
    int innerLayers = 1;      //!< layers of solid leaves kept inside closed surfaces

    //! Declares resolution (described by `resolutionHelp`), voxel_size, supersampling, bounces,
    //! cone_angle, start_offset, inject_offset, sky_start, sky_occlusion, step_scale, trace_step, device,
    //! capsule_resolution and inner_layers.
    static void declare(config::ParamSchema& schema, const char* resolutionHelp, int innerLayersDefault,
                        const char* skyOcclusionDefault);
    static SparseConeParams read(const config::ParamSet& p);
    void write(config::ParamSet& p) const;
};

//! The `sky_occlusion` parameter of every cone-traced technique: how its pixel cones march the
//! sky's transmittance, `optical_depth` or `occupancy` (cone_tracing.h ConeMarchSettings::
//! skyOpticalDepth), with the technique's default.
void declareSkyOcclusion(config::ParamSchema& schema, const char* defaultValue);
bool readSkyOpticalDepth(const config::ParamSet& p);

//! The `device` and `capsule_resolution` parameters of every cone-traced technique (cascades,
//! svo, adaptive_voxel_tree_cones): where the pixel gather runs and where the capsules are tested.
void declareGatherPlacement(config::ParamSchema& schema);
CapsuleResolution readCapsuleResolution(const config::ParamSet& p);
std::string toString(CapsuleResolution resolution);

} // namespace rtlab::voxelgi
