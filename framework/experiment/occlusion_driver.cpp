// The occlusion family in experiments. Each frame of the run is a frame graph
// (pipeline/frame_graph.h), culled before it runs:
//   sdf_remesh         mesh the scene's SDF models (needs sdf_models; reused while no edit starts)
//   character_pose     the characters' capsules at this frame (needs characters)
//   assemble_geometry  the frame's triangles
//   scene_upload       to the GPU (reused while the geometry is unchanged)
//   gbuffer            rasterise on Vulkan (timed: GPU and CPU)
//   view_inputs        view-space depth and normals, the technique's input
//   occlusion          the technique (timed the same way)
//   reference          Embree ground truth of exactly the quantity the technique declares (or the
//                      run's override), from the same G-buffer; reference_bent: the bent cone
//   metric.*           one pass per metric the run asks for (RunConfig::metrics); a ground truth
//                      that no requested metric reads is not computed
//   images             technique, reference, error and noise floor as EXR
// and one row per frame, with each pass recorded as run or skipped and why.

#include "experiment/runner.h"

#include "core/error.h"
#include "core/hash.h"
#include "experiment/gpu_timing.h"
#include "experiment/image_files.h"
#include "gpu/context.h"
#include "metrics/image_metrics.h"
#include "metrics/temporal_metrics.h"
#include "metrics/timing.h"
#include "pipeline/frame_graph.h"
#include "plugin/occlusion.h"
#include "reference/reference.h"
#include "reference/screen_space_reference.h"
#include "render/gbuffer_pass.h"
#include "scene/camera_paths.h"
#include "scene/scene_file.h"
#include "scene/sdf_shapes.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/mat3x3.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <optional>

namespace rtlab::experiment {

namespace {

reference::ReferenceSettings makeReferenceSettings(const plugin::OcclusionDefinition& d,
                                                   const RunConfig& run)
{
    reference::ReferenceSettings s;
    switch (d.quantity) {
    case plugin::OcclusionQuantity::CosineAo:
        s.quantity = reference::Quantity::Ao;
        break;
    case plugin::OcclusionQuantity::UniformAo:
        s.quantity = reference::Quantity::AoUniform;
        break;
    case plugin::OcclusionQuantity::Obscurance:
        s.quantity = reference::Quantity::Obscurance;
        break;
    }
    s.falloff = d.falloff == plugin::OcclusionFalloff::Smoothstep ? reference::Falloff::Smoothstep
                                                                  : reference::Falloff::Linear;
    s.radius = d.radius;
    // The run may measure against another quantity than the one declared (an ablation).
    if (!run.reference.quantity.empty())
        s.quantity = reference::parseQuantity(run.reference.quantity);
    if (!run.reference.falloff.empty())
        s.falloff = reference::parseFalloff(run.reference.falloff);
    if (run.reference.radius > 0.0)
        s.radius = run.reference.radius;
    s.targetStdErr = run.reference.targetStdErr;
    s.targetRelStdErr = run.reference.targetRelStdErr;
    s.maxSamples = run.reference.maxSamples;
    s.batchSize = std::min(s.batchSize, s.maxSamples);
    s.seed = run.reference.seed;
    return s;
}

const char* getQuantityColumnName(plugin::OcclusionQuantity q)
{
    switch (q) {
    case plugin::OcclusionQuantity::CosineAo:
        return "cosine_ao";
    case plugin::OcclusionQuantity::UniformAo:
        return "uniform_ao";
    case plugin::OcclusionQuantity::Obscurance:
        return "obscurance";
    }
    return "?";
}

// Mean over pixels where `mask` is set of f(i); NaN when none.
template <class F> double computeMaskedMean(const Image<std::uint8_t>& mask, F f)
{
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < mask.pixels.size(); ++i)
        if (mask.pixels[i]) {
            const double v = f(i);
            if (std::isfinite(v)) {
                sum += v;
                ++n;
            }
        }
    return n ? sum / double(n) : std::nan("");
}

void addErrorColumns(ResultRow& row, const std::string& prefix, const Image<float>& test,
                     const Image<float>& ref, const Image<std::uint8_t>& mask, bool full)
{
    const auto e = metrics::computeImageErrors(
        test, ref, metrics::ImageErrorOptions{.withSsim = false, .withFlip = false}, mask);
    row.set(prefix + ".rmse", e.rmse).set(prefix + ".mean_signed_error", e.meanSignedError);
    row.set(prefix + ".pixels", std::int64_t(e.pixels));
    if (full) {
        row.set(prefix + ".psnr", e.psnr);
        row.set(prefix + ".rel_mse", e.relMse)
            .set(prefix + ".non_finite_pixels", std::int64_t(e.nonFinitePixels));
    }
}

Image<std::uint8_t> intersectMasks(const Image<std::uint8_t>& a, const Image<std::uint8_t>& b)
{
    Image<std::uint8_t> out(a.width, a.height, 0);
    for (std::size_t i = 0; i < out.pixels.size(); ++i)
        out.pixels[i] = (a.pixels[i] && b.pixels[i]) ? 1 : 0;
    return out;
}

// The screen-space ground truth depends only on the view (depth, normals, matrices) and the
// settings, which the runs of a sweep that differ only in technique parameters share: the last few
// are kept in memory for the process (it has no disk cache, unlike the Embree reference).
const reference::ScreenSpaceResult&
computeScreenSpaceTruthCached(const reference::ScreenSpaceView& view,
                              const reference::ReferenceSettings& s, bool& fromCache)
{
    static std::mutex mutex;
    static std::vector<std::pair<std::string, reference::ScreenSpaceResult>> cache;
    constexpr std::size_t kEntries = 6;
    Hasher h;
    h.addBytes(view.linearDepth->pixels.data(), view.linearDepth->pixels.size() * sizeof(float))
        .addBytes(view.normal->pixels.data(), view.normal->pixels.size() * sizeof(glm::vec3))
        .addValue(view.linearDepth->width)
        .addValue(view.linearDepth->height)
        .addValue(view.projection)
        .addValue(view.view)
        .addValue(int(s.quantity))
        .addValue(s.radius)
        .addValue(int(s.falloff))
        .addValue(s.targetStdErr)
        .addValue(s.targetRelStdErr)
        .addValue(s.batchSize)
        .addValue(s.maxSamples)
        .addValue(s.seed);
    const std::string key = h.hexDigest();
    std::lock_guard lock(mutex);
    for (auto& [k, result] : cache)
        if (k == key) {
            fromCache = true;
            return result;
        }
    fromCache = false;
    if (cache.size() == kEntries)
        cache.erase(cache.begin());
    cache.emplace_back(key, reference::computeScreenSpaceReference(view, s));
    return cache.back().second;
}

} // namespace

std::vector<ResultRow> runOcclusionFamily(const RunConfig& run, const std::string& family,
                                          DriverContext& context, const ResultRow& common)
{
    if (scene::findAnalyticShape(run.scene))
        throw Error("scene '" + run.scene +
                    "' is an analytic shape for isosurface studies; the occlusion family "
                    "needs a scene with geometry and a camera (e.g. ao_testbed, tomorrow_town, or "
                    "a .yaml file)");
    scene::Scene scene = scene::loadScene(run.scene);
    if (run.frames > scene.frameCount && (run.cameraPath.empty() || run.cameraPath == "scene"))
        throw Error("the run asks for " + std::to_string(run.frames) + " frames but scene '" +
                    scene.name + "' has " + std::to_string(scene.frameCount) +
                    " (choose a camera_path such as orbit to move the camera "
                    "over more frames)");
    scene::selectCameraPath(scene, run.cameraPath, run.frames);
    const TechniqueChoice& choice = run.techniques.at(family);
    const plugin::TechniqueEntry* entry =
        context.registry().findTechnique(family, choice.technique);
    auto technique = entry->create(choice.params);
    auto* occlusion = dynamic_cast<plugin::OcclusionTechnique*>(technique.get());
    if (!occlusion)
        throw Error("technique '" + choice.technique +
                    "' does not implement the occlusion interface");
    const plugin::OcclusionDefinition definition = occlusion->definition();
    const reference::ReferenceSettings settings = makeReferenceSettings(definition, run);
    const reference::ReferenceSettings declared = makeReferenceSettings(definition, RunConfig{});
    const bool matches = settings.quantity == declared.quantity &&
                         settings.radius == declared.radius &&
                         (settings.quantity != reference::Quantity::Obscurance ||
                          settings.falloff == declared.falloff);

    ResultRow base = common;
    const config::ParamSet effective = technique->effectiveParams();
    for (const auto& [name, value] : effective.values())
        base.set("param." + name, config::formatValue(value));
    const scene::FeatureSet features = scene.computeFeatures();
    base.set("quantity", std::string(getQuantityColumnName(definition.quantity)))
        .set("radius", definition.radius)
        .set("reference.quantity", std::string(reference::getQuantityName(settings.quantity)))
        .set("reference.radius", settings.radius)
        .set("reference.matches_technique", matches)
        .set("camera_path", run.cameraPath.empty() ? std::string("scene") : run.cameraPath)
        .set("scene_features", features.toString());
    base.set("gpu_time_source",
             std::string(toString(chooseGpuTimeSource(context.getGpu().getDeviceInfo()))));

    // Which outputs the run keeps: one per requested metric, and the images.
    std::vector<std::string> outputs = {"images"};
    for (const auto& m : context.registry().findFamily(family)->metrics)
        if (run.wantsMetric(m.name))
            outputs.push_back("metric." + m.name);

    gpu::Context& gpu = context.getGpu();
    render::GBufferPass gbufferPass(gpu);
    std::vector<ResultRow> rows;
    // State carried between frames: what the graph may reuse.
    std::vector<scene::SdfMesh> sdfMeshes;
    std::optional<std::uint64_t> meshedEditKey;
    int meshedFrame = -1;
    std::string uploadedHash;
    int uploadedFrame = -1;
    // The previous frame's images, for the flicker metric.
    struct PreviousFrame {
        Image<float> technique, reference, referenceStdErr, depth;
        glm::mat4 projection{1.0f}, view{1.0f};
    };
    std::optional<PreviousFrame> previous;
    for (int frame = 0; frame < run.frames; ++frame) {
        ResultRow row = base;
        row.set("frame", std::int64_t(frame));
        const scene::Camera camera = scene.getCameraAt(frame);

        scene::RenderScene renderScene;
        std::vector<scene::PosedCapsule> capsules;
        scene::GBuffer g;
        Image<glm::vec3> viewNormal;
        Image<std::uint8_t> surface;
        plugin::OcclusionInput input;
        plugin::OcclusionOutput out;
        reference::ReferenceResult truth, bent;
        const reference::ScreenSpaceResult* screenTruth = nullptr;
        auto timeCpu = [&](const std::string& pass, auto&& work) {
            const auto start = std::chrono::steady_clock::now();
            work();
            row.set(pass + ".cpu_ms", std::chrono::duration<double, std::milli>(
                                          std::chrono::steady_clock::now() - start)
                                          .count());
        };

        pipeline::FrameGraph graph;
        graph.addExternal("scene");
        graph.addExternal("previous_frame", previous.has_value(),
                          frame == 0 ? "first frame of the run"
                                     : "the previous frame has no ground truth");
        if (!occlusion->outputsBentCone())
            graph.addExternal("technique_bent_cone", false,
                              "technique '" + choice.technique +
                                  "' outputs no bent normal or cone");
        graph.addPass({.name = "sdf_remesh",
                       .reads = {"scene"},
                       .writes = {"sdf_meshes"},
                       .needs = {scene::SceneFeature::SdfModels}},
                      [&] {
                          const std::uint64_t key = scene.getEditStateKey(frame);
                          if (meshedEditKey && *meshedEditKey == key)
                              return pipeline::PassOutcome::skipped("no edit starts after frame " +
                                                                    std::to_string(meshedFrame) +
                                                                    ": its SDF meshes are reused");
                          timeCpu("sdf_remesh", [&] { sdfMeshes = scene.meshSdfModels(frame); });
                          meshedEditKey = key;
                          meshedFrame = frame;
                          return pipeline::PassOutcome{};
                      });
        graph.addPass({.name = "character_pose",
                       .reads = {"scene"},
                       .writes = {"capsules"},
                       .needs = {scene::SceneFeature::Characters}},
                      [&] {
                          capsules = scene.poseCharacters(frame);
                          return pipeline::PassOutcome{};
                      });
        graph.addPass({.name = "assemble_geometry",
                       .reads = {"scene"},
                       .optionalReads = {"sdf_meshes", "capsules"},
                       .writes = {"geometry"}},
                      [&] {
                          renderScene = scene.assembleRenderScene(sdfMeshes, capsules, frame);
                          return pipeline::PassOutcome{};
                      });
        graph.addPass(
            {.name = "scene_upload", .reads = {"geometry"}, .writes = {"gpu_scene"}}, [&] {
                const std::string sceneHash = renderScene.computeContentHash();
                if (sceneHash == uploadedHash)
                    return pipeline::PassOutcome::skipped("geometry unchanged since frame " +
                                                          std::to_string(uploadedFrame));
                timeCpu("scene_upload", [&] { gbufferPass.setScene(renderScene); });
                uploadedHash = sceneHash;
                uploadedFrame = frame;
                return pipeline::PassOutcome{};
            });
        graph.addPass({.name = "gbuffer", .reads = {"gpu_scene"}, .writes = {"gbuffer"}}, [&] {
            gpu.takeRunLog();
            const auto report = metrics::measure(run.timing, [&] {
                gbufferPass.draw(camera, run.width, run.height);
                return collectGpuPassTimes(gpu);
            });
            addTimingColumns(row, "gbuffer", report);
            g = gbufferPass.readBack();
            return pipeline::PassOutcome{};
        });
        graph.addPass(
            {.name = "view_inputs", .reads = {"gbuffer"}, .writes = {"view_gbuffer"}}, [&] {
                const glm::mat3 toView(g.view);
                viewNormal = Image<glm::vec3>(g.width, g.height, glm::vec3(0.0f));
                surface = Image<std::uint8_t>(g.width, g.height, 0);
                for (std::size_t i = 0; i < viewNormal.pixels.size(); ++i)
                    if (g.materialId.pixels[i] != scene::kNoMaterial) {
                        viewNormal.pixels[i] = glm::normalize(toView * g.normal.pixels[i]);
                        surface.pixels[i] = 1;
                    }
                input.linearDepth = &g.depth;
                input.normal = &viewNormal;
                input.projection = g.projection;
                input.view = g.view;
                input.frameIndex = frame;
                input.gpu = &gpu;
                input.scene = &renderScene; // for ray-traced baselines only (plugin/occlusion.h)
                input.gbuffer = &g;
                return pipeline::PassOutcome{};
            });
        std::vector<std::string> techniqueWrites = {"technique_ambient"};
        if (occlusion->outputsBentCone())
            techniqueWrites.push_back("technique_bent_cone");
        graph.addPass(
            {.name = "occlusion", .reads = {"view_gbuffer"}, .writes = techniqueWrites}, [&] {
                gpu.takeRunLog();
                const auto report = metrics::measure(run.timing, [&] {
                    occlusion->compute(input, out);
                    return collectGpuPassTimes(gpu);
                });
                addTimingColumns(row, "occlusion", report);
                // The technique's time for the equal-time charts: its GPU passes when it ran any,
                // else its CPU wall time (ray-traced baselines); the row says which.
                const bool onGpu = !report.gpuMs.empty();
                row.set("technique_ms", onGpu ? report.gpuTotalMedianMs() : report.cpuMs.median)
                    .set("technique_time_source", std::string(onGpu ? "gpu" : "cpu"));
                for (const auto& [name, value] : technique->counters())
                    row.set("counter." + name, value);
                if (out.ambient.width != g.width || out.ambient.height != g.height)
                    throw Error(
                        "technique '" + choice.technique + "' returned an ambient image of " +
                        std::to_string(out.ambient.width) + "x" +
                        std::to_string(out.ambient.height) + " for a " + std::to_string(g.width) +
                        "x" + std::to_string(g.height) + " G-buffer");
                return pipeline::PassOutcome{};
            });
        const std::string fromCache =
            "read from the reference cache (same scene, G-buffer and settings)";
        graph.addPass(
            {.name = "reference", .reads = {"geometry", "gbuffer"}, .writes = {"ground_truth"}},
            [&] {
                truth = reference::computeReference(renderScene, g, settings);
                row.set("reference.seconds", truth.stats.seconds)
                    .set("reference.from_cache", truth.stats.fromCache)
                    .set("reference.samples_mean", truth.stats.meanSamples)
                    .set("reference.stderr_mean",
                         computeMaskedMean(surface,
                                           [&](std::size_t i) {
                                               return double(truth.occlusionStdErr.pixels[i]);
                                           }))
                    .set("reference.stderr_max", truth.stats.maxStdErr);
                return truth.stats.fromCache ? pipeline::PassOutcome::skipped(fromCache)
                                             : pipeline::PassOutcome{};
            });
        graph.addPass({.name = "reference_bent",
                       .reads = {"geometry", "gbuffer"},
                       .writes = {"ground_truth_bent"}},
                      [&] {
                          reference::ReferenceSettings bentSettings = settings;
                          bentSettings.quantity = reference::Quantity::Bent;
                          if (!std::isfinite(bentSettings.radius) || bentSettings.radius <= 0.0)
                              bentSettings.radius = std::numeric_limits<double>::infinity();
                          bent = reference::computeReference(renderScene, g, bentSettings);
                          return bent.stats.fromCache ? pipeline::PassOutcome::skipped(fromCache)
                                                      : pipeline::PassOutcome{};
                      });

        graph.addPass(
            {.name = "screen_space_reference",
             .reads = {"view_gbuffer"},
             .writes = {"ground_truth_screen"}},
            [&] {
                // The same quantity, seed and stopping rule, traced against the depth
                // buffer as a height field (reference/screen_space_reference.h).
                reference::ScreenSpaceView view{&g.depth, &viewNormal, g.projection, g.view};
                bool fromCache = false;
                timeCpu("screen_space_reference", [&] {
                    screenTruth = &computeScreenSpaceTruthCached(view, settings, fromCache);
                });
                return fromCache
                           ? pipeline::PassOutcome::skipped("computed by an earlier run of this "
                                                            "process (same view and settings)")
                           : pipeline::PassOutcome{};
            });

        // Metrics: one pass each, so that a run that does not ask for one does not pay for it
        // (nor for a ground truth only it reads).
        auto metricPass = [&](const std::string& name, std::vector<std::string> reads,
                              auto&& compute) {
            graph.addPass(
                {.name = "metric." + name, .reads = std::move(reads), .writes = {"metric." + name}},
                [&, compute] {
                    compute();
                    return pipeline::PassOutcome{};
                });
        };
        metricPass("error", {"technique_ambient", "ground_truth", "view_gbuffer"}, [&] {
            addErrorColumns(row, "ao", out.ambient, truth.occlusion, surface, true);
        });
        metricPass("ssim", {"technique_ambient", "ground_truth", "view_gbuffer"}, [&] {
            row.set("ao.ssim",
                    metrics::computeImageErrors(out.ambient, truth.occlusion,
                                                {.withSsim = true, .withFlip = false}, surface)
                        .ssim);
        });
        metricPass("flip", {"technique_ambient", "ground_truth", "view_gbuffer"}, [&] {
            row.set("ao.flip",
                    metrics::computeImageErrors(out.ambient, truth.occlusion,
                                                {.withSsim = false, .withFlip = true}, surface)
                        .flip);
        });
        metricPass("masks", {"technique_ambient", "ground_truth", "view_gbuffer"}, [&] {
            const auto edges = intersectMasks(metrics::makeDepthEdgeMask(g.depth, 2, 0.1), surface);
            const auto border =
                intersectMasks(metrics::makeBorderMask(g.width, g.height, 8), surface);
            const auto thin = intersectMasks(metrics::makeThinStructureMask(surface, 2), surface);
            addErrorColumns(row, "ao_depth_edges", out.ambient, truth.occlusion, edges, false);
            addErrorColumns(row, "ao_border", out.ambient, truth.occlusion, border, false);
            addErrorColumns(row, "ao_thin", out.ambient, truth.occlusion, thin, false);
        });
        metricPass("bent_cone", {"technique_bent_cone", "ground_truth_bent", "view_gbuffer"}, [&] {
            const glm::mat3 toWorld = glm::transpose(glm::mat3(g.view));
            const bool hasBent = out.bentNormal.size() == viewNormal.size();
            const bool hasAperture = out.coneAperture.size() == viewNormal.size();
            row.set("bent.angle_error_deg",
                    hasBent ? computeMaskedMean(
                                  surface,
                                  [&](std::size_t i) {
                                      const glm::vec3 t = out.bentNormal.pixels[i];
                                      const glm::vec3 r = bent.bentNormal.pixels[i];
                                      if (glm::dot(t, t) == 0.0f || glm::dot(r, r) == 0.0f)
                                          return std::nan("");
                                      const float c =
                                          glm::dot(glm::normalize(toWorld * t), glm::normalize(r));
                                      return double(
                                          glm::degrees(std::acos(std::clamp(c, -1.0f, 1.0f))));
                                  })
                            : std::nan(""));
            row.set("cone.aperture_error_deg",
                    hasAperture ? computeMaskedMean(surface,
                                                    [&](std::size_t i) {
                                                        return double(glm::degrees(
                                                            out.coneAperture.pixels[i] -
                                                            bent.aperture.pixels[i]));
                                                    })
                                : std::nan(""));
            row.set("cone.aperture_abs_error_deg",
                    hasAperture ? computeMaskedMean(surface,
                                                    [&](std::size_t i) {
                                                        return double(glm::degrees(
                                                            std::abs(out.coneAperture.pixels[i] -
                                                                     bent.aperture.pixels[i])));
                                                    })
                                : std::nan(""));
            row.set("cone_visibility.count", std::int64_t(out.coneVisibility.size()));
        });
        metricPass(
            "screen_space_split",
            {"technique_ambient", "ground_truth", "ground_truth_screen", "view_gbuffer"}, [&] {
                // technique vs rays on the depth buffer: the estimator's own error;
                // rays on the depth buffer vs the full scene: what screen space cannot see.
                addErrorColumns(row, "ao_vs_screen_truth", out.ambient,
                                screenTruth->reference.occlusion, surface, false);
                addErrorColumns(row, "screen_truth", screenTruth->reference.occlusion,
                                truth.occlusion, surface, false);
                row.set("screen_truth.off_screen_share", screenTruth->meanOffScreenShare)
                    .set("screen_truth.samples_mean", screenTruth->reference.stats.meanSamples);
            });
        metricPass(
            "flicker", {"technique_ambient", "ground_truth", "view_gbuffer", "previous_frame"},
            [&] {
                const metrics::TemporalFrame before{.technique = &previous->technique,
                                                    .reference = &previous->reference,
                                                    .linearDepth = &previous->depth,
                                                    .projection = previous->projection,
                                                    .view = previous->view,
                                                    .referenceStdErr = &previous->referenceStdErr};
                const metrics::TemporalFrame now{.technique = &out.ambient,
                                                 .reference = &truth.occlusion,
                                                 .linearDepth = &g.depth,
                                                 .projection = g.projection,
                                                 .view = g.view,
                                                 .referenceStdErr = &truth.occlusionStdErr,
                                                 .mask = &surface};
                const metrics::TemporalChange change = metrics::computeTemporalChange(before, now);
                row.set("flicker.rms", change.flickerRms)
                    .set("flicker.technique_change_rms", change.techniqueChangeRms)
                    .set("flicker.reference_change_rms", change.referenceChangeRms)
                    .set("flicker.reference_noise_floor_rms", change.referenceNoiseFloorRms)
                    .set("flicker.used_share", change.usedShare);
            });
        // Images: numbers in EXR (the report makes the PNGs).
        graph.addPass({.name = "images",
                       .reads = {"technique_ambient", "ground_truth", "view_gbuffer"},
                       .writes = {"images"}},
                      [&] {
                          const std::string dir =
                              context.runDirectory() + "/frame" + std::to_string(frame);
                          std::filesystem::create_directories(dir);
                          Image<float> error(g.width, g.height, 0.0f);
                          for (std::size_t i = 0; i < error.pixels.size(); ++i)
                              error.pixels[i] = surface.pixels[i] ? out.ambient.pixels[i] -
                                                                        truth.occlusion.pixels[i]
                                                                  : 0.0f;
                          writeExr(out.ambient, dir + "/technique.exr");
                          writeExr(truth.occlusion, dir + "/reference.exr");
                          writeExr(truth.occlusionStdErr, dir + "/reference_stderr.exr");
                          writeExr(error, dir + "/error.exr");
                          row.set("image.technique", dir + "/technique.exr")
                              .set("image.reference", dir + "/reference.exr")
                              .set("image.error", dir + "/error.exr");
                          return pipeline::PassOutcome{};
                      });

        const auto records = graph.execute(features, outputs);
        const auto ran = [&](const std::string& name) {
            return std::any_of(records.begin(), records.end(),
                               [&](const auto& r) { return r.name == name && r.ran; });
        };
        const bool haveTruth = truth.occlusion.size() == g.depth.size() && !g.depth.pixels.empty();
        if (ran("occlusion") && haveTruth)
            previous = PreviousFrame{out.ambient, truth.occlusion, truth.occlusionStdErr,
                                     g.depth,     g.projection,    g.view};
        else
            previous.reset();
        PassLog passes;
        for (const auto& r : records)
            r.ran ? passes.add(r.name) : passes.skip(r.name, r.reason);
        passes.write(row);
        rows.push_back(std::move(row));
    }
    return rows;
}

} // namespace rtlab::experiment
