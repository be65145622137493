// rtlab reference: the Embree ground truth of one quantity for a scene's frame, traced from the
// G-buffer the rasteriser produces (the same surface points every technique reads).

#include "cli/commands.h"

#include "core/error.h"
#include "gpu/context.h"
#include "reference/reference.h"
#include "render/gbuffer_pass.h"
#include "scene/scene_file.h"

#include <fmt/core.h>

#include <cstdio>
#include <filesystem>

namespace rtlab::cli {

int referenceCommand(const ReferenceOptions& options)
{
    reference::ReferenceSettings settings;
    try {
        settings.quantity = reference::parseQuantity(options.quantity);
        settings.falloff = reference::parseFalloff(options.falloff);
    } catch (const Error& e) {
        fmt::print(stderr, "rtlab reference: {}\n", e.what());
        return kExitBadInput;
    }
    if (options.radius > 0.0)
        settings.radius = options.radius;
    else if (settings.quantity == reference::Quantity::Obscurance) {
        fmt::print(stderr, "rtlab reference: obscurance needs a finite --radius (world units)\n");
        return kExitBadInput;
    }
    settings.bounces = options.bounces;
    settings.targetStdErr = options.targetStdErr;
    settings.targetRelStdErr = options.targetRelStdErr;
    settings.maxSamples = options.maxSamples;
    settings.seed = options.seed;
    settings.threadCount = options.threads;
    settings.useCache = !options.noCache;

    try {
        const scene::Scene scene = scene::loadScene(options.scene);
        for (const auto& w : scene.warnings)
            std::fprintf(stderr, "warning: %s\n", w.c_str());
        if (options.frame < 0 || options.frame >= scene.frameCount) {
            fmt::print(stderr, "rtlab reference: --frame {} is outside the scene's frames 0..{}\n", options.frame,
                       scene.frameCount - 1);
            return kExitBadInput;
        }
        const scene::RenderScene renderScene = scene.buildRenderScene(options.frame);
        const scene::Camera camera = scene.getCameraAt(options.frame);
        scene::GBuffer gbuffer;
        std::string gbufferSource;
        if (options.gbuffer == "vulkan") {
            gpu::Context context;
            gbuffer = render::renderGBuffer(context, renderScene, camera, options.width, options.height);
            gbufferSource = "rasterised on " + context.getDeviceInfo().name;
        } else {
            gbuffer = reference::castGBuffer(renderScene, camera, options.width, options.height);
            gbufferSource = "ray cast with Embree";
        }
        fmt::print("scene {} frame {}: {} triangles; G-buffer {}x{} {}\n", scene.name, options.frame,
                   renderScene.triangleCount(), options.width, options.height, gbufferSource);

        const reference::ReferenceResult result = reference::computeReference(renderScene, gbuffer, settings);
        std::filesystem::create_directories(options.outputDirectory);
        reference::writeReferenceExr(result, options.outputDirectory);
        const auto& s = result.stats;
        const std::string name = reference::getQuantityName(settings.quantity);
        fmt::print("{}: {} surface pixels, {:.1f} samples per pixel on average, {} at the {}-sample cap\n", name,
                   s.surfacePixels, s.meanSamples, s.pixelsAtCap, settings.maxSamples);
        fmt::print("  largest per-pixel standard error {:.4g} (target max({}, {} x value))\n", s.maxStdErr,
                   settings.targetStdErr, settings.targetRelStdErr);
        if (s.fromCache)
            fmt::print("  read from the cache ({}), computed earlier in {:.2f} s\n", s.cachePath, s.seconds);
        else
            fmt::print("  {:.2f} s, {:.3g} M rays, {:.2f} Mrays/s\n", s.seconds, double(s.rayCount) * 1e-6,
                       s.seconds > 0 ? double(s.rayCount) * 1e-6 / s.seconds : 0.0);
        fmt::print("wrote {0}/{1}.exr and {0}/{1}_stderr.exr (the noise floor)\n", options.outputDirectory, name);

        if (options.throughputSamples > 0) {
            const reference::RayThroughput t =
                reference::measureRayThroughput(renderScene, gbuffer, settings, options.throughputSamples);
            fmt::print("throughput ({} threads, {} samples per pixel, same run, medians of {} alternating rounds):\n",
                       t.threads, options.throughputSamples, t.repeats);
            fmt::print("  reference estimator  {:8.2f} Mrays/s  ({:.3g} M samples/s, {:.2f} rays "
                       "per sample)\n",
                       t.referenceMraysPerSecond,
                       t.referenceSeconds > 0
                           ? double(t.referenceSamples) * 1e-6 / t.referenceSeconds
                           : 0.0,
                       t.referenceSamples > 0 ? double(t.referenceRays) / double(t.referenceSamples)
                                              : 0.0);
            fmt::print("  raw rtcIntersect1    {:8.2f} Mrays/s  (reference / raw = {:.2f})\n",
                       t.rawIntersectMraysPerSecond, t.referenceMraysPerSecond / t.rawIntersectMraysPerSecond);
            fmt::print("  raw rtcOccluded1     {:8.2f} Mrays/s\n", t.rawOccludedMraysPerSecond);
            fmt::print("  raw replay           {:8.2f} Mrays/s  (reference / replay = {:.2f}; the "
                       "estimator's own "
                       "{:.3g} M rays through the bare calls it made)\n",
                       t.replayMraysPerSecond, t.referenceMraysPerSecond / t.replayMraysPerSecond,
                       double(t.replayRays) * 1e-6);
        }
        return kExitOk;
    } catch (const InputError& e) {
        fmt::print(stderr, "{}\n", e.what());
        return kExitBadInput;
    } catch (const EnvironmentError& e) {
        fmt::print(stderr, "rtlab reference: {}\n", e.what());
        return kExitEnvironment;
    } catch (const Error& e) {
        fmt::print(stderr, "rtlab reference: {}\n", e.what());
        return kExitFailed;
    }
}

} // namespace rtlab::cli
