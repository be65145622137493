// The occlusion family in experiments. Per frame of the run's scene:
//   gbuffer    rasterise the frame on Vulkan (timed: GPU timestamps and CPU wall time)
//   occlusion  the technique on the G-buffer in view space (timed the same way)
//   reference  the Embree ground truth of exactly the quantity the technique declares, from the
//              same G-buffer (and of the bent normal and cone for the bent-cone errors)
//   metrics    image errors over surface pixels, and inside the artifact masks
// and one row per frame, with the images written beside it.

#include "experiment/runner.h"

#include "core/error.h"
#include "experiment/gpu_timing.h"
#include "experiment/image_files.h"
#include "gpu/context.h"
#include "metrics/image_metrics.h"
#include "metrics/timing.h"
#include "plugin/occlusion.h"
#include "reference/reference.h"
#include "render/gbuffer_pass.h"
#include "scene/scene_file.h"
#include "scene/sdf_shapes.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/mat3x3.hpp>

#include <cmath>
#include <filesystem>

namespace rtlab::experiment {

namespace {

reference::ReferenceSettings makeReferenceSettings(const plugin::OcclusionDefinition& d, const RunConfig& run)
{
    reference::ReferenceSettings s;
    switch (d.quantity) {
    case plugin::OcclusionQuantity::CosineAo: s.quantity = reference::Quantity::Ao; break;
    case plugin::OcclusionQuantity::UniformAo: s.quantity = reference::Quantity::AoUniform; break;
    case plugin::OcclusionQuantity::Obscurance: s.quantity = reference::Quantity::Obscurance; break;
    }
    s.falloff = d.falloff == plugin::OcclusionFalloff::Smoothstep ? reference::Falloff::Smoothstep
                                                                  : reference::Falloff::Linear;
    s.radius = d.radius;
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
    case plugin::OcclusionQuantity::CosineAo: return "cosine_ao";
    case plugin::OcclusionQuantity::UniformAo: return "uniform_ao";
    case plugin::OcclusionQuantity::Obscurance: return "obscurance";
    }
    return "?";
}

// Mean over pixels where `mask` is set of f(i); NaN when none.
template <class F>
double computeMaskedMean(const Image<std::uint8_t>& mask, F f)
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

void addErrorColumns(ResultRow& row, const std::string& prefix, const Image<float>& test, const Image<float>& ref,
                     const Image<std::uint8_t>& mask, bool full)
{
    metrics::ImageErrorOptions options;
    options.withSsim = full;
    options.withFlip = full;
    const auto e = metrics::computeImageErrors(test, ref, options, mask);
    row.set(prefix + ".rmse", e.rmse).set(prefix + ".mean_signed_error", e.meanSignedError);
    row.set(prefix + ".pixels", std::int64_t(e.pixels));
    if (full) {
        row.set(prefix + ".psnr", e.psnr).set(prefix + ".ssim", e.ssim).set(prefix + ".flip", e.flip);
        row.set(prefix + ".rel_mse", e.relMse).set(prefix + ".non_finite_pixels", std::int64_t(e.nonFinitePixels));
    }
}

Image<std::uint8_t> intersectMasks(const Image<std::uint8_t>& a, const Image<std::uint8_t>& b)
{
    Image<std::uint8_t> out(a.width, a.height, 0);
    for (std::size_t i = 0; i < out.pixels.size(); ++i)
        out.pixels[i] = (a.pixels[i] && b.pixels[i]) ? 1 : 0;
    return out;
}

} // namespace

std::vector<ResultRow> runOcclusionFamily(const RunConfig& run, const std::string& family, DriverContext& context,
                                          const ResultRow& common)
{
    if (scene::findAnalyticShape(run.scene))
        throw Error("scene '" + run.scene + "' is an analytic shape for isosurface studies; the occlusion family "
                    "needs a scene with geometry and a camera (e.g. ao_testbed, tomorrow_town, or a .yaml file)");
    const scene::Scene scene = scene::loadScene(run.scene);
    if (run.frames > scene.frameCount)
        throw Error("the run asks for " + std::to_string(run.frames) + " frames but scene '" + scene.name + "' has " +
                    std::to_string(scene.frameCount));
    const TechniqueChoice& choice = run.techniques.at(family);
    const plugin::TechniqueEntry* entry = context.registry().findTechnique(family, choice.technique);
    auto technique = entry->create(choice.params);
    auto* occlusion = dynamic_cast<plugin::OcclusionTechnique*>(technique.get());
    if (!occlusion)
        throw Error("technique '" + choice.technique + "' does not implement the occlusion interface");
    const plugin::OcclusionDefinition definition = occlusion->definition();

    ResultRow base = common;
    const config::ParamSet effective = technique->effectiveParams();
    for (const auto& [name, value] : effective.values())
        base.set("param." + name, config::formatValue(value));
    base.set("quantity", std::string(getQuantityColumnName(definition.quantity)))
        .set("radius", definition.radius)
        .set("scene_features", scene.computeFeatures().toString());
    base.set("gpu_time_source", std::string(toString(chooseGpuTimeSource(context.getGpu().getDeviceInfo()))));

    gpu::Context& gpu = context.getGpu();
    render::GBufferPass gbufferPass(gpu);
    std::vector<ResultRow> rows;
    std::string uploadedHash;
    for (int frame = 0; frame < run.frames; ++frame) {
        ResultRow row = base;
        row.set("frame", std::int64_t(frame));
        const scene::RenderScene renderScene = scene.buildRenderScene(frame);
        PassLog passes;
        const std::string sceneHash = renderScene.computeContentHash();
        if (sceneHash != uploadedHash) {
            gbufferPass.setScene(renderScene);
            uploadedHash = sceneHash;
            passes.add("scene_upload");
        } else {
            passes.skip("scene_upload", "geometry unchanged since frame " + std::to_string(frame - 1) +
                                            " (no edits or moving characters in between)");
        }
        const scene::Camera camera = scene.getCameraAt(frame);

        // Pass 1: the G-buffer.
        gpu.takeRunLog();
        const auto gbufferReport = metrics::measure(run.timing, [&] {
            gbufferPass.draw(camera, run.width, run.height);
            return collectGpuPassTimes(gpu);
        });
        addTimingColumns(row, "gbuffer", gbufferReport);
        passes.add("gbuffer");
        const scene::GBuffer g = gbufferPass.readBack();

        // View-space inputs.
        const glm::mat3 toView(g.view);
        Image<glm::vec3> viewNormal(g.width, g.height, glm::vec3(0.0f));
        Image<std::uint8_t> surface(g.width, g.height, 0);
        for (std::size_t i = 0; i < viewNormal.pixels.size(); ++i)
            if (g.materialId.pixels[i] != scene::kNoMaterial) {
                viewNormal.pixels[i] = glm::normalize(toView * g.normal.pixels[i]);
                surface.pixels[i] = 1;
            }
        plugin::OcclusionInput input;
        input.linearDepth = &g.depth;
        input.normal = &viewNormal;
        input.projection = g.projection;
        input.view = g.view;
        input.frameIndex = frame;
        input.gpu = &gpu;

        // Pass 2: the technique.
        plugin::OcclusionOutput out;
        gpu.takeRunLog();
        const auto report = metrics::measure(run.timing, [&] {
            occlusion->compute(input, out);
            return collectGpuPassTimes(gpu);
        });
        addTimingColumns(row, "occlusion", report);
        passes.add("occlusion");
        if (out.ambient.width != g.width || out.ambient.height != g.height)
            throw Error("technique '" + choice.technique + "' returned an ambient image of " +
                        std::to_string(out.ambient.width) + "x" + std::to_string(out.ambient.height) + " for a " +
                        std::to_string(g.width) + "x" + std::to_string(g.height) + " G-buffer");

        // Pass 3: the ground truth of the declared quantity, and of the bent normal and cone.
        const reference::ReferenceSettings settings = makeReferenceSettings(definition, run);
        const reference::ReferenceResult truth = reference::computeReference(renderScene, g, settings);
        if (truth.stats.fromCache)
            passes.skip("reference", "read from the reference cache (same scene, G-buffer and settings)");
        else
            passes.add("reference");
        const bool hasBent = out.bentNormal.size() == viewNormal.size();
        const bool hasAperture = out.coneAperture.size() == viewNormal.size();
        reference::ReferenceResult bent;
        if (hasBent || hasAperture) {
            reference::ReferenceSettings bentSettings = settings;
            bentSettings.quantity = reference::Quantity::Bent;
            if (!std::isfinite(bentSettings.radius) || bentSettings.radius <= 0.0)
                bentSettings.radius = std::numeric_limits<double>::infinity();
            bent = reference::computeReference(renderScene, g, bentSettings);
            if (bent.stats.fromCache)
                passes.skip("reference_bent", "read from the reference cache (same scene, G-buffer and settings)");
            else
                passes.add("reference_bent");
        } else {
            passes.skip("reference_bent", "the technique outputs no bent normal or cone");
        }
        row.set("reference.seconds", truth.stats.seconds)
            .set("reference.from_cache", truth.stats.fromCache)
            .set("reference.samples_mean", truth.stats.meanSamples)
            .set("reference.stderr_mean",
                 computeMaskedMean(surface, [&](std::size_t i) { return double(truth.occlusionStdErr.pixels[i]); }))
            .set("reference.stderr_max", truth.stats.maxStdErr);

        // Metrics over surface pixels, and inside the artifact masks.
        addErrorColumns(row, "ao", out.ambient, truth.occlusion, surface, true);
        const auto edges = intersectMasks(metrics::makeDepthEdgeMask(g.depth, 2, 0.1), surface);
        const auto border = intersectMasks(metrics::makeBorderMask(g.width, g.height, 8), surface);
        const auto thin = intersectMasks(metrics::makeThinStructureMask(surface, 2), surface);
        addErrorColumns(row, "ao_depth_edges", out.ambient, truth.occlusion, edges, false);
        addErrorColumns(row, "ao_border", out.ambient, truth.occlusion, border, false);
        addErrorColumns(row, "ao_thin", out.ambient, truth.occlusion, thin, false);

        const glm::mat3 toWorld = glm::transpose(toView);
        row.set("bent.angle_error_deg",
                hasBent ? computeMaskedMean(surface,
                                            [&](std::size_t i) {
                                                const glm::vec3 t = out.bentNormal.pixels[i];
                                                const glm::vec3 r = bent.bentNormal.pixels[i];
                                                if (glm::dot(t, t) == 0.0f || glm::dot(r, r) == 0.0f)
                                                    return std::nan("");
                                                const float c = glm::dot(glm::normalize(toWorld * t),
                                                                         glm::normalize(r));
                                                return double(glm::degrees(std::acos(std::clamp(c, -1.0f, 1.0f))));
                                            })
                        : std::nan(""));
        row.set("cone.aperture_error_deg",
                hasAperture ? computeMaskedMean(surface,
                                                [&](std::size_t i) {
                                                    return double(glm::degrees(
                                                        out.coneAperture.pixels[i] - bent.aperture.pixels[i]));
                                                })
                            : std::nan(""));
        row.set("cone.aperture_abs_error_deg",
                hasAperture ? computeMaskedMean(surface,
                                                [&](std::size_t i) {
                                                    return double(glm::degrees(std::abs(
                                                        out.coneAperture.pixels[i] - bent.aperture.pixels[i])));
                                                })
                            : std::nan(""));
        row.set("cone_visibility.count", std::int64_t(out.coneVisibility.size()));
        passes.write(row);

        // Images: numbers in EXR (the report makes the PNGs).
        const std::string dir = context.runDirectory() + "/frame" + std::to_string(frame);
        std::filesystem::create_directories(dir);
        Image<float> error(g.width, g.height, 0.0f);
        for (std::size_t i = 0; i < error.pixels.size(); ++i)
            error.pixels[i] = surface.pixels[i] ? out.ambient.pixels[i] - truth.occlusion.pixels[i] : 0.0f;
        writeExr(out.ambient, dir + "/technique.exr");
        writeExr(truth.occlusion, dir + "/reference.exr");
        writeExr(truth.occlusionStdErr, dir + "/reference_stderr.exr");
        writeExr(error, dir + "/error.exr");
        row.set("image.technique", dir + "/technique.exr")
            .set("image.reference", dir + "/reference.exr")
            .set("image.error", dir + "/error.exr");
        rows.push_back(std::move(row));
    }
    return rows;
}

} // namespace rtlab::experiment
