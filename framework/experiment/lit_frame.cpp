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
#include <cmath>
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
    // The truth's direct light from the sky and the emitters alone (the scene without its
    // point lights): with `direct` and `full` it splits the truth into the frame's terms.
    const pipeline::Resource<reference::ReferenceResult> skyTruth{
        "truth_sky", pipeline::ResourceType::cpuImage("radiance direct, no point lights", w, h)};
    graph.addPass(
        {.name = "reference_sky", .reads = {geometry, gbuffer}, .writes = {skyTruth}, .measurement = true},
        [this, skyTruth, geometry, gbuffer, fromCache](pipeline::PassContext& ctx) {
            scene::RenderScene g = ctx.read(geometry);
            g.pointLights.clear();
            reference::ReferenceResult& t = ctx.write(skyTruth);
            t = reference::computeReference(g, ctx.read(gbuffer),
                                            makeRadianceSettings(mRun, reference::Quantity::Direct));
            mRow->set("reference_sky.seconds", t.stats.seconds)
                .set("reference_sky.from_cache", t.stats.fromCache);
            return t.stats.fromCache ? pipeline::PassOutcome::skipped(fromCache)
                                     : pipeline::PassOutcome{};
        });
    // What the frame's light is made of, in the technique and in the truth: the mean over the
    // surface pixels of each term's radiance (luminance, Rec. 709), so an error is traced to its
    // term. Emission is the G-buffer's in both; direct splits into the point lights' part and
    // the sky's (with the emitters' light where the technique's sky comes through its cones,
    // and always in the truth); indirect is the rest of the frame.
    graph.addPass({.name = "metric.frame_terms",
                   .reads = {lit, full, direct, skyTruth, gbuffer, view},
                   .writes = {"metric.frame_terms"},
                   .measurement = true},
                  [this, lit, full, direct, skyTruth, gbuffer, view](pipeline::PassContext& ctx) {
                      const pipeline::LitFrame& f = ctx.read(lit);
                      const scene::GBuffer& g = ctx.read(gbuffer);
                      const Image<std::uint8_t>& surface = ctx.read(view).surface;
                      const auto lum = [](const glm::vec3& c) {
                          return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
                      };
                      const Image<glm::vec3>& tFull = ctx.read(full).radiance;
                      const Image<glm::vec3>& tDirect = ctx.read(direct).radiance;
                      const Image<glm::vec3>& tSky = ctx.read(skyTruth).radiance;
                      // technique: emission, point lights, sky, indirect; then the truth's; and
                      // the squared per-pixel differences of the last three
                      double sums[8] = {}, squares[3] = {};
                      std::size_t n = 0;
                      for (std::size_t i = 0; i < f.hdr.pixels.size(); ++i) {
                          if (surface.pixels[i] == 0)
                              continue;
                          ++n;
                          const double e = lum(g.emission.pixels[i]);
                          const double d = lum(f.direct.pixels[i]), s = f.directSky.pixels[i];
                          sums[0] += e;
                          sums[1] += d - s;
                          sums[2] += s;
                          sums[3] += lum(f.hdr.pixels[i]) - e - d;
                          const double td = lum(tDirect.pixels[i]), ts = lum(tSky.pixels[i]);
                          sums[4] += e;
                          sums[5] += td - ts;
                          sums[6] += ts;
                          sums[7] += lum(tFull.pixels[i]) - e - td;
                          const double terms[3] = {d - s - (td - ts), s - ts,
                                                   (lum(f.hdr.pixels[i]) - e - d) -
                                                       (lum(tFull.pixels[i]) - e - td)};
                          for (int k = 0; k < 3; ++k)
                              squares[k] += terms[k] * terms[k];
                      }
                      {
                          // The sky term's images, the technique's and the truth's (luminance).
                          Image<glm::vec3> mine(g.emission.width, g.emission.height),
                              truth(g.emission.width, g.emission.height);
                          for (std::size_t i = 0; i < mine.pixels.size(); ++i) {
                              mine.pixels[i] = glm::vec3(f.directSky.pixels[i]);
                              truth.pixels[i] = glm::vec3(float(lum(tSky.pixels[i])));
                          }
                          const std::string dir =
                              mContext.runDirectory() + "/frame" + std::to_string(ctx.frame());
                          std::filesystem::create_directories(dir);
                          writeExr(mine, dir + "/sky_term.exr");
                          writeExr(truth, dir + "/truth_sky_term.exr");
                      }
                      static const char* kTerms[4] = {"emission", "point_lights", "sky", "indirect"};
                      for (int k = 0; k < 4; ++k) {
                          const double scale = n > 0 ? 1.0 / double(n) : std::nan("");
                          mRow->set(std::string("frame.term.") + kTerms[k], sums[k] * scale)
                              .set(std::string("truth.term.") + kTerms[k], sums[4 + k] * scale);
                          // Each lit term's own error, per pixel (the point lights' part: their
                          // shadows against the truth's, apart from the sky's).
                          if (k > 0)
                              mRow->set(std::string("frame.term_rmse.") + kTerms[k],
                                        std::sqrt(squares[k - 1] * scale));
                      }
                      return pipeline::PassOutcome{};
                  });
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
    outputs.push_back("metric.frame_terms");
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
