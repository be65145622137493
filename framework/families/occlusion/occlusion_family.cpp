// The occlusion family: screen-space ambient occlusion / obscurance, with bent normals and cones.
// Its passes, on the shared frame start (pipeline/frame_start.h):
//   occlusion          the technique (timed with the run's repeats: GPU and CPU)
//   reference          Embree ground truth of exactly the quantity the technique declares (or the
//                      run's override), from the same G-buffer; reference_bent: the bent cone
//   screen_space_reference  the same quantity traced against the depth buffer
//   metric.*           one pass per metric the run asks for (RunConfig::metrics); a ground truth
//                      that no requested metric reads is not computed
//   remember_frame     what the next frame's flicker metric compares with
//   images             technique, reference, error and noise floor as EXR
// and one row per frame, with each pass recorded as run or skipped and why.

#include "families/occlusion/occlusion.h"
#include "families/occlusion/stress_cases.h"

#include "core/error.h"
#include "core/hash.h"
#include "experiment/family.h"
#include "experiment/image_files.h"
#include "experiment/runner.h"
#include "gpu/resources.h"
#include "metrics/image_metrics.h"
#include "metrics/temporal_metrics.h"
#include "pipeline/compose.h"
#include "pipeline/frame_graph.h"
#include "pipeline/frame_start.h"
#include "reference/reference.h"
#include "reference/screen_space_reference.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>

namespace rtlab::families {

namespace {

reference::ReferenceSettings makeReferenceSettings(const plugin::OcclusionDefinition& d,
                                                   const experiment::RunConfig& run)
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
    experiment::applySamplingOptions(run.reference, s);
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

void addErrorColumns(experiment::ResultRow& row, const std::string& prefix,
                     const Image<float>& test, const Image<float>& ref,
                     const Image<std::uint8_t>& mask, bool full)
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

// The previous frame's images, for the flicker metric.
struct PreviousFrame {
    Image<float> technique, reference, referenceStdErr, depth;
    glm::mat4 projection{1.0f}, view{1.0f};
};

class OcclusionRun final : public experiment::FamilyRun {
public:
    explicit OcclusionRun(experiment::RunSetup& setup)
        : mRun(setup.run), mContext(setup.context), mFamily(setup.family.name),
          mParamPrefix(setup.paramPrefix)
    {
        if (!setup.frameStart)
            throw Error("the occlusion family needs the screen-space frame start");
        mTechnique = experiment::createTechnique<plugin::OcclusionTechnique>(
            mRun, mContext.registry(), mFamily);
        mTechniqueName = mRun.techniques.at(mFamily).technique;
        mDefinition = mTechnique->definition();
        mSettings = makeReferenceSettings(mDefinition, mRun);
        const reference::ReferenceSettings declared =
            makeReferenceSettings(mDefinition, experiment::RunConfig{});
        mMatches = mSettings.quantity == declared.quantity && mSettings.radius == declared.radius &&
                   (mSettings.quantity != reference::Quantity::Obscurance ||
                    mSettings.falloff == declared.falloff);
        addPasses(setup);
    }

    void describe(experiment::ResultRow& row) const override
    {
        experiment::addParamColumns(row, *mTechnique, mParamPrefix);
        row.set("quantity", std::string(getQuantityColumnName(mDefinition.quantity)))
            .set("radius", mDefinition.radius)
            .set("reference.quantity", std::string(reference::getQuantityName(mSettings.quantity)))
            .set("reference.radius", mSettings.radius)
            .set("reference.matches_technique", mMatches);
    }

    void beginFrame(int frame, experiment::ResultRow& row) override
    {
        mRow = &row;
        mGraph->setExternalAvailable("previous_frame", mHavePrevious,
                                     frame == 0 ? "first frame of the run"
                                                : "the previous frame has no ground truth");
    }

    void endFrame(int frame, const std::vector<pipeline::PassRecord>& records,
                  experiment::ResultRow& row) override
    {
        mHavePrevious = false;
        for (const auto& r : records) {
            if (r.name == "remember_frame")
                mHavePrevious = r.ran;
            // The technique's time for the equal-time charts: its GPU passes when it ran any,
            // else its CPU wall time (ray-traced baselines); the row says which.
            if (r.name == "occlusion" && r.ran && r.time) {
                const bool onGpu = !r.time->gpuMs.empty();
                row.set("technique_ms", onGpu ? r.time->gpuTotalMedianMs() : r.time->cpuMs.median)
                    .set("technique_time_source", std::string(onGpu ? "gpu" : "cpu"));
            }
        }
        mRow = nullptr;
    }

private:
    void addPasses(experiment::RunSetup& setup)
    {
        pipeline::FrameGraph& graph = setup.graph;
        pipeline::FrameStart& start = *setup.frameStart;
        mGraph = &graph;
        const int w = mRun.width, h = mRun.height;
        const auto geometry = start.geometry();
        const auto gbuffer = start.gbufferCpu();
        const auto view = start.viewInputs();
        const pipeline::Resource<plugin::OcclusionOutput> ambient{
            "technique_ambient", pipeline::ResourceType::cpuImage("ao + bent normal + cone", w, h)};
        const pipeline::Resource<reference::ReferenceResult> truth{
            "ground_truth", pipeline::ResourceType::cpuImage("reference occlusion", w, h)};
        const pipeline::Resource<reference::ReferenceResult> truthBent{
            "ground_truth_bent", pipeline::ResourceType::cpuImage("reference bent cone", w, h)};
        const pipeline::Resource<const reference::ScreenSpaceResult*> truthScreen{
            "ground_truth_screen",
            pipeline::ResourceType::cpuImage("screen-space reference", w, h)};
        const auto previous = graph.addExternal<PreviousFrame>(
            "previous_frame", pipeline::ResourceType::cpuImage("previous frame", w, h), &mPrevious);

        if (!mTechnique->outputsBentCone())
            graph.addExternal("technique_bent_cone", false,
                              "technique '" + mTechniqueName + "' outputs no bent normal or cone");
        std::vector<pipeline::ResourceRef> techniqueWrites = {ambient};
        if (mTechnique->outputsBentCone())
            techniqueWrites.push_back("technique_bent_cone");
        // The technique's call, the same whichever view it reads.
        auto runTechnique = [this, w, h](const plugin::OcclusionInput& input,
                                         plugin::OcclusionOutput& out) {
            mTechnique->compute(input, out);
            for (const auto& [name, value] : mTechnique->counters())
                mRow->set("counter." + name, value);
            if (out.ambient.width != w || out.ambient.height != h)
                throw Error("technique '" + mTechniqueName + "' returned an ambient image of " +
                            std::to_string(out.ambient.width) + "x" +
                            std::to_string(out.ambient.height) + " for a " + std::to_string(w) +
                            "x" + std::to_string(h) + " G-buffer");
            return pipeline::PassOutcome{};
        };
        const auto aoSlot = pipeline::Compose::ambientOcclusionSlot(w, h);
        const auto conesSlot = pipeline::Compose::coneVisibilitySlot(w, h);
        const auto viewGpu = start.viewInputsGpu();
        const auto depthGpu = start.viewDepthGpu();
        const auto normalGpu = start.viewNormalGpu();
        // The technique's input from the view inputs on the GPU.
        auto makeGpuInput = [this, viewGpu, depthGpu,
                             normalGpu](const pipeline::PassContext& ctx) {
            const pipeline::GpuViewInputs& v = ctx.read(viewGpu);
            plugin::OcclusionInput input;
            input.projection = v.projection;
            input.view = v.view;
            input.frameIndex = ctx.frame();
            input.gpu = &mContext.getGpu();
            input.gpuLinearDepth = &ctx.read(depthGpu);
            input.gpuNormal = &ctx.read(normalGpu);
            return input;
        };
        if (mTechnique->acceptsGpuInputs() && mTechnique->outputsOnGpu() && mRun.gbufferOnGpu) {
            // G-buffer and result stay on the GPU: the technique binds the view inputs made
            // there, the lit frame binds the technique's images, and the result comes to the CPU
            // in a pass of its own, which runs only when a pass that runs reads it (metrics,
            // images, a CPU reader of the slots).
            const pipeline::Resource<plugin::OcclusionGpuOutput> onGpu{
                "technique_gpu",
                pipeline::ResourceType::gpuImage("the technique's images (r32f ao or 4 x rgba32f "
                                                 "cone visibilities)",
                                                 w, h)};
            graph.addPass(
                {.name = "occlusion",
                 .reads = {viewGpu, depthGpu, normalGpu},
                 .writes = {onGpu},
                 .timing = pipeline::PassTiming::Repeated},
                [this, makeGpuInput, onGpu, w, h](pipeline::PassContext& ctx) {
                    plugin::OcclusionInput input = makeGpuInput(ctx);
                    input.readBack = false;
                    plugin::OcclusionOutput out;
                    mTechnique->compute(input, out);
                    for (const auto& [name, value] : mTechnique->counters())
                        mRow->set("counter." + name, value);
                    const plugin::OcclusionGpuOutput& images = out.gpu;
                    std::vector<const gpu::Image*> all(images.coneVisibility.begin(),
                                                       images.coneVisibility.end());
                    all.push_back(images.ambient);
                    if (images.ambient == nullptr && images.coneVisibility[0] == nullptr)
                        throw Error("technique '" + mTechniqueName +
                                    "' says its outputs stay on the GPU but left none there");
                    for (const gpu::Image* image : all)
                        if (image != nullptr && (int(image->getDesc().width) != w ||
                                                 int(image->getDesc().height) != h))
                            throw Error("technique '" + mTechniqueName + "' left a " +
                                        std::to_string(image->getDesc().width) + "x" +
                                        std::to_string(image->getDesc().height) +
                                        " image on the GPU for a " + std::to_string(w) + "x" +
                                        std::to_string(h) + " G-buffer");
                    ctx.write(onGpu) = images;
                    return pipeline::PassOutcome{};
                });
            graph.addPass({.name = "occlusion_readback",
                           .reads = {onGpu},
                           .writes = techniqueWrites,
                           .forReaders = true},
                          [this, ambient, w, h](pipeline::PassContext& ctx) {
                              plugin::OcclusionOutput& out = ctx.write(ambient);
                              mTechnique->readBack(out);
                              if (out.ambient.width != w || out.ambient.height != h)
                                  throw Error("technique '" + mTechniqueName +
                                              "' read back an ambient image of " +
                                              std::to_string(out.ambient.width) + "x" +
                                              std::to_string(out.ambient.height) + " for a " +
                                              std::to_string(w) + "x" + std::to_string(h) +
                                              " G-buffer");
                              return pipeline::PassOutcome{};
                          });
            const auto aoGpuSlot = pipeline::Compose::ambientOcclusionGpuSlot(w, h);
            const auto conesGpuSlot = pipeline::Compose::coneVisibilityGpuSlot(w, h);
            graph.addPass({.name = "occlusion_gpu_slots",
                           .reads = {onGpu},
                           .writes = {aoGpuSlot, conesGpuSlot}},
                          [onGpu, aoGpuSlot, conesGpuSlot](pipeline::PassContext& ctx) {
                              const plugin::OcclusionGpuOutput& images = ctx.read(onGpu);
                              // Cones when the technique gives them (the lighting pass takes
                              // one visibility input).
                              const bool cones = images.coneVisibility[0] != nullptr;
                              ctx.write(aoGpuSlot) = cones ? nullptr : images.ambient;
                              ctx.write(conesGpuSlot) = images.coneVisibility;
                              return pipeline::PassOutcome{};
                          });
        } else if (mTechnique->acceptsGpuInputs() && mRun.gbufferOnGpu) {
            // The G-buffer stays on the GPU: the technique binds the view inputs made there, and
            // the frame reads the G-buffer back only if another pass that runs needs it.
            graph.addPass({.name = "occlusion",
                           .reads = {viewGpu, depthGpu, normalGpu},
                           .writes = techniqueWrites,
                           .timing = pipeline::PassTiming::Repeated},
                          [makeGpuInput, ambient, runTechnique](pipeline::PassContext& ctx) {
                              return runTechnique(makeGpuInput(ctx), ctx.write(ambient));
                          });
        } else {
            graph.addPass(
                {.name = "occlusion",
                 .reads = {gbuffer, view, geometry},
                 .writes = techniqueWrites,
                 .timing = pipeline::PassTiming::Repeated},
                [this, gbuffer, view, geometry, ambient, runTechnique](pipeline::PassContext& ctx) {
                    const scene::GBuffer& g = ctx.read(gbuffer);
                    plugin::OcclusionInput input;
                    input.linearDepth = &g.depth;
                    input.normal = &ctx.read(view).normal;
                    input.projection = g.projection;
                    input.view = g.view;
                    input.frameIndex = ctx.frame();
                    input.gpu = &mContext.getGpu();
                    input.scene = &ctx.read(
                        geometry); // ray-traced baselines only (families/occlusion/occlusion.h)
                    input.gbuffer = &g;
                    return runTechnique(input, ctx.write(ambient));
                });
        }
        // The frame's CPU slots (pipeline/compose.h), for CPU readers, and for the lit frame
        // when the GPU slots were not written above (compose uploads them then).
        graph.addPass(
            {.name = "occlusion_slots", .reads = {ambient}, .writes = {aoSlot, conesSlot}},
            [ambient, aoSlot, conesSlot](pipeline::PassContext& ctx) {
                const plugin::OcclusionOutput& out = ctx.read(ambient);
                ctx.write(aoSlot) = out.ambient;
                ctx.write(conesSlot) = out.coneVisibility;
                return pipeline::PassOutcome{};
            });
        const std::string fromCache =
            "read from the reference cache (same scene, G-buffer and settings)";
        graph.addPass(
            {.name = "reference",
             .reads = {geometry, gbuffer, view},
             .writes = {truth},
             .measurement = true},
            [this, geometry, gbuffer, view, truth, fromCache](pipeline::PassContext& ctx) {
                reference::ReferenceResult& t = ctx.write(truth);
                t = reference::computeReference(ctx.read(geometry), ctx.read(gbuffer), mSettings);
                const auto& surface = ctx.read(view).surface;
                mRow->set("reference.seconds", t.stats.seconds)
                    .set("reference.from_cache", t.stats.fromCache)
                    .set("reference.samples_mean", t.stats.meanSamples)
                    .set("reference.stderr_mean",
                         computeMaskedMean(
                             surface,
                             [&](std::size_t i) { return double(t.occlusionStdErr.pixels[i]); }))
                    .set("reference.stderr_max", t.stats.maxStdErr);
                return t.stats.fromCache ? pipeline::PassOutcome::skipped(fromCache)
                                         : pipeline::PassOutcome{};
            });
        graph.addPass({.name = "reference_bent",
                       .reads = {geometry, gbuffer},
                       .writes = {truthBent},
                       .measurement = true},
                      [this, geometry, gbuffer, truthBent, fromCache](pipeline::PassContext& ctx) {
                          reference::ReferenceSettings bentSettings = mSettings;
                          bentSettings.quantity = reference::Quantity::Bent;
                          if (!std::isfinite(bentSettings.radius) || bentSettings.radius <= 0.0)
                              bentSettings.radius = std::numeric_limits<double>::infinity();
                          reference::ReferenceResult& b = ctx.write(truthBent);
                          b = reference::computeReference(ctx.read(geometry), ctx.read(gbuffer),
                                                          bentSettings);
                          return b.stats.fromCache ? pipeline::PassOutcome::skipped(fromCache)
                                                   : pipeline::PassOutcome{};
                      });
        graph.addPass(
            {.name = "screen_space_reference",
             .reads = {gbuffer, view},
             .writes = {truthScreen},
             .measurement = true},
            [this, gbuffer, view, truthScreen](pipeline::PassContext& ctx) {
                // The same quantity, seed and stopping rule, traced against the depth
                // buffer as a height field (reference/screen_space_reference.h).
                const scene::GBuffer& g = ctx.read(gbuffer);
                reference::ScreenSpaceView v{&g.depth, &ctx.read(view).normal, g.projection,
                                             g.view};
                bool cached = false;
                ctx.write(truthScreen) = &computeScreenSpaceTruthCached(v, mSettings, cached);
                return cached ? pipeline::PassOutcome::skipped("computed by an earlier run of this "
                                                               "process (same view and settings)")
                              : pipeline::PassOutcome{};
            });

        // Metrics: one pass each, so that a run that does not ask for one does not pay for it
        // (nor for a ground truth only it reads).
        auto metricPass = [&](const std::string& name, std::vector<pipeline::ResourceRef> reads,
                              std::function<void(pipeline::PassContext&)> compute) {
            graph.addPass({.name = "metric." + name,
                           .reads = std::move(reads),
                           .writes = {"metric." + name},
                           .measurement = true},
                          [compute](pipeline::PassContext& ctx) {
                              compute(ctx);
                              return pipeline::PassOutcome{};
                          });
        };
        metricPass("error", {ambient, truth, view}, [=, this](pipeline::PassContext& ctx) {
            addErrorColumns(*mRow, "ao", ctx.read(ambient).ambient, ctx.read(truth).occlusion,
                            ctx.read(view).surface, true);
        });
        metricPass("ssim", {ambient, truth, view}, [=, this](pipeline::PassContext& ctx) {
            mRow->set("ao.ssim", metrics::computeImageErrors(
                                     ctx.read(ambient).ambient, ctx.read(truth).occlusion,
                                     {.withSsim = true, .withFlip = false}, ctx.read(view).surface)
                                     .ssim);
        });
        metricPass("flip", {ambient, truth, view}, [=, this](pipeline::PassContext& ctx) {
            mRow->set("ao.flip", metrics::computeImageErrors(
                                     ctx.read(ambient).ambient, ctx.read(truth).occlusion,
                                     {.withSsim = false, .withFlip = true}, ctx.read(view).surface)
                                     .flip);
        });
        metricPass("masks", {ambient, truth, view, gbuffer}, [=, this](pipeline::PassContext& ctx) {
            const auto& g = ctx.read(gbuffer);
            const auto& surface = ctx.read(view).surface;
            const auto& a = ctx.read(ambient).ambient;
            const auto& t = ctx.read(truth).occlusion;
            const auto edges = intersectMasks(metrics::makeDepthEdgeMask(g.depth, 2, 0.1), surface);
            const auto border =
                intersectMasks(metrics::makeBorderMask(g.width, g.height, 8), surface);
            const auto thin = intersectMasks(metrics::makeThinStructureMask(surface, 2), surface);
            addErrorColumns(*mRow, "ao_depth_edges", a, t, edges, false);
            addErrorColumns(*mRow, "ao_border", a, t, border, false);
            addErrorColumns(*mRow, "ao_thin", a, t, thin, false);
        });
        metricPass(
            "bent_cone", {ambient, "technique_bent_cone", truthBent, view, gbuffer},
            [=, this](pipeline::PassContext& ctx) {
                const auto& out = ctx.read(ambient);
                const auto& bent = ctx.read(truthBent);
                const auto& v = ctx.read(view);
                const glm::mat3 toWorld = glm::transpose(glm::mat3(ctx.read(gbuffer).view));
                const bool hasBent = out.bentNormal.size() == v.normal.size();
                const bool hasAperture = out.coneAperture.size() == v.normal.size();
                mRow->set("bent.angle_error_deg",
                          hasBent ? computeMaskedMean(
                                        v.surface,
                                        [&](std::size_t i) {
                                            const glm::vec3 t = out.bentNormal.pixels[i];
                                            const glm::vec3 r = bent.bentNormal.pixels[i];
                                            if (glm::dot(t, t) == 0.0f || glm::dot(r, r) == 0.0f)
                                                return std::nan("");
                                            const float c = glm::dot(glm::normalize(toWorld * t),
                                                                     glm::normalize(r));
                                            return double(glm::degrees(
                                                std::acos(std::clamp(c, -1.0f, 1.0f))));
                                        })
                                  : std::nan(""));
                mRow->set("cone.aperture_error_deg",
                          hasAperture ? computeMaskedMean(v.surface,
                                                          [&](std::size_t i) {
                                                              return double(glm::degrees(
                                                                  out.coneAperture.pixels[i] -
                                                                  bent.aperture.pixels[i]));
                                                          })
                                      : std::nan(""));
                mRow->set("cone.aperture_abs_error_deg",
                          hasAperture ? computeMaskedMean(v.surface,
                                                          [&](std::size_t i) {
                                                              return double(glm::degrees(std::abs(
                                                                  out.coneAperture.pixels[i] -
                                                                  bent.aperture.pixels[i])));
                                                          })
                                      : std::nan(""));
                mRow->set("cone_visibility.count", std::int64_t(out.coneVisibility.size()));
            });
        metricPass("screen_space_split", {ambient, truth, truthScreen, view},
                   [=, this](pipeline::PassContext& ctx) {
                       // technique vs rays on the depth buffer: the estimator's own error; rays on
                       // the depth buffer vs the full scene: what screen space cannot see.
                       const auto& surface = ctx.read(view).surface;
                       const reference::ScreenSpaceResult& screen = *ctx.read(truthScreen);
                       addErrorColumns(*mRow, "ao_vs_screen_truth", ctx.read(ambient).ambient,
                                       screen.reference.occlusion, surface, false);
                       addErrorColumns(*mRow, "screen_truth", screen.reference.occlusion,
                                       ctx.read(truth).occlusion, surface, false);
                       mRow->set("screen_truth.off_screen_share", screen.meanOffScreenShare)
                           .set("screen_truth.samples_mean", screen.reference.stats.meanSamples);
                   });
        metricPass(
            "flicker", {ambient, truth, view, gbuffer, previous},
            [=, this](pipeline::PassContext& ctx) {
                const PreviousFrame& before = ctx.read(previous);
                const scene::GBuffer& g = ctx.read(gbuffer);
                const reference::ReferenceResult& t = ctx.read(truth);
                const metrics::TemporalFrame then{.technique = &before.technique,
                                                  .reference = &before.reference,
                                                  .linearDepth = &before.depth,
                                                  .projection = before.projection,
                                                  .view = before.view,
                                                  .referenceStdErr = &before.referenceStdErr};
                const metrics::TemporalFrame now{.technique = &ctx.read(ambient).ambient,
                                                 .reference = &t.occlusion,
                                                 .linearDepth = &g.depth,
                                                 .projection = g.projection,
                                                 .view = g.view,
                                                 .referenceStdErr = &t.occlusionStdErr,
                                                 .mask = &ctx.read(view).surface};
                const metrics::TemporalChange change = metrics::computeTemporalChange(then, now);
                mRow->set("flicker.rms", change.flickerRms)
                    .set("flicker.technique_change_rms", change.techniqueChangeRms)
                    .set("flicker.reference_change_rms", change.referenceChangeRms)
                    .set("flicker.reference_noise_floor_rms", change.referenceNoiseFloorRms)
                    .set("flicker.used_share", change.usedShare);
            });
        // What the flicker metric of the next frame compares with (only when it is asked for).
        graph.addPass({.name = "remember_frame",
                       .reads = {ambient, truth, gbuffer},
                       .writes = {"frame_memory"},
                       .measurement = true},
                      [=, this](pipeline::PassContext& ctx) {
                          const scene::GBuffer& g = ctx.read(gbuffer);
                          const reference::ReferenceResult& t = ctx.read(truth);
                          mPrevious = PreviousFrame{ctx.read(ambient).ambient,
                                                    t.occlusion,
                                                    t.occlusionStdErr,
                                                    g.depth,
                                                    g.projection,
                                                    g.view};
                          return pipeline::PassOutcome{};
                      });
        // Images: numbers in EXR (the report makes the PNGs).
        graph.addPass({.name = "images",
                       .reads = {ambient, truth, view},
                       .writes = {"images"},
                       .measurement = true},
                      [=, this](pipeline::PassContext& ctx) {
                          const std::string dir =
                              mContext.runDirectory() + "/frame" + std::to_string(ctx.frame());
                          std::filesystem::create_directories(dir);
                          const auto& a = ctx.read(ambient).ambient;
                          const auto& t = ctx.read(truth);
                          const auto& surface = ctx.read(view).surface;
                          Image<float> error(a.width, a.height, 0.0f);
                          for (std::size_t i = 0; i < error.pixels.size(); ++i)
                              error.pixels[i] =
                                  surface.pixels[i] ? a.pixels[i] - t.occlusion.pixels[i] : 0.0f;
                          experiment::writeExr(a, dir + "/technique.exr");
                          experiment::writeExr(t.occlusion, dir + "/reference.exr");
                          experiment::writeExr(t.occlusionStdErr, dir + "/reference_stderr.exr");
                          experiment::writeExr(error, dir + "/error.exr");
                          mRow->set("image.technique", dir + "/technique.exr")
                              .set("image.reference", dir + "/reference.exr")
                              .set("image.error", dir + "/error.exr");
                          return pipeline::PassOutcome{};
                      });

        // Which outputs the run keeps: one per requested metric, and the images.
        setup.outputs.push_back("images");
        for (const auto& m : setup.family.metrics)
            if (mRun.wantsMetric(m.name)) {
                setup.outputs.push_back("metric." + m.name);
                if (m.name == "flicker")
                    setup.outputs.push_back("frame_memory");
            }
    }

    const experiment::RunConfig& mRun;
    experiment::DriverContext& mContext;
    std::string mFamily;
    std::string mParamPrefix;
    std::unique_ptr<plugin::OcclusionTechnique> mTechnique;
    std::string mTechniqueName;
    plugin::OcclusionDefinition mDefinition;
    reference::ReferenceSettings mSettings;
    bool mMatches = true;
    pipeline::FrameGraph* mGraph = nullptr;
    experiment::ResultRow* mRow = nullptr;
    PreviousFrame mPrevious;
    bool mHavePrevious = false;
};

class OcclusionFamily final : public experiment::Family {
public:
    std::unique_ptr<experiment::FamilyRun> beginRun(experiment::RunSetup& setup) const override
    {
        return std::make_unique<OcclusionRun>(setup);
    }
};

plugin::FamilyInfo describeOcclusionFamily()
{
    plugin::FamilyInfo info{
        .name = "occlusion",
        .summary = "screen-space ambient occlusion / obscurance with bent normals and cones",
        .input = "G-buffer (linear depth, view-space normals) and camera",
        .output = "AO or obscurance in [0,1], bent normal, cone aperture",
        .groundTruth = "Embree rays from the same G-buffer points, same quantity and radius",
        .metrics =
            {
                {"error", "RMSE, relative MSE, PSNR, mean signed error over surface pixels (ao.*)"},
                {"ssim", "structural similarity against the ground truth (ao.ssim)"},
                {"flip", "FLIP perceptual difference (ao.flip)"},
                {"masks",
                 "errors inside the artifact masks: depth edges, thin occluders, screen border"},
                {"bent_cone",
                 "bent-normal angle and cone-aperture errors against the ray-traced bent cone"},
                {"screen_space_split",
                 "error against rays on the depth buffer (estimator error) and that "
                 "ground truth's error against the full scene (what screen space cannot see)"},
                {"flicker",
                 "frame-to-frame change along the camera path, beside the ground truth's"},
            },
    };
    info.domain = plugin::FamilyDomain::Screen;
    info.report = {
        .cost = "technique_ms",
        .costLabel = "time of the technique (ms, median): GPU passes, or CPU for ray tracing",
        .error = "ao.rmse",
        .errorLabel = "RMSE against ground truth (AO / obscurance, unitless)",
        .passes = {"gbuffer.gpu_ms", "technique_ms"},
        .passTimeLabel = "time (ms, median; GPU, CPU for ray tracing)",
        .extraErrors = {{"bent.angle_error_deg", "bent-normal angle error (degrees, mean)"},
                        {"ao_vs_screen_truth.rmse",
                         "RMSE against the screen-space ground truth (unitless)"},
                        {"flicker.rms",
                         "flicker: RMS frame-to-frame change of the error (unitless)"}},
        .tableColumns = {"ao.mean_signed_error", "ao.ssim", "ao.flip", "ao_depth_edges.rmse",
                         "ao_thin.rmse", "ao_border.rmse", "bent.angle_error_deg",
                         "cone.aperture_abs_error_deg", "screen_truth.rmse",
                         "ao_vs_screen_truth.rmse", "flicker.rms"},
        .baseline = "raytraced_ao",
    };
    info.runtime = std::make_shared<OcclusionFamily>();
    info.stressCases = occlusion::makeOcclusionStressCases;
    return info;
}

} // namespace
} // namespace rtlab::families

RTLAB_REGISTER_FAMILY(occlusion, rtlab::families::describeOcclusionFamily)
