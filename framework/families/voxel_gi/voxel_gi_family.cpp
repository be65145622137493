// The voxel_gi family: voxel scene structures (cascades, sparse octree, 64-ary adaptive tree)
// cone traced for indirect diffuse light. The technique interface is families/voxel_gi/voxel_gi.h.
// Its passes, on the shared frame start (pipeline/frame_start.h):
//   voxel_geometry   the static triangles the structure voxelizes: the scene's meshes and meshed
//                    SDF models, without the characters (the talk does not voxelize them);
//                    reused while no edit starts
//   voxelize         the technique re-voxelizes what changed (skipped, with its reason, when
//                    nothing did)
//   light_injection  the technique updates its voxel light buffers where they are stale
//   voxel_gather     indirect irradiance at the G-buffer pixels (with the occlusion family's 16
//                    per-direction visibilities when an occlusion technique listed before it
//                    gives them, and the characters' capsules)
//   indirect_slot    into the lit frame's `indirect_irradiance` slot (pipeline/compose.h)
//   reference_indirect      Embree "indirect" with the technique's bounce count, same G-buffer
//   metric.indirect_error   indirect.* RMSE, relMSE, PSNR, mean signed error over surface pixels
//   metric.indirect_flip    HDR-FLIP of the indirect irradiance
//   voxel_rays, metric.indirect_split  the error split: the technique's voxels gathered along
//                           rays (traceVoxelRays) against its cones and against the truth
//   reference_cone_sky, voxel_sky_rays, metric.sky_split  the same for the cones' sky in a lit
//                           frame that takes it (cone_sky_split.h)
//   metric.indirect_flicker the frame-to-frame change of the error along the camera path
//                           (remember_indirect keeps the previous frame for it)
//   images_indirect         technique, reference (and its standard error) and signed error as EXR
// (names of their own, so that the family runs beside the occlusion family in one frame)

#include "families/voxel_gi/voxel_gi.h"
#include "families/voxel_gi/cone_sky_split.h"
#include "families/voxel_gi/resident_gather.h"
#include "families/voxel_gi/stress_cases.h"

#include "core/error.h"
#include "core/hash.h"
#include "experiment/family.h"
#include "experiment/image_files.h"
#include "experiment/runner.h"
#include "metrics/gradient_error.h"
#include "metrics/image_metrics.h"
#include "metrics/temporal_metrics.h"
#include "pipeline/compose.h"
#include "pipeline/frame_graph.h"
#include "pipeline/frame_start.h"
#include "reference/reference.h"

#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>

namespace rtlab::families {
namespace {

Image<float> computeLuminance(const Image<glm::vec3>& rgb)
{
    Image<float> out(rgb.width, rgb.height, 0.0f);
    for (std::size_t i = 0; i < rgb.pixels.size(); ++i)
        out.pixels[i] = 0.2126f * rgb.pixels[i].x + 0.7152f * rgb.pixels[i].y +
                        0.0722f * rgb.pixels[i].z;
    return out;
}

// The previous frame's indirect light, for the flicker metric.
struct PreviousIndirect {
    Image<float> technique, reference, depth;
    glm::mat4 projection{1.0f}, view{1.0f};
};

// Rays per pixel of the split's voxel-ray gather (a 16 x 16 stratified grid).
constexpr int kSplitRays = 256;

class VoxelGiRun final : public experiment::FamilyRun {
public:
    explicit VoxelGiRun(experiment::RunSetup& setup)
        : mRun(setup.run), mContext(setup.context), mFamily(setup.family.name),
          mParamPrefix(setup.paramPrefix)
    {
        if (!setup.frameStart)
            throw Error("the voxel_gi family needs the screen-space frame start");
        mTechnique = experiment::createTechnique<plugin::VoxelGiTechnique>(
            mRun, mContext.registry(), mFamily);
        mTechniqueName = mRun.techniques.at(mFamily).technique;
        mDefinition = mTechnique->definition();
        mSettings.quantity = reference::Quantity::Indirect;
        mSettings.bounces = mDefinition.bounces;
        experiment::applySamplingOptions(mRun.reference, mSettings);
        addPasses(setup);
    }

    void describe(experiment::ResultRow& row) const override
    {
        experiment::addParamColumns(row, *mTechnique, mParamPrefix);
        row.set("quantity", std::string("indirect_irradiance"))
            .set("bounces", std::int64_t(mDefinition.bounces))
            .set("reference.quantity", std::string("indirect"))
            .set("reference.bounces", std::int64_t(mSettings.bounces));
    }

    void beginFrame(int frame, experiment::ResultRow& row) override
    {
        mRow = &row;
        mGraph->setExternalAvailable("previous_indirect", mHavePrevious,
                                     frame == 0 ? "first frame of the run"
                                                : "the previous frame has no ground truth");
    }

    void endFrame(int, const std::vector<pipeline::PassRecord>& records,
                  experiment::ResultRow& row) override
    {
        // The technique's time: its three steps, CPU wall time (the GPU paths will add theirs).
        double total = 0.0;
        mHavePrevious = false;
        for (const auto& r : records) {
            if (r.name == "remember_indirect")
                mHavePrevious = r.ran;
            const bool mine = r.name == "voxelize" || r.name == "light_injection" ||
                              r.name == "voxel_gather";
            if (!mine)
                continue;
            const double ms = r.ran && r.time ? r.time->cpuMs.median : 0.0;
            row.set(r.name + "_ms", ms);
            if (r.name == "light_injection" && mDefinition.precomputedLight)
                row.set("bake_ms", ms); // a precompute: apart from the frame's time
            else
                total += ms;
        }
        row.set("technique_ms", total).set("technique_time_source", std::string("cpu"));
        for (const auto& [name, value] : mTechnique->counters())
            row.set("counter." + name, value);
        const plugin::VoxelGiMemory m = mTechnique->memory();
        row.set("memory.topology_bytes", std::int64_t(m.topologyBytes))
            .set("memory.payload_bytes", std::int64_t(m.payloadBytes));
        mRow = nullptr;
    }

private:
    plugin::VoxelGiFrame makeFrame(const pipeline::PassContext& ctx,
                                   const scene::RenderScene& geometry) const
    {
        plugin::VoxelGiFrame f;
        f.geometry = &geometry;
        f.geometryKey = mGeometryKey;
        f.changeKnown = mChangeKnown;
        f.changedFromKey = mChangedFromKey;
        f.changedMin = mChangedMin;
        f.changedMax = mChangedMax;
        f.cameraPosition = glm::dvec3(mScene->getCameraAt(ctx.frame()).position);
        f.frameIndex = ctx.frame();
        f.force = !ctx.mayReuse();
        f.gpu = &mContext.getGpu();
        f.coneSky = wantsConeSky();
        return f;
    }

    std::string mResidentRow; //!< voxel_gather.resident: "yes", or "no: " and why
    //! Whether the run's lit frame takes its sky from the technique's cones.
    bool wantsConeSky() const { return mRun.lighting && mRun.sky != "lobes"; }

    void addPasses(experiment::RunSetup& setup)
    {
        pipeline::FrameGraph& graph = setup.graph;
        pipeline::FrameStart& start = *setup.frameStart;
        mScene = &start.getScene();
        mStart = &start;
        mGraph = &graph;
        const int w = mRun.width, h = mRun.height;
        const auto sceneRes = start.scene();
        const auto sdfMeshes = start.sdfMeshes();
        const auto geometry = start.geometry();
        const auto gbuffer = start.gbufferCpu();
        const auto view = start.viewInputs();
        const pipeline::Resource<scene::RenderScene> staticGeometry{
            "voxel_geometry", pipeline::ResourceType::mesh("static triangles, lights, sky")};
        const pipeline::Resource<int> voxels{"voxel_gbuffer",
                                             pipeline::ResourceType::value("volumetric G-buffer")};
        const pipeline::Resource<int> voxelLight{
            "voxel_light", pipeline::ResourceType::value("voxel light buffers")};
        const pipeline::Resource<Image<glm::vec3>> indirect{
            "technique_indirect", pipeline::ResourceType::cpuImage("vec3", w, h)};
        const pipeline::Resource<reference::ReferenceResult> truth{
            "ground_truth_indirect", pipeline::ResourceType::cpuImage("reference indirect", w, h)};

        std::vector<pipeline::ResourceRef> geometryReads;
        if (graph.declares(sdfMeshes.name))
            geometryReads.push_back(sdfMeshes);
        graph.addPass(
            {.name = "voxel_geometry",
             .reads = {sceneRes},
             .optionalReads = geometryReads,
             .writes = {staticGeometry},
             .persistent = {staticGeometry.name},
             .reuse =
                 [this](const pipeline::PassContext& ctx) {
                     if (mGeometryFrame < 0 ||
                         mScene->getEditStateKey(ctx.frame()) != mGeometryEditKey)
                         return std::string();
                     return "no edit started since frame " + std::to_string(mGeometryFrame);
                 }},
            [this, sdfMeshes, staticGeometry](pipeline::PassContext& ctx) {
                static const std::vector<scene::SdfMesh> kNone;
                const auto* meshes = ctx.tryRead(sdfMeshes);
                scene::RenderScene& g = ctx.write(staticGeometry);
                g = mScene->assembleRenderScene(meshes ? *meshes : kNone, {}, ctx.frame());
                // The static triangles change only where the digs re-meshed (characters are not
                // voxelized): what changed since this pass last assembled them.
                mChangeKnown = mGeometryFrame >= 0 && ctx.mayReuse() &&
                               mStart->findSdfChangeSince(mGeometryFrame, mChangedMin, mChangedMax);
                mChangedFromKey = mGeometryKey;
                mGeometryKey = g.computeContentHash();
                mGeometryEditKey = mScene->getEditStateKey(ctx.frame());
                mGeometryFrame = ctx.frame();
                return pipeline::PassOutcome{};
            });
        graph.addPass({.name = "voxelize",
                       .reads = {staticGeometry},
                       .writes = {voxels},
                       .persistent = {voxels.name}},
                      [this, staticGeometry, voxels](pipeline::PassContext& ctx) {
                          const scene::RenderScene& g = ctx.read(staticGeometry);
                          const plugin::VoxelGiStep step = mTechnique->voxelize(makeFrame(ctx, g));
                          ctx.write(voxels) = ctx.frame();
                          mRow->set("voxelize.did", step.did);
                          return step.ran ? pipeline::PassOutcome{}
                                          : pipeline::PassOutcome::skipped(step.skipReason);
                      });
        graph.addPass({.name = "light_injection",
                       .reads = {staticGeometry, voxels},
                       .writes = {voxelLight},
                       .persistent = {voxelLight.name}},
                      [this, staticGeometry, voxelLight](pipeline::PassContext& ctx) {
                          const scene::RenderScene& g = ctx.read(staticGeometry);
                          const plugin::VoxelGiStep step =
                              mTechnique->injectLight(makeFrame(ctx, g));
                          ctx.write(voxelLight) = ctx.frame();
                          mRow->set("light_injection.did", step.did);
                          return step.ran ? pipeline::PassOutcome{}
                                          : pipeline::PassOutcome::skipped(step.skipReason);
                      });
        // The per-direction visibilities of an occlusion technique listed before this family.
        const auto cones = pipeline::Compose::coneVisibilitySlot(w, h);
        std::vector<pipeline::ResourceRef> gatherOptional;
        const bool hasCones = graph.declares(cones.name);
        if (hasCones)
            gatherOptional.push_back(cones);
        const auto capsules = start.capsules();
        const bool hasCapsules = graph.declares(capsules.name);
        if (hasCapsules)
            gatherOptional.push_back(capsules);
        // What the gather and the cone sky read: the G-buffer, the visibilities, the capsules.
        const auto makeInput = [this, cones, hasCones, capsules,
                                hasCapsules](pipeline::PassContext& ctx, const scene::GBuffer& g) {
            plugin::VoxelGiInput input;
            input.gbuffer = &g;
            input.cameraPosition = glm::dvec3(g.camera.position);
            input.frameIndex = ctx.frame();
            input.gpu = &mContext.getGpu();
            input.capsules = hasCapsules ? ctx.tryRead(capsules) : nullptr;
            const auto* visibility = hasCones ? ctx.tryRead(cones) : nullptr;
            input.coneVisibility =
                visibility && visibility->size() == std::size_t(scene::kConeDirectionCount)
                    ? visibility
                    : nullptr;
            input.coneSky = wantsConeSky();
            return input;
        };
        // A technique's image must be the G-buffer's size.
        const auto checkSize = [this](const Image<glm::vec3>& out, const scene::GBuffer& g,
                                      const char* what) {
            if (out.width != g.width || out.height != g.height)
                throw Error("technique '" + mTechniqueName + "' returned " +
                            std::to_string(out.width) + "x" + std::to_string(out.height) + " " +
                            what + " for a " + std::to_string(g.width) + "x" +
                            std::to_string(g.height) + " G-buffer");
        };
        // Resident: the technique reduces the G-buffer's GPU images, traces and combines
        // its cones on the device, and the lighting pass binds its image; the irradiance comes
        // to the CPU only for the passes that read it there (measurements). Otherwise the gather
        // reads the CPU G-buffer and the compose passes upload its result.
        const auto conesGpu = pipeline::Compose::coneVisibilityGpuSlot(w, h);
        std::string whyNotResident;
        if (!mRun.gbufferOnGpu)
            whyNotResident = "frame: {gbuffer_on_gpu: false} (the round trip through the CPU)";
        else if (std::string why = mTechnique->whyNotGatheredOnGpu(mContext.getGpu()); !why.empty())
            whyNotResident = why;
        else if (hasCones && !graph.declares(conesGpu.name))
            whyNotResident = "the occlusion technique's cone visibilities are on the CPU only";
        const bool resident = whyNotResident.empty();
        mResidentRow = resident ? "yes" : "no: " + whyNotResident;
        const auto slot = pipeline::Compose::indirectIrradianceSlot(w, h);
        const auto coneSky = pipeline::Compose::coneSkySlot(w, h);
        if (resident)
            voxelgi::addResidentGather(graph, start,
                                       {.voxelLight = voxelLight,
                                        .indirect = indirect,
                                        .geometry = geometry,
                                        .coneSky = coneSky,
                                        .coneVisibility = hasCones ? std::optional(conesGpu) : std::nullopt,
                                        .capsules = hasCapsules ? std::optional(capsules) : std::nullopt},
                                       {.width = w, .height = h, .technique = mTechnique.get(),
                                        .techniqueName = mTechniqueName, .gpu = &mContext.getGpu(),
                                        .coneSky = wantsConeSky(), .resident = &mResidentRow, .row = &mRow});
        else {
            graph.addPass(
                {.name = "voxel_gather",
                 .reads = {voxelLight, gbuffer, geometry},
                 .optionalReads = gatherOptional,
                 .writes = {indirect}},
                [this, gbuffer, geometry, makeInput, checkSize, indirect](pipeline::PassContext& ctx) {
                    const scene::GBuffer& g = ctx.read(gbuffer);
                    plugin::VoxelGiInput input = makeInput(ctx, g);
                    input.scene = &ctx.read(geometry);
                    Image<glm::vec3>& out = ctx.write(indirect);
                    mTechnique->gather(input, out);
                    checkSize(out, g, "irradiance");
                    mRow->set("gather.cone_visibility", input.coneVisibility != nullptr);
                    mRow->set("voxel_gather.resident", mResidentRow);
                    return pipeline::PassOutcome{};
                });
            // The sky and the emitters through the technique's cones, for the lit frame (culled
            // when no frame is lit: nothing reads the slot then).
            graph.addPass(
                {.name = "voxel_cone_sky",
                 .reads = {indirect, gbuffer},
                 .optionalReads = gatherOptional,
                 .writes = {coneSky}},
                [this, gbuffer, makeInput, checkSize, coneSky](pipeline::PassContext& ctx) {
                    const scene::GBuffer& g = ctx.read(gbuffer);
                    const plugin::VoxelGiInput input = makeInput(ctx, g);
                    Image<glm::vec3>& out = ctx.write(coneSky);
                    out = Image<glm::vec3>();
                    const std::string whyNot = mTechnique->combineConeSky(input, out);
                    if (!whyNot.empty()) {
                        out = Image<glm::vec3>(); // the frame lights its sky with the lobes
                        mRow->set("voxel_cone_sky.none", whyNot);
                    } else {
                        checkSize(out, g, "cone sky");
                    }
                    return pipeline::PassOutcome{};
                });
        }
        graph.addPass({.name = "indirect_slot", .reads = {indirect}, .writes = {slot}},
                      [indirect, slot](pipeline::PassContext& ctx) {
                          ctx.write(slot) = ctx.read(indirect);
                          return pipeline::PassOutcome{};
                      });
        graph.addPass(
            {.name = "reference_indirect",
             .reads = {geometry, gbuffer, view},
             .writes = {truth},
             .measurement = true},
            [this, geometry, gbuffer, truth](pipeline::PassContext& ctx) {
                reference::ReferenceResult& t = ctx.write(truth);
                t = reference::computeReference(ctx.read(geometry), ctx.read(gbuffer), mSettings);
                mRow->set("reference.seconds", t.stats.seconds)
                    .set("reference.from_cache", t.stats.fromCache)
                    .set("reference.samples_mean", t.stats.meanSamples)
                    .set("reference.stderr_max", t.stats.maxStdErr);
                return t.stats.fromCache
                           ? pipeline::PassOutcome::skipped(
                                 "read from the reference cache (same scene, G-buffer and settings)")
                           : pipeline::PassOutcome{};
            });
        auto metricPass = [&](const std::string& name, std::function<void(pipeline::PassContext&)> f) {
            graph.addPass({.name = "metric.indirect_" + name,
                           .reads = {indirect, truth, view},
                           .writes = {"metric.indirect_" + name},
                           .measurement = true},
                          [f](pipeline::PassContext& ctx) {
                              f(ctx);
                              return pipeline::PassOutcome{};
                          });
        };
        metricPass("error", [=, this](pipeline::PassContext& ctx) {
            metrics::ImageErrorOptions o;
            o.range = metrics::DynamicRange::Hdr;
            o.withSsim = false;
            o.withFlip = false;
            const auto e = metrics::computeImageErrors(ctx.read(indirect), ctx.read(truth).irradiance,
                                                       o, ctx.read(view).surface);
            mRow->set("indirect.rmse", e.rmse)
                .set("indirect.rel_mse", e.relMse)
                .set("indirect.psnr", e.psnr)
                .set("indirect.mean_signed_error", e.meanSignedError)
                .set("indirect.non_finite_pixels", std::int64_t(e.nonFinitePixels))
                .set("indirect.pixels", std::int64_t(e.pixels));
        });
        metricPass("flip", [=, this](pipeline::PassContext& ctx) {
            metrics::ImageErrorOptions o;
            o.range = metrics::DynamicRange::Hdr;
            o.withSsim = false;
            mRow->set("indirect.flip",
                      metrics::computeImageErrors(ctx.read(indirect), ctx.read(truth).irradiance, o,
                                                  ctx.read(view).surface)
                          .flip);
        });
        // Discontinuities (metrics/gradient_error.h): level transitions and interpolation seams
        // are lines, which the per-pixel RMSE hardly sees; neighbour differences against the
        // reference's, on smooth surface pairs, with the reference's noise taken out.
        graph.addPass({.name = "metric.indirect_discontinuity",
                       .reads = {indirect, truth, gbuffer},
                       .writes = {"metric.indirect_discontinuity"},
                       .measurement = true},
                      [=, this](pipeline::PassContext& ctx) {
                          const scene::GBuffer& g = ctx.read(gbuffer);
                          const reference::ReferenceResult& t = ctx.read(truth);
                          const auto pairs = metrics::makeSmoothPairMask(g.depth, g.normal);
                          const auto* se = t.irradianceStdErr.width == t.irradiance.width
                                               ? &t.irradianceStdErr
                                               : nullptr;
                          const auto e = metrics::computeGradientError(ctx.read(indirect),
                                                                       t.irradiance, se, pairs);
                          mRow->set("indirect.gradient_rmse", e.rmse)
                              .set("indirect.gradient_noise_floor", e.noiseFloor)
                              .set("indirect.gradient_excess", e.excess)
                              .set("indirect.gradient_pairs", std::int64_t(e.pairs));
                          // Across level transitions against within one level, where the
                          // technique says which level each pixel's lookup used.
                          plugin::VoxelGiInput input;
                          input.gbuffer = &g;
                          input.frameIndex = ctx.frame();
                          Image<std::uint8_t> levels;
                          if (!mTechnique->computeLookupLevels(input, levels))
                              return pipeline::PassOutcome{};
                          const auto split = metrics::splitPairsByLabel(
                              pairs, levels, plugin::VoxelGiTechnique::kNoLevel);
                          const auto across = metrics::computeGradientError(
                              ctx.read(indirect), t.irradiance, se, split.across);
                          const auto within = metrics::computeGradientError(
                              ctx.read(indirect), t.irradiance, se, split.within);
                          const double nan = std::numeric_limits<double>::quiet_NaN();
                          const double a = across.pairs > 0 ? across.rmse : nan;
                          const double w = within.pairs > 0 ? within.rmse : nan;
                          mRow->set("indirect.transition_gradient_rmse", a)
                              .set("indirect.transition_pairs", std::int64_t(across.pairs))
                              .set("indirect.within_level_gradient_rmse", w)
                              .set("indirect.within_level_pairs", std::int64_t(within.pairs))
                              .set("indirect.transition_ratio", w > 0.0 ? a / w : nan);
                          return pipeline::PassOutcome{};
                      });
        // The split of the error: the technique's voxels gathered along rays instead of cones.
        const pipeline::Resource<Image<glm::vec3>> voxelRays{
            "voxel_rays", pipeline::ResourceType::cpuImage("vec3", w, h)};
        graph.addPass({.name = "voxel_rays",
                       .reads = {voxelLight, gbuffer},
                       .writes = {voxelRays},
                       .measurement = true},
                      [this, gbuffer, voxelRays](pipeline::PassContext& ctx) {
                          plugin::VoxelGiInput input;
                          input.gbuffer = &ctx.read(gbuffer);
                          input.frameIndex = ctx.frame();
                          Image<glm::vec3>& out = ctx.write(voxelRays);
                          if (!mTechnique->traceVoxelRays(input, kSplitRays, out)) {
                              out = Image<glm::vec3>();
                              return pipeline::PassOutcome::skipped(
                                  "technique '" + mTechniqueName + "' traces no voxel rays");
                          }
                          return pipeline::PassOutcome{};
                      });
        graph.addPass({.name = "metric.indirect_split",
                       .reads = {indirect, voxelRays, truth, view},
                       .writes = {"metric.indirect_split"},
                       .measurement = true},
                      [=, this](pipeline::PassContext& ctx) {
                          const Image<glm::vec3>& rays = ctx.read(voxelRays);
                          const auto& technique = ctx.read(indirect);
                          const auto& surface = ctx.read(view).surface;
                          metrics::ImageErrorOptions o;
                          o.range = metrics::DynamicRange::Hdr;
                          o.withSsim = false;
                          o.withFlip = false;
                          const bool have = rays.width == technique.width &&
                                            rays.height == technique.height;
                          const auto cone = have ? metrics::computeImageErrors(technique, rays, o, surface)
                                                 : metrics::ImageErrors{};
                          const auto voxels =
                              have ? metrics::computeImageErrors(rays, ctx.read(truth).irradiance, o, surface)
                                   : metrics::ImageErrors{};
                          const double nan = std::nan("");
                          mRow->set("split.cone_rmse", have ? cone.rmse : nan)
                              .set("split.cone_mean_signed_error", have ? cone.meanSignedError : nan)
                              .set("split.voxel_rmse", have ? voxels.rmse : nan)
                              .set("split.voxel_mean_signed_error",
                                   have ? voxels.meanSignedError : nan)
                              .set("split.rays_per_pixel", std::int64_t(kSplitRays));
                          return pipeline::PassOutcome{};
                      });
        if (wantsConeSky()) {
            voxelgi::addConeSkySplit(graph,
                                     {.geometry = geometry, .gbuffer = gbuffer, .view = view,
                                      .voxelLight = voxelLight, .coneSky = coneSky},
                                     {.width = w, .height = h, .technique = mTechnique.get(),
                                      .techniqueName = mTechniqueName, .reference = mSettings,
                                      .raysPerPixel = kSplitRays, .row = &mRow});
            mSkySplit = true;
        }
        // Flicker along the camera path: the frame-to-frame change of the indirect light's
        // error at reprojected points (metrics/temporal_metrics.h), on luminance.
        const auto previous = graph.addExternal<PreviousIndirect>(
            "previous_indirect", pipeline::ResourceType::cpuImage("previous indirect", w, h),
            &mPrevious);
        graph.addPass({.name = "metric.indirect_flicker",
                       .reads = {indirect, truth, view, gbuffer, previous},
                       .writes = {"metric.indirect_flicker"},
                       .measurement = true},
                      [=, this](pipeline::PassContext& ctx) {
                          const PreviousIndirect& before = ctx.read(previous);
                          const scene::GBuffer& g = ctx.read(gbuffer);
                          const Image<float> now = computeLuminance(ctx.read(indirect));
                          const Image<float> truthNow = computeLuminance(ctx.read(truth).irradiance);
                          const metrics::TemporalFrame then{.technique = &before.technique,
                                                            .reference = &before.reference,
                                                            .linearDepth = &before.depth,
                                                            .projection = before.projection,
                                                            .view = before.view};
                          const metrics::TemporalFrame current{.technique = &now,
                                                               .reference = &truthNow,
                                                               .linearDepth = &g.depth,
                                                               .projection = g.projection,
                                                               .view = g.view,
                                                               .mask = &ctx.read(view).surface};
                          const auto change = metrics::computeTemporalChange(then, current);
                          mRow->set("indirect_flicker.rms", change.flickerRms)
                              .set("indirect_flicker.technique_change_rms", change.techniqueChangeRms)
                              .set("indirect_flicker.reference_change_rms", change.referenceChangeRms)
                              .set("indirect_flicker.used_share", change.usedShare);
                          return pipeline::PassOutcome{};
                      });
        graph.addPass({.name = "remember_indirect",
                       .reads = {indirect, truth, gbuffer},
                       .writes = {"indirect_frame_memory"},
                       .measurement = true},
                      [=, this](pipeline::PassContext& ctx) {
                          const scene::GBuffer& g = ctx.read(gbuffer);
                          mPrevious = PreviousIndirect{computeLuminance(ctx.read(indirect)),
                                                       computeLuminance(ctx.read(truth).irradiance),
                                                       g.depth, g.projection, g.view};
                          return pipeline::PassOutcome{};
                      });
        graph.addPass({.name = "images_indirect",
                       .reads = {indirect, truth, view},
                       .writes = {"images_indirect"},
                       .measurement = true},
                      [=, this](pipeline::PassContext& ctx) {
                          const std::string dir =
                              mContext.runDirectory() + "/frame" + std::to_string(ctx.frame());
                          std::filesystem::create_directories(dir);
                          const auto& a = ctx.read(indirect);
                          const auto& t = ctx.read(truth).irradiance;
                          const auto& surface = ctx.read(view).surface;
                          Image<glm::vec3> error(a.width, a.height, glm::vec3(0.0f));
                          for (std::size_t i = 0; i < error.pixels.size(); ++i)
                              if (surface.pixels[i])
                                  error.pixels[i] = a.pixels[i] - t.pixels[i];
                          experiment::writeExr(a, dir + "/indirect.exr");
                          experiment::writeExr(t, dir + "/indirect_reference.exr");
                          // Its noise floor, beside it (the report's image grid shows it under
                          // the reference).
                          if (const auto& se = ctx.read(truth).irradianceStdErr; se.width == t.width)
                              experiment::writeExr(se, dir + "/indirect_reference_stderr.exr");
                          experiment::writeExr(error, dir + "/indirect_error.exr");
                          mRow->set("image.indirect", dir + "/indirect.exr")
                              .set("image.indirect_reference", dir + "/indirect_reference.exr")
                              .set("image.indirect_error", dir + "/indirect_error.exr");
                          return pipeline::PassOutcome{};
                      });
        setup.outputs.push_back("images_indirect");
        for (const auto& m : setup.family.metrics)
            if (mRun.wantsMetric(m.name)) {
                setup.outputs.push_back("metric.indirect_" + m.name);
                if (m.name == "split" && mSkySplit)
                    setup.outputs.push_back("metric.sky_split");
                if (m.name == "flicker")
                    setup.outputs.push_back("indirect_frame_memory");
            }
    }

    const experiment::RunConfig& mRun;
    experiment::DriverContext& mContext;
    std::string mFamily;
    std::string mParamPrefix;
    std::unique_ptr<plugin::VoxelGiTechnique> mTechnique;
    std::string mTechniqueName;
    plugin::VoxelGiDefinition mDefinition;
    reference::ReferenceSettings mSettings;
    const scene::Scene* mScene = nullptr;
    const pipeline::FrameStart* mStart = nullptr;
    std::string mGeometryKey;
    bool mChangeKnown = false; //!< VoxelGiFrame::changeKnown and the fields below
    std::string mChangedFromKey;
    glm::dvec3 mChangedMin{1e300}, mChangedMax{-1e300};
    std::uint64_t mGeometryEditKey = 0;
    int mGeometryFrame = -1;
    experiment::ResultRow* mRow = nullptr;
    pipeline::FrameGraph* mGraph = nullptr;
    PreviousIndirect mPrevious;
    bool mHavePrevious = false;
    bool mSkySplit = false; // addConeSkySplit's passes exist
};

class VoxelGiFamily final : public experiment::Family {
public:
    std::unique_ptr<experiment::FamilyRun> beginRun(experiment::RunSetup& setup) const override
    {
        return std::make_unique<VoxelGiRun>(setup);
    }
};

plugin::FamilyInfo describeVoxelGiFamily()
{
    plugin::FamilyInfo info{
        .name = "voxel_gi",
        .summary = "voxel scene structures cone traced for indirect diffuse light",
        .input = "static triangles (voxelized), lights, sky, camera, G-buffer",
        .output = "indirect irradiance at G-buffer pixels",
        .groundTruth = "Embree path tracer, indirect only, same lights and bounce count",
        .metrics = {{"error", "RMSE, relative MSE, PSNR, mean signed error of the indirect "
                              "irradiance over surface pixels (indirect.*)"},
                    {"flip", "HDR-FLIP of the indirect irradiance (indirect.flip)"},
                    {"discontinuity",
                     "error of the differences between neighbouring pixels on smooth surfaces, "
                     "the reference's noise taken out (indirect.gradient_*); where the "
                     "technique reports its lookup levels, the same across level transitions "
                     "and within one level, and their ratio (indirect.transition_*, "
                     "indirect.within_level_*)"},
                    {"flicker", "frame-to-frame change of the indirect light's error along the "
                                "camera path, at reprojected points (indirect_flicker.*)"},
                    {"split", "the error split: technique against its own voxels gathered "
                              "along 256 rays per pixel (split.cone_*: the cone approximation) "
                              "and those against the ground truth (split.voxel_*: voxel geometry "
                              "and light buffers); in a lit frame whose sky comes through the "
                              "cones, the same for that sky against the truth's direct irradiance "
                              "without point lights (sky.*, split.sky_cone_*, split.sky_voxel_*)"}},
    };
    info.domain = plugin::FamilyDomain::Screen;
    info.report = {
        .cost = "technique_ms",
        .costLabel = "time of voxelize + light injection + gather (ms, CPU; "
                     "a bake excluded)",
        .error = "indirect.rmse",
        .errorLabel = "RMSE of indirect irradiance against ground truth",
        .passes = {"voxelize_ms", "light_injection_ms", "voxel_gather_ms"},
        .passTimeLabel = "time (ms, CPU)",
        .extraErrors = {{"indirect.flip", "HDR-FLIP of indirect irradiance"},
                        {"indirect.rel_mse", "relative MSE of indirect irradiance"},
                        {"indirect.gradient_excess",
                         "discontinuity: RMS error of neighbour differences above "
                         "the reference's noise"},
                        {"indirect.transition_gradient_rmse",
                         "level transitions: RMS error of neighbour differences "
                         "across a change of lookup level"},
                        {"indirect_flicker.rms",
                         "flicker: RMS frame-to-frame change of the indirect error"}},
        .paramErrors = {{"indirect.transition_ratio",
                         "level transitions: neighbour-difference error across / "
                         "within a level (1: not visible)"}},
        .tableColumns = {"indirect.mean_signed_error", "indirect.rel_mse", "indirect.flip",
                         "indirect.transition_ratio", "split.cone_rmse", "split.voxel_rmse",
                         "split.voxel_mean_signed_error", "memory.payload_bytes",
                         "counter.surface_voxels", "counter.steps_per_cone"},
        .acrossScenes = {{.x = "scene.wall_voxels",
                          .xLabel = "wall thickness (level-0 voxels)",
                          .y = "indirect.mean_signed_error",
                          .yLabel = "mean indirect irradiance inside (truth 0)",
                          .name = "voxel_gi_leak",
                          .title = "leak test: light inside a closed room lit from outside",
                          .caption = "Leak test (scenes/leak_room_*.yaml): a closed room lit only "
                                     "from outside; the ground truth inside is 0, so the mean "
                                     "indirect irradiance there is light that leaked through walls "
                                     "of the given thickness.",
                          .seriesBy = {"param.anti_leak"}},
                         {.x = "param.resolution",
                          .xLabel = "resolution (cascades: voxels per level and axis; "
                                    "adaptive_voxel_tree: leaves along the box)",
                          .y = "memory.payload_bytes",
                          .yLabel = "payload (bytes)",
                          .name = "voxel_gi_memory",
                          .title = "memory against resolution",
                          .caption = "Memory of the structure (cascades' payload: volumetric "
                                     "G-buffer, light and pre-combined buffers; the tree's: its "
                                     "probes) against its resolution, every scene."}},
        .baseline = "path_traced"};
    info.runtime = std::make_shared<VoxelGiFamily>();
    info.stressCases = voxelgi::makeVoxelGiStressCases;
    return info;
}

} // namespace
} // namespace rtlab::families

RTLAB_REGISTER_FAMILY(voxel_gi, rtlab::families::describeVoxelGiFamily)
