// cascades: the voxel texture cascade of the Tomorrow Children, cone traced in 16 directions.
//
// Registry key: voxel_gi/cascades
//
// Talk: J. McLaren, "The Technology of The Tomorrow Children", GDC 2015 (seed
// shared/seeds/000_3da000e866ebc485.txt, "Voxel Texture Cascade" to "Characters"), after
// C. Crassin et al., "Interactive Indirect Illumination Using Voxel Cone Tracing", Pacific
// Graphics 2011.
//
// Quantity: indirect diffuse irradiance at the G-buffer pixels, E = sum over bounces k = 1..B
// of E_k (reference.h "indirect" with bounces = B): the pixel's 16 cones gather the reflected
// direct light of the voxels (B >= 1), their first bounce (B >= 2) and second bounce (B = 3).
//
// Algorithm (cascade_volume.h, and the family's shared voxelize.h and cone_tracing.h):
// 1. N levels of R^3 anisotropic voxels centred on the camera, level i of voxel size v0 * 2^i,
//    placed on a lattice of 2 voxels of the level ("Cascade Update: calculate new cascade
//    centre"). Each level is voxelized from the static triangles (characters are not voxelized)
//    with supersampled coverage and solid fill; only the level due this frame is updated (level
//    i every 2^(i+1) frames) unless `update: all_levels`; a level is re-voxelized only when its
//    region scrolled (then only the new slabs are voxelized; the rest is shifted) or the geometry
//    changed (then only the voxels around the triangles that appeared or disappeared: the dug
//    region), its light carried over (a scrolled level takes the missing edge from the next
//    coarser level).
// 2. Light injection per surface voxel: 16 cones gather emission, the sky (as 16 SRBF lobes on
//    the cone directions, by the cones that leave the cascade) and, through the direct buffer,
//    the bounces; point lights are gathered along a thin cone toward each light with the
//    occupancy accumulated on the way. Per face, E = sum_k w_k L_k with w_k proportional to the
//    clamped cosine about the face's shading normal, normalised to pi (exact for a furnace).
//    `schedule: three_pass` traces direct, first and second bounce one after the other;
//    `one_pass` traces once and writes all three from the previous buffers (the talk).
// 3. Per pixel, 16 cones (those above the surface) through the light the pixel gathers,
//    front to back with step-corrected opacity, the start level blended by distance to the
//    level centres, at one pixel per trace_step^2 block (the talk's quarter resolution)
//    with optional pre-combined direction buffers. At full resolution each cone's radiance is
//    upsampled by depth and normal and multiplied by the pixel's per-direction visibilities of
//    bentcone_ssdo (when that occlusion technique runs in the same frame) and by the characters'
//    capsules tested against the cone ("Characters": not voxelized; families/voxel_gi/upsample.h;
//    `capsule_resolution: traced`, the default, tests them at the traced pixels and upsamples
//    them with the cones, 1/16 of the tests at trace_step 4), on Vulkan when the gather runs
//    there on a GPU, else in C++, or where `combine_device` says (Vulkan: cone_combine_gpu.h,
//    the cones of a Vulkan gather read where they are, only the irradiance read back; the
//    capsules at the traced pixels multiply the device's cone buffer in place).
//
// The pixel gather runs on Vulkan (shaders/cascade_gather.comp, `device: vulkan`, the default
// `auto` where the Vulkan device is a GPU) or in C++ (`device: cpu`, and `auto` where Vulkan runs
// on the CPU, lavapipe: there the C++ gather is 1.6-3x faster, README "Voxel GI"); so
// do the cones of light injection (shaders/cascade_inject.comp, `inject_device: vulkan`: the 16
// cones and the shadow cones of every surface voxel; the light buffers stay in C++, go up per
// level when they changed, and the C++ side reflects, propagates inward and pre-combines the
// irradiance that comes back). The voxelization runs in C++ (TBB) or on Vulkan
// (framework/families/voxel_gi/voxelize_gpu.h, `voxelize_device: vulkan`: the columns' rays and
// the per-voxel resolve; the binning of triangles to columns and the solid fill's last step in
// C++).
// With `far_start` > 0 (the default) the pixel cones are split ("Split Cone Trace"): each pixel
// traces its cones up to far_start voxels of its start level (at least start_offset: a smaller
// far_start is raised to it, and the row records the value used), and the rest comes from far cones
// traced once per voxel centre of the level (when a pixel first needs them, kept until a level they
// sample changes) and interpolated trilinearly (cascade_gather.cpp gatherConesSplit). The far cones
// are traced by the pixel gather's device (Vulkan: the gather shader's far-cone mode, or C++), as
// are the near parts and the composite.
// With `extrapolate` the pixels also gather the talk's extrapolated extra bounce ("Extra Magic",
// cone_tracing.h extrapolateBounce) from the voxels' last two bounces: the technique then claims
// bounces + 1 reflections and is measured against that ground truth.
// `level_noise` adds the talk's "3D noise offset" to the start-level blend of the pixel cones (a
// smooth value noise on the level-0 voxel lattice, the same bits in C++ and on Vulkan).
// Not yet: the volumetric G-buffer and the light buffers kept on the GPU between updates.
//
// Parameters
// clang-format off
// | name           | type  | default           | range / choices                       | unit   |
// |----------------|-------|-------------------|---------------------------------------|--------|
// | levels         | int   | 6                 | [1, 10]                               |        |
// | resolution     | int   | 32                | [4, 128], even                        | voxels |
// | voxel_size     | float | 0 (auto)          | [0, 1e6]                              | world  |
// | supersampling  | int   | 4                 | [1, 16]                               | rays per voxel side |
// | bounces        | int   | 2                 | [1, 3]                                |        |
// | schedule       | enum  | three_pass        | three_pass, one_pass                  |        |
// | update         | enum  | one_level_per_frame | one_level_per_frame, all_levels     |        |
// | cone_angle     | float | 29                | [5, 60]                               | degrees (half-angle) |
// | start_offset   | float | 1                 | [0, 4]                                | voxels |
// | sky_start      | float | 4                 | [0, 64]                               | voxels of the pixel's start level |
// | sky_occlusion  | enum  | occupancy         | optical_depth, occupancy              | the sky's transmittance |
// | step_scale     | float | 0.5               | [0.1, 2]                              | of the voxel size sampled |
// | precombine     | bool  | true              |                                       |        |
// | solid          | bool  | true              |                                       |        |
// | device         | enum  | auto              | auto, vulkan, cpu (pixel gather)      |        |
// | combine_device | enum  | auto              | auto, vulkan, cpu (full-res. combine) |        |
// | capsule_resolution | enum | traced          | traced, full                          |        |
// | inject_device  | enum  | cpu               | cpu, vulkan (light injection's cones) |        |
// | voxelize_device| enum  | cpu               | cpu, vulkan (resolution <= 128)       |        |
// | trace_step     | int   | 4                 | [1, 8]                                | pixels |
// | far_start      | float | 1                 | 0 (whole cones) or [start_offset, 64] | voxels of the pixel's start level |
// | extrapolate    | bool  | false             | needs bounces >= 2                    |        |
// | level_noise    | float | 0                 | [0, 0.5]                              | of a level's radius |
// clang-format on
// voxel_size 0 makes the outermost level hold the whole scene seen from the first camera.
// The talk's split is "about a meter" at its 0.4 m finest voxels: far_start about 2.5. The
// default 1 (= start_offset: no near part, the pixel's cones interpolated from the far cones of
// the voxel centres around it) is on both study scenes the fastest and the most accurate of 0, 1,
// 1.5 and 2.5 (experiments/gpu_voxel_gi.yaml; README "Voxel GI"); 0 traces whole cones per pixel.
// The talk: 6 levels of 32^3, 16x supersampling per axis, one level per frame, one pass,
// 2 bounces in the voxels plus the pixel's gather (bounces: 3 here).
//
// Config example:
//   techniques:
//     voxel_gi: {technique: cascades, params: {levels: 6, resolution: 32, schedule: one_pass}}

#include "cascade_gather_gpu.h"
#include "cascade_inject_gpu.h"
#include "cascade_volume.h"
#include "families/voxel_gi/cone_combine_gpu.h"
#include "families/voxel_gi/sparse_cone_params.h"

#include "core/error.h"
#include "core/hash.h"
#include "families/voxel_gi/upsample.h"
#include "families/voxel_gi/voxel_gi.h"
#include "families/voxel_gi/voxelize_gpu.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

namespace {

using namespace rtlab;

class Cascades final : public plugin::VoxelGiTechnique {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "voxel texture cascades (6 x 32^3 around the camera), 16 cones",
                .reference = "McLaren, The Technology of The Tomorrow Children, GDC 2015",
                .seed = "000_3da000e866ebc485.txt"};
    }

    static config::ParamSchema declareParams()
    {
        config::ParamSchema schema;
        schema.addInt("levels", 6, 1, 10, "", "cascade levels, each doubling the extent");
        schema.addInt("resolution", 32, 4, 128, "voxels", "voxels per level and axis (even)");
        schema.addFloat("voxel_size", 0.0, 0.0, 1e6, "world units",
                        "level-0 voxel size; 0 = the outermost level holds the whole scene");
        schema.addInt("supersampling", 4, 1, 16, "rays per voxel side",
                      "voxelization rays per voxel column and axis, per side (coverage)");
        schema.addInt("bounces", 2, 1, 3, "", "reflections gathered at the pixel");
        schema.addEnum("schedule", "three_pass", {"three_pass", "one_pass"},
                       "light update: direct, bounce 1, bounce 2 one after the other, or the "
                       "talk's single staggered pass");
        schema.addEnum("update", "one_level_per_frame", {"one_level_per_frame", "all_levels"},
                       "levels updated per frame (level i every 2^(i+1) frames) or all");
        schema.addFloat("cone_angle", 29.0, 5.0, 60.0, "degrees", "cone half-angle");
        schema.addFloat("start_offset", 1.0, 0.0, 4.0, "voxels",
                        "cone start distance and origin offset along the normal");
        schema.addFloat("sky_start", 4.0, 0.0, 64.0, "voxels",
                        "distance along a pixel cone (voxels of its start level) from which its "
                        "voxels shadow the sky (nearer occluders, the pixel's own surface among "
                        "them, are the occlusion family's)");
        voxelgi::declareSkyOcclusion(schema, "occupancy");
        schema.addFloat("step_scale", 0.5, 0.1, 2.0, "", "march step / size of the voxels sampled");
        schema.addBool("precombine", true,
                       "pre-combined direction buffers for the pixel cones (3x fewer lookups)");
        schema.addBool("solid", true, "solid voxelization (fill closed spans)");
        schema.addInt("trace_step", 4, 1, 8, "pixels",
                      "trace one pixel per trace_step^2 block and upsample (depth- and "
                      "normal-aware); 4 = the talk's quarter resolution, 1 = every pixel");
        schema.addFloat("far_start", 1.0, 0.0, 64.0, "voxels",
                        "split near/far cones: pixels trace up to this many voxels of their "
                        "start level (at least start_offset), far cones from the voxel centres "
                        "do the rest (0 = whole cones per pixel)");
        schema.addBool("extrapolate", false,
                       "add the talk's extrapolated extra bounce (bounces + 1 reflections; "
                       "needs bounces >= 2)");
        schema.addFloat("level_noise", 0.0, 0.0, 0.5, "of a level's radius",
                        "3D noise offset on the pixel cones' start-level blend (hides the "
                        "transition between levels)");
        voxelgi::declareGatherPlacement(
            schema); // device (Vulkan needs precombine), capsule_resolution
        schema.addEnum("combine_device", "auto", {"auto", "vulkan", "cpu"},
                       "where the full-resolution combine runs (upsampling, visibilities, "
                       "capsules); auto: on Vulkan when the pixel gather runs there on a GPU "
                       "(its cones staying on the device), else in C++");
        schema.addEnum("inject_device", "cpu", {"cpu", "vulkan"},
                       "where light injection traces the surface voxels' cones (the light "
                       "buffers stay on the CPU)");
        schema.addEnum("voxelize_device", "cpu", {"cpu", "vulkan"},
                       "where the levels are voxelized (Vulkan: resolution up to 128)");
        return schema;
    }

    explicit Cascades(const config::ParamSet& p)
    {
        mSettings.levels = int(p.getInt("levels"));
        mSettings.resolution = int(p.getInt("resolution"));
        if (mSettings.resolution % 2 != 0)
            throw Error("cascades: resolution must be even, found " +
                        std::to_string(mSettings.resolution));
        mVoxelSizeParam = p.getFloat("voxel_size");
        mSettings.voxelSize = mVoxelSizeParam;
        mSettings.supersampling = int(p.getInt("supersampling"));
        mSettings.bounces = int(p.getInt("bounces"));
        mSettings.onePass = p.getString("schedule") == "one_pass";
        mSettings.oneLevelPerFrame = p.getString("update") == "one_level_per_frame";
        mSettings.coneHalfAngleDegrees = p.getFloat("cone_angle");
        mSettings.startOffset = p.getFloat("start_offset");
        mSettings.skyStart = p.getFloat("sky_start");
        mSettings.skyOpticalDepth = voxelgi::readSkyOpticalDepth(p);
        mSettings.stepScale = p.getFloat("step_scale");
        mSettings.precombine = p.getBool("precombine");
        mSettings.solid = p.getBool("solid");
        mDevice = p.getString("device");
        mInjectOnGpu = p.getString("inject_device") == "vulkan";
        mCombineDevice = p.getString("combine_device");
        mCapsuleResolution = voxelgi::readCapsuleResolution(p);
        mVoxelizeOnGpu = p.getString("voxelize_device") == "vulkan";
        mTraceStep = int(p.getInt("trace_step"));
        mSettings.farStart = p.getFloat("far_start");
        if (mSettings.farStart > 0.0) // no split nearer than where the cones start
            mSettings.farStart = std::max(mSettings.farStart, mSettings.startOffset);
        mSettings.extrapolate = p.getBool("extrapolate");
        mSettings.levelNoise = p.getFloat("level_noise");
        if (mSettings.extrapolate && mSettings.bounces < 2)
            throw Error("cascades: extrapolate needs bounces >= 2 (it extrapolates from the last "
                        "two), found bounces " + std::to_string(mSettings.bounces));
    }

    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p;
        p.set("levels", std::int64_t(mSettings.levels));
        p.set("resolution", std::int64_t(mSettings.resolution));
        p.set("voxel_size", mVoxelSizeParam);
        p.set("supersampling", std::int64_t(mSettings.supersampling));
        p.set("bounces", std::int64_t(mSettings.bounces));
        p.set("schedule", std::string(mSettings.onePass ? "one_pass" : "three_pass"));
        p.set("update", std::string(mSettings.oneLevelPerFrame ? "one_level_per_frame" : "all_levels"));
        p.set("cone_angle", mSettings.coneHalfAngleDegrees);
        p.set("start_offset", mSettings.startOffset);
        p.set("sky_start", mSettings.skyStart);
        p.set("sky_occlusion", std::string(mSettings.skyOpticalDepth ? "optical_depth" : "occupancy"));
        p.set("step_scale", mSettings.stepScale);
        p.set("precombine", mSettings.precombine);
        p.set("solid", mSettings.solid);
        p.set("device", mDevice);
        p.set("inject_device", std::string(mInjectOnGpu ? "vulkan" : "cpu"));
        p.set("combine_device", mCombineDevice);
        p.set("capsule_resolution", voxelgi::toString(mCapsuleResolution));
        p.set("voxelize_device", std::string(mVoxelizeOnGpu ? "vulkan" : "cpu"));
        p.set("trace_step", std::int64_t(mTraceStep));
        p.set("far_start", mSettings.farStart);
        p.set("extrapolate", mSettings.extrapolate);
        p.set("level_noise", mSettings.levelNoise);
        return p;
    }

    //! With the extrapolated bounce the pixels' light claims one reflection more.
    plugin::VoxelGiDefinition definition() const override
    {
        return {.bounces = mSettings.bounces + (mSettings.extrapolate ? 1 : 0)};
    }

    plugin::VoxelGiStep voxelize(const plugin::VoxelGiFrame& frame) override
    {
        if (!mVolume) {
            voxelgi::CascadeSettings s = mSettings;
            if (s.voxelSize <= 0.0) {
                // The outermost level holds every corner of the scene's bounds seen from the
                // first frame's camera (inside the sphere the level selection uses).
                const glm::dvec3 lo(frame.geometry->boundsMin), hi(frame.geometry->boundsMax);
                double farthest = 0.0;
                for (int c = 0; c < 8; ++c)
                    farthest = std::max(
                        farthest, glm::length(glm::dvec3(c & 1 ? hi.x : lo.x, c & 2 ? hi.y : lo.y,
                                                         c & 4 ? hi.z : lo.z) -
                                              frame.cameraPosition));
                if (!(farthest > 0.0) || !std::isfinite(farthest))
                    farthest = 1.0;
                s.voxelSize = farthest / (0.5 * s.resolution - 2.0) / std::ldexp(1.0, s.levels - 1);
            }
            mVolume.emplace(s);
        }
        mVoxelizedOnGpu = mVoxelizeOnGpu && frame.gpu != nullptr;
        mVoxelizer.resetCounters();
        voxelgi::CascadeVolume::Voxelizer onGpu;
        if (mVoxelizedOnGpu)
            onGpu = [&](const scene::RenderScene& geometry, const voxelgi::VoxelRegion& region,
                        const voxelgi::VoxelizeOptions& options) {
                return mVoxelizer.voxelize(*frame.gpu, geometry, region, options);
            };
        // A dig's re-meshed region, when the frame knows it: no triangle comparison.
        if (frame.changeKnown)
            mVolume->noteGeometryChange(frame.changedFromKey, frame.geometryKey, frame.changedMin,
                                        frame.changedMax);
        const std::string what = mVolume->voxelize(*frame.geometry, frame.geometryKey, frame.cameraPosition,
                                                   frame.frameIndex, frame.force, onGpu);
        if (what.empty())
            return plugin::VoxelGiStep::skipped("no due level moved and the geometry is unchanged");
        return plugin::VoxelGiStep::done(what);
    }

    plugin::VoxelGiStep injectLight(const plugin::VoxelGiFrame& frame) override
    {
        // The surface voxels' cones on Vulkan when asked and a device is there.
        mInjectedOnGpu = mInjectOnGpu && frame.gpu != nullptr;
        mInjectGpu.resetCounters();
        voxelgi::CascadeVolume::IrradianceGather onGpu;
        if (mInjectedOnGpu)
            onGpu = [&](int level, const voxelgi::InjectionLights& lights,
                        std::vector<voxelgi::FaceIrradiance>& out) {
                mInjectGpu.gatherIrradiance(*frame.gpu, *mVolume, level, lights, out);
            };
        const std::string what = mVolume->injectLight(*frame.geometry, voxelgi::computeLightsKey(*frame.geometry),
                                                      frame.frameIndex, frame.force, onGpu);
        if (what.empty())
            return plugin::VoxelGiStep::skipped(
                "the due level's voxels, lights and coarser levels are unchanged since it was lit");
        return plugin::VoxelGiStep::done("lit " + what);
    }

    std::string whyNotGatheredOnGpu(const gpu::Context& gpu) const override
    {
        if (!voxelgi::shouldGatherOnGpu(&gpu, mDevice) || !mSettings.precombine)
            return !mSettings.precombine ? "the Vulkan gather reads the pre-combined buffers (precombine: false)"
                                         : "the pixel cones run in C++ (device: " + mDevice +
                                               (mDevice == "auto" ? " on a CPU device" : "") + ")";
        if (!voxelgi::shouldCombineOnGpu(&gpu, true, mCombineDevice))
            return "the combine runs in C++ (combine_device: " + mCombineDevice +
                   (mCombineDevice == "auto" ? " on a CPU device" : "") + ")";
        return {};
    }

    const gpu::Image* getGpuIrradiance() const override { return mCombineGpu.getResidentOutput(); }

    void readBackIrradiance(Image<glm::vec3>& irradiance) override
    {
        irradiance = mCombineGpu.readBackResident();
    }

    const gpu::Image* getGpuConeSky() const override
    {
        return mSkyOnGpu ? mSkyCombineGpu.getResidentOutput() : nullptr;
    }

    void readBackConeSky(Image<glm::vec3>& irradiance) override
    {
        if (!mSkyOnGpu)
            throw Error("cascades: the last gather traced no cone sky on the GPU");
        irradiance = mSkyCombineGpu.readBackResident();
    }

    void gather(const plugin::VoxelGiInput& input, Image<glm::vec3>& irradiance) override
    {
        mSky.cones.clear();
        mSkyOnGpu = false;
        mSkyWhyNot.clear();
        // The cones' sky and emitters, traced with the light when the frame asks for them.
        std::optional<std::array<glm::vec3, voxelgi::kConeCount>> skyPerCone;
        if (input.coneSky && input.scene != nullptr)
            skyPerCone = voxelgi::computeSkyPerCone(input.scene->sky, mVolume->getCones());
        if (input.gpuGBuffer != nullptr) {
            // Resident: the pixels reduced on the device, their cones and the combine there.
            if (input.gpu == nullptr || !whyNotGatheredOnGpu(*input.gpu).empty())
                throw Error("cascades: the G-buffer was given on the GPU to a gather that does not run there");
            mGatheredOnGpu = mCombinedOnGpu = mGatheredResident = true;
            mGpu.setConeSky(skyPerCone);
            voxelgi::gatherConesResident(
                *input.gpu, mCombineGpu, *input.gpuGBuffer, mTraceStep, mVolume->getCones().halfAngle,
                input.gpuConeVisibility, input.capsules,
                [&](const voxelgi::PixelSource& pixels) -> const voxelgi::PixelConeDispatch& {
                    return mGpu.gatherConesResident(*input.gpu, *mVolume, pixels);
                },
                &mCombineMs, mCapsuleResolution, skyPerCone ? &mSkyCombineGpu : nullptr);
            mSkyOnGpu = skyPerCone.has_value();
            if (input.readBack)
                readBackIrradiance(irradiance);
            return;
        }
        // The Vulkan gather reads the pre-combined buffers; without them the C++ path runs.
        // Reduced resolution ("Trace at a lower resolution"): one pixel per trace_step^2 block,
        // each cone's radiance upsampled by depth and normal, times the pixel's own visibilities
        // (bent-cone SSDO) and the characters' capsules.
        mGatheredResident = false;
        mGatheredOnGpu = voxelgi::shouldGatherOnGpu(input.gpu, mDevice) && mSettings.precombine;
        mCombinedOnGpu = voxelgi::shouldCombineOnGpu(input.gpu, mGatheredOnGpu, mCombineDevice);
        if (mGatheredOnGpu) {
            mGpu.setConeSky(skyPerCone);
            mVolume->setConeSky(skyPerCone ? &*skyPerCone : nullptr);
        }
        // The Vulkan gather's cones: the far cones first with split cones (on Vulkan too, their
        // sky with them).
        const auto prepareGpuCones = [&](const scene::GBuffer& reduced) {
            if (mSettings.farStart > 0.0)
                mVolume->prepareFarCones(
                    reduced, [&](const std::vector<std::pair<int, std::uint32_t>>& centres,
                                 std::vector<glm::vec3>& far, std::vector<glm::vec3>* farSky) {
                        mGpu.traceFarCones(*input.gpu, *mVolume, centres, far, farSky);
                    });
        };
        // The Vulkan gather's cones' sky to the CPU, for combineConeSky (this path's round trip).
        const auto readBackGpuSky = [&](std::vector<glm::vec3>& cones) {
            if (!skyPerCone)
                return;
            if (mGpu.tracedSky())
                mGpu.readBackSky(cones);
            else
                mSkyWhyNot = "the far cones were traced without the sky (it was not asked for when they were)";
        };
        voxelgi::ConeSkyOutput sky;
        if (skyPerCone)
            sky.skyPerCone = *skyPerCone;
        if (mCombinedOnGpu) {
            // The combine on Vulkan (cone_combine_gpu.h): the cones of the Vulkan gather stay on
            // the device, those of the C++ gather go up.
            irradiance = voxelgi::gatherConesReducedOnGpu(
                *input.gpu, mCombineGpu, *input.gbuffer, mTraceStep, mVolume->getCones().halfAngle,
                input.coneVisibility, input.capsules,
                [&](const scene::GBuffer& reduced) -> const gpu::Buffer& {
                    if (!mGatheredOnGpu) {
                        // The C++ gather's cones go up; their sky stays here, for the C++
                        // combine of combineConeSky (float against double: within 1e-5).
                        std::vector<glm::vec3> cones;
                        sky.out = &mSky.cones;
                        mVolume->gatherCones(reduced, cones, skyPerCone ? &sky : nullptr);
                        return mCombineGpu.uploadCones(*input.gpu, cones);
                    }
                    prepareGpuCones(reduced);
                    return mGpu.gatherConesOnDevice(*input.gpu, *mVolume, reduced);
                },
                &mCombineMs, mCapsuleResolution);
            if (mGatheredOnGpu)
                readBackGpuSky(mSky.cones);
            if (!mSky.cones.empty())
                voxelgi::keepConeSky(mSky, *input.gbuffer, mTraceStep, mVolume->getCones().halfAngle,
                                     input.capsules, mCapsuleResolution);
            return;
        }
        irradiance = voxelgi::gatherConesReduced(
            *input.gbuffer, mTraceStep, mVolume->getCones().halfAngle, input.coneVisibility,
            input.capsules,
            [&](const scene::GBuffer& reduced, std::vector<glm::vec3>& cones,
                std::vector<glm::vec3>* skyCones) {
                if (mGatheredOnGpu) {
                    prepareGpuCones(reduced);
                    mGpu.gatherCones(*input.gpu, *mVolume, reduced, cones);
                    if (skyCones != nullptr)
                        readBackGpuSky(*skyCones);
                } else {
                    sky.out = skyCones;
                    mVolume->gatherCones(reduced, cones, skyPerCone ? &sky : nullptr);
                }
            },
            &mCombineMs, mCapsuleResolution, &mSky);
    }

    std::string combineConeSky(const plugin::VoxelGiInput& input, Image<glm::vec3>& irradiance) override
    {
        if (!mSkyWhyNot.empty())
            return mSkyWhyNot;
        if (!mSky.isValid())
            return "the last gather traced no cone sky (its far cones were traced without it)";
        irradiance = voxelgi::combineConeSky(mSky, *input.gbuffer, mVolume->getCones().halfAngle,
                                             input.coneVisibility, input.capsules);
        return {};
    }

    bool traceVoxelRays(const plugin::VoxelGiInput& input, int raysPerPixel,
                        Image<glm::vec3>& irradiance) override
    {
        // At the same representative pixels as the cones, upsampled the same way.
        irradiance = voxelgi::traceRaysReduced(*input.gbuffer, mTraceStep,
                                               [&](const scene::GBuffer& reduced, Image<glm::vec3>& low) {
                                                   mVolume->gatherRays(reduced, raysPerPixel, low);
                                               });
        return true;
    }

    bool traceVoxelSkyRays(const plugin::VoxelGiInput& input, int raysPerPixel, const scene::Sky& sky,
                           Image<glm::vec3>& irradiance) override
    {
        irradiance = voxelgi::traceRaysReduced(*input.gbuffer, mTraceStep,
                                               [&](const scene::GBuffer& reduced, Image<glm::vec3>& low) {
                                                   mVolume->gatherRays(reduced, raysPerPixel, low, &sky);
                                               });
        return true;
    }

    bool computeLookupLevels(const plugin::VoxelGiInput& input,
                             Image<std::uint8_t>& levels) override
    {
        if (!mVolume)
            return false;
        mVolume->computeStartLevels(*input.gbuffer, levels);
        return true;
    }

    plugin::VoxelGiMemory memory() const override
    {
        if (!mVolume)
            return {};
        return {.topologyBytes = mVolume->getTopologyBytes(),
                .payloadBytes = mVolume->getPayloadBytes()};
    }

    std::vector<std::pair<std::string, double>> counters() const override
    {
        if (!mVolume)
            return {};
        const auto& c = mVolume->getCounters();
        std::size_t surface = 0;
        for (int i = 0; i < mVolume->getLevelCount(); ++i)
            surface += mVolume->getLevel(i).grid.surfaceVoxels.size();
        std::vector<std::pair<std::string, double>> counters = {
            {"voxel_size", mVolume->getSettings().voxelSize},
            {"levels_voxelized", double(c.levelsVoxelized)},
            {"voxelize_changed_voxels", double(c.changedVoxels)},
            {"voxelize_changed_ms", c.changedMs},
            {"levels_lit", double(c.levelsLit)},
            {"surface_voxels", double(surface)},
            {"steps_per_cone", mGatheredOnGpu ? std::nan("") : c.meanStepsPerCone}};
        voxelgi::appendGatherCounters(counters, mGatheredOnGpu, mGpu.getLastGpuMs(),
                                      mGpu.getLastUploadBytes(), mCombineMs, mCombinedOnGpu,
                                      mCombineGpu);
        const auto& inject = mInjectGpu.getCounters();
        const auto& voxelizer = mVoxelizer.getCounters();
        counters.insert(
            counters.end(),
            {{"far_levels_dropped", mGatheredResident ? double(mGpu.getLastFarLevelsDropped()) : std::nan("")},
             {"far_cones_traced", mGatheredResident ? std::nan("") : double(c.farConesTraced)},
             {"far_cones_ms", c.farConesMs},
             {"pixel_cones_ms", mGatheredOnGpu ? std::nan("") : c.pixelConesMs},
             {"far_voxels_cached", double(c.farVoxelsCached)},
             {"inject_on_gpu", mInjectedOnGpu ? 1.0 : 0.0},
             {"inject_cones_ms", c.injectConesMs},
             {"inject_gpu_ms", mInjectedOnGpu && inject.timed && inject.dispatches > 0
                                   ? inject.gpuMs
                                   : std::nan("")},
             {"inject_upload_bytes", mInjectedOnGpu ? double(inject.uploadBytes) : 0.0},
             {"inject_dispatch_ms", mInjectedOnGpu ? inject.submitMs : std::nan("")},
             {"inject_device_call_ms", mInjectedOnGpu ? inject.callMs : std::nan("")},
             {"voxelize_on_gpu", mVoxelizedOnGpu ? 1.0 : 0.0},
             {"voxelize_dispatch_ms", mVoxelizedOnGpu ? voxelizer.submitMs : std::nan("")},
             {"voxelize_device_call_ms", mVoxelizedOnGpu ? voxelizer.callMs : std::nan("")},
             {"voxelize_fallbacks", mVoxelizedOnGpu ? double(voxelizer.fallbacks) : 0.0}});
        return counters;
    }

private:
    voxelgi::CascadeSettings mSettings;
    double mVoxelSizeParam = 0.0;
    std::optional<voxelgi::CascadeVolume> mVolume;
    voxelgi::CascadeGatherGpu mGpu;
    voxelgi::ConeCombineGpu mCombineGpu;
    voxelgi::ConeCombineGpu mSkyCombineGpu; // the resident gather's cones' sky
    bool mSkyOnGpu = false;                 // the last gather left its cones' sky there
    voxelgi::CascadeInjectGpu mInjectGpu;
    voxelgi::VoxelizerGpu mVoxelizer;
    bool mVoxelizeOnGpu = false;
    bool mVoxelizedOnGpu = false;
    std::string mDevice = "auto";
    std::string mCombineDevice = "auto";
    bool mCombinedOnGpu = false;
    bool mGatheredResident = false; // the last gather ran resident (far cones on the device)
    bool mInjectOnGpu = false;
    bool mInjectedOnGpu = false;
    voxelgi::ConeSkyTrace mSky; // the last gather's cones' sky on the CPU, for combineConeSky
    std::string mSkyWhyNot;     // why the last gather traced no cone sky, "" when it did
    bool mGatheredOnGpu = false;
    double mCombineMs = std::nan(""); // the gather beyond its cones: reduction and combine
    voxelgi::CapsuleResolution mCapsuleResolution = voxelgi::CapsuleResolution::Traced;
    int mTraceStep = 4;
};

} // namespace

RTLAB_REGISTER_TECHNIQUE(voxel_gi, cascades, Cascades)
