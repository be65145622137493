#pragma once
// Experiment files: one YAML document describes a study. A `base` run plus a `sweep` that expands
// to the cross product of its axes. Everything is validated against the registry's declarations
// before anything runs; errors name file:line:column.
//
//   name: smoke
//   description: marching cubes on analytic shapes
//   base:
//     scene: sphere                     # an analytic shape (isosurface), a procedural scene
//                                       # (cornell_box, ...) or a scene file (.yaml)
//     grid: 48                          # SDF samples per axis (isosurface)
//     resolution: [320, 180]            # image size (screen-space families)
//     frames: 1                         # frames of the scene's animation, from frame 0
//     camera_path: scene                # scene (its own), static, orbit, dolly, strafe, or a
//                                       # path the scene names (scene/camera_paths.h)
//     metrics: [error, masks]           # what the families measure (default: all they declare)
//     reference: {target_stderr: 0.01, target_rel_stderr: 0.02, max_samples: 1024, seed: 0,
//                 quantity: ao, radius: 0.5}  # quantity/radius/falloff override the technique's
//                                             # declaration (default: exactly what it declares)
//     timing: {warmup: 1, repeats: 5}
//     frame: {culling: true,            # false: run every pass (frame graph ablation)
//             lighting: false,          # true: compose the lit frame, measure it against Embree
//             gbuffer_on_gpu: true,     # false: techniques read the G-buffer's CPU copy (ablation)
//             tonemapper: aces, exposure_ev: 0, shadow_map_size: 256,
//             sky: auto}                # lobes: the sky never through a voxel GI technique's cones
//     techniques:                       # one technique per family; several screen families
//                                       # share one frame
//       isosurface: {technique: marching_cubes, params: {vertex_placement: linear}}
//   sweep:                              # cross product, axes in file order
//     scene: [sphere, torus]
//     grid: [24, 48]
//     isosurface.technique: [marching_cubes]
//     isosurface.vertex_placement: [linear, midpoint]

#include "config/param.h"
#include "metrics/timing.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rtlab::plugin {
class Registry;
}

namespace rtlab::experiment {

//! The technique a run uses for one family, with its validated parameters (every declared key).
struct TechniqueChoice {
    std::string technique;
    config::ParamSet params;
};

//! How the ground truth of screen-space families is computed (reference/reference.h).
struct ReferenceOptions {
    double targetStdErr = 0.01;    //!< absolute per-pixel standard error to reach
    double targetRelStdErr = 0.02; //!< relative part of the stopping rule
    int maxSamples = 1024;         //!< per pixel
    std::uint64_t seed = 0;
    //! Ground-truth quantity override ("ao", "ao_uniform", "obscurance"); "" = the quantity the
    //! technique declares. An override measures a technique against a quantity it does not claim
    //! (rows then say reference.matches_technique = false).
    std::string quantity;
    std::string falloff; //!< "linear", "smoothstep"; "" = the technique's
    double radius = 0.0; //!< world units; 0 = the technique's
};

} // namespace rtlab::experiment
namespace rtlab::reference {
struct ReferenceSettings;
}
namespace rtlab::experiment {

//! Copies the run's sampling options (target standard errors, sample cap, seed) into the
//! settings of a ground truth, whatever quantity it computes.
void applySamplingOptions(const ReferenceOptions& options, reference::ReferenceSettings& settings);

//! One fully expanded run.
struct RunConfig {
    std::string scene; //!< analytic shape, procedural scene, or scene file path
    int grid = 64;     //!< SDF samples per axis (isosurface)
    int width = 320;   //!< image size in pixels (screen-space families)
    int height = 180;
    int frames = 1;                   //!< frames 0..frames-1 of the scene's animation
    std::string cameraPath;           //!< "" = the scene's own (scene/camera_paths.h)
    std::vector<std::string> metrics; //!< metric names of the run's families; empty = all
    metrics::TimingOptions timing;
    ReferenceOptions reference;
    std::map<std::string, TechniqueChoice> techniques; //!< family -> choice
    //! `frame: {culling: false}` runs every pass of the frame graph (no pass is skipped for having
    //! no consumer or for reusing earlier work): the ablation that proves culling changes nothing.
    bool culling = true;
    //! `frame: {lighting: true}` composes the lit frame after the families' passes
    //! (pipeline/compose.h) and measures it against the Embree `full` radiance (and its direct
    //! term against `direct`); with its tonemapper ("aces", "reinhard"), exposure in stops and
    //! shadow-map size (texels per cube face).
    bool lighting = false;
    //! `frame: {gbuffer_on_gpu: false}` makes Vulkan techniques read the CPU copy of the G-buffer
    //! (read back, then uploaded again by the technique): the ablation of keeping it on the GPU.
    bool gbufferOnGpu = true;
    std::string tonemapper = "aces";
    double exposureEv = 0.0;
    int shadowMapSize = 256;
    //! `frame: {sky: lobes}` lights the sky through the 16 lobes times the occlusion family's
    //! visibility even when a voxel GI technique gives its cone sky; `auto` (the default) takes
    //! the cone sky when there is one (pipeline/compose.h): the ablation of the talk's sky.
    std::string sky = "auto";
    //! True when a family of the run works on a sampled volume (`grid`) rather than images; set
    //! by the loader from the families' domains (not part of the hash).
    bool volume = false;

    //! Short readable id, unique within an experiment: "sphere-g48-marching_cubes-3f2a91c0".
    std::string id() const;
    //! Canonical JSON of everything that determines the result (used for resume).
    std::string toJson() const;
    //! True when `metric` is to be computed (metrics empty, or it is listed).
    bool wantsMetric(const std::string& metric) const;
    //! Hash of toJson(): a run whose hash is already in the results table is not recomputed.
    std::string hash() const;
};

struct Experiment {
    std::string path;
    std::string name;
    std::string description;
    //! `report: {time_from_frame: N}`: the report averages the time columns (`*_ms`) of a run of
    //! more than N frames over its frames N and later only (the first frames' builds and shader
    //! compiles left out: a frame's cost once running); errors stay averaged over every frame.
    //! Written into each row as `report.time_from_frame` when set; not part of a run's identity.
    int reportTimeFromFrame = 0;
    RunConfig base;
    std::vector<std::string> sweepKeys; //!< axes in file order
    std::vector<RunConfig> runs;        //!< the expanded cross product (just `base` without sweep)
};

//! Loads, validates and expands an experiment file.
Experiment loadExperiment(const std::string& path, const plugin::Registry& registry);
//! Same for in-memory text; `label` stands for the path in messages.
Experiment parseExperiment(const std::string& text, const std::string& label,
                           const plugin::Registry& registry);

} // namespace rtlab::experiment
