#include "experiment/lit_frame.h"

#include "experiment/image_files.h"
#include "experiment/runner.h"
#include "metrics/image_metrics.h"
#include "pipeline/compose.h"
#include "pipeline/frame_graph.h"
#include "pipeline/frame_start.h"
#include "reference/reference.h"
#include "render/lighting_pass.h"

#include <algorithm>
#include <filesystem>

namespace rtlab::experiment {

namespace {

reference::ReferenceSettings makeRadianceSettings(const RunConfig& run,
                                                  reference::Quantity quantity)
{
    reference::ReferenceSettings s;
    s.quantity = quantity;
    s.bounces = 2; // the Tomorrow Children's light: direct, first and second bounce
    applySamplingOptions(run.reference, s);
    return s;
}

void addRadianceErrors(ResultRow& row, const std::string& prefix, const Image<glm::vec3>& test,
                       const Image<glm::vec3>& truth, const Image<std::uint8_t>* mask)
{
    metrics::ImageErrorOptions options;
    options.range = metrics::DynamicRange::Hdr;
    options.withSsim = false;
    options.withFlip = true;
    const auto e = mask ? metrics::computeImageErrors(test, truth, options, *mask)
                        : metrics::computeImageErrors(test, truth, options);
    row.set(prefix + ".rmse", e.rmse)
        .set(prefix + ".rel_mse", e.relMse)
        .set(prefix + ".flip", e.flip)
        .set(prefix + ".mean_signed_error", e.meanSignedError)
        .set(prefix + ".non_finite_pixels", std::int64_t(e.nonFinitePixels));
}

} // namespace

LitFrame::LitFrame(const RunConfig& run, DriverContext& context, pipeline::FrameStart& start,
                   pipeline::FrameGraph& graph, std::vector<std::string>& outputs)
    : mRun(run), mContext(context)
{
    mCompose = std::make_unique<pipeline::Compose>(
        start, pipeline::ComposeOptions{run.tonemapper, run.exposureEv, run.shadowMapSize,
                                        run.sky != "lobes"});
    mCompose->addPasses(graph);
    const int w = run.width, h = run.height;
    const auto geometry = start.geometry();
    const auto gbuffer = start.gbufferCpu();
    const auto view = start.viewInputs();
    const auto lit = mCompose->litFrame();
    const pipeline::Resource<reference::ReferenceResult> full{
        "truth_full", pipeline::ResourceType::cpuImage("radiance full", w, h)};
    const pipeline::Resource<reference::ReferenceResult> direct{
        "truth_direct", pipeline::ResourceType::cpuImage("radiance direct", w, h)};
    const std::string fromCache =
        "read from the reference cache (same scene, G-buffer and settings)";
    for (const auto& [name, quantity, resource] :
         {std::tuple{"reference_full", reference::Quantity::Full, full},
          std::tuple{"reference_direct", reference::Quantity::Direct, direct}}) {
        const std::string pass = name;
        const reference::Quantity q = quantity;
        const auto out = resource;
        graph.addPass(
            {.name = pass, .reads = {geometry, gbuffer}, .writes = {out}, .measurement = true},
            [this, pass, q, out, geometry, gbuffer, fromCache](pipeline::PassContext& ctx) {
                reference::ReferenceResult& t = ctx.write(out);
                t = reference::computeReference(ctx.read(geometry), ctx.read(gbuffer),
                                                makeRadianceSettings(mRun, q));
                mRow->set(pass + ".seconds", t.stats.seconds)
                    .set(pass + ".samples_mean", t.stats.meanSamples)
                    .set(pass + ".from_cache", t.stats.fromCache);
                return t.stats.fromCache ? pipeline::PassOutcome::skipped(fromCache)
                                         : pipeline::PassOutcome{};
            });
    }
    graph.addPass({.name = "metric.frame",
                   .reads = {lit, full, direct, view},
                   .writes = {"metric.frame"},
                   .measurement = true},
                  [this, lit, full, direct, view](pipeline::PassContext& ctx) {
                      const pipeline::LitFrame& f = ctx.read(lit);
                      addRadianceErrors(*mRow, "frame", f.hdr, ctx.read(full).radiance, nullptr);
                      addRadianceErrors(*mRow, "direct", f.direct, ctx.read(direct).radiance,
                                        &ctx.read(view).surface);
                      return pipeline::PassOutcome{};
                  });
    graph.addPass(
        {.name = "frame_images",
         .reads = {lit, full},
         .writes = {"frame_images"},
         .measurement = true},
        [this, lit, full](pipeline::PassContext& ctx) {
            const std::string dir =
                mContext.runDirectory() + "/frame" + std::to_string(ctx.frame());
            std::filesystem::create_directories(dir);
            const pipeline::LitFrame& f = ctx.read(lit);
            const Image<glm::vec3>& truth = ctx.read(full).radiance;
            const render::TonemapSettings tonemap{float(mRun.exposureEv),
                                                  render::parseTonemapper(mRun.tonemapper)};
            Image<glm::vec3> truthLdr(truth.width, truth.height), error(truth.width, truth.height);
            for (std::size_t i = 0; i < truth.pixels.size(); ++i) {
                truthLdr.pixels[i] = render::computeTonemappedColor(truth.pixels[i], tonemap);
                error.pixels[i] = f.hdr.pixels[i] - truth.pixels[i];
            }
            writePng(f.ldr, dir + "/lit.png");
            writeExr(f.hdr, dir + "/lit.exr");
            writePng(truthLdr, dir + "/truth.png");
            writeExr(truth, dir + "/truth.exr");
            writeExr(error, dir + "/lit_error.exr");
            mRow->set("image.lit", dir + "/lit.png")
                .set("image.lit_hdr", dir + "/lit.exr")
                .set("image.truth", dir + "/truth.png")
                .set("image.truth_hdr", dir + "/truth.exr")
                .set("image.lit_error", dir + "/lit_error.exr");
            return pipeline::PassOutcome{};
        });
    outputs.push_back("metric.frame");
    outputs.push_back("frame_images");
}

LitFrame::~LitFrame() = default;

void LitFrame::describe(ResultRow& row) const
{
    row.set("frame.lighting", true)
        .set("frame.tonemapper", mRun.tonemapper)
        .set("frame.exposure_ev", mRun.exposureEv)
        .set("frame.shadow_map_size", std::int64_t(mRun.shadowMapSize))
        .set("frame.indirect", mCompose->getStats().indirect);
}

void LitFrame::endFrame(ResultRow& row)
{
    const pipeline::ComposeStats& s = mCompose->getStats();
    row.set("frame.lights", std::int64_t(s.lights))
        .set("frame.shadow_maps_rendered", std::int64_t(s.lightsRendered))
        .set("frame.shadow_faces_rendered", std::int64_t(s.shadowFacesRendered))
        .set("frame.shadow_skips", s.shadowSkips)
        .set("frame.visibility", s.visibility)
        .set("frame.sky", s.sky);
    mRow = nullptr;
}

} // namespace rtlab::experiment
