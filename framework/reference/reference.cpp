#include "reference/reference.h"

#include "core/error.h"
#include "core/strings.h"
#include "reference/bent_estimate.h"
#include "reference/cache.h"
#include "reference/exr_io.h"
#include "reference/prepared.h"
#include "reference/primary_rays.h"

#include <glm/geometric.hpp>

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace rtlab::reference {

namespace {

struct QuantityName {
    Quantity quantity;
    const char* name;
};
constexpr QuantityName kQuantityNames[] = {
    {Quantity::Ao, "ao"},
    {Quantity::AoUniform, "ao_uniform"},
    {Quantity::Obscurance, "obscurance"},
    {Quantity::Bent, "bent"},
    {Quantity::Direct, "direct"},
    {Quantity::Indirect, "indirect"},
    {Quantity::Full, "full"},
};

void finalize(ReferenceResult& r, const ProgressiveOutput& out, const PreparedReference& prepared,
              const scene::GBuffer& g)
{
    const Quantity q = r.settings.quantity;
    const int channels = getChannelCount(q);
    const CameraRays cameraRays(g);
    const scene::Sky& sky = prepared.getContext().lights->getSky();
    double sampleSum = 0.0;
    for (std::size_t i = 0; i < out.pixels.size(); ++i) {
        const PixelEstimate& e = out.pixels[i];
        if (!prepared.getActive()[i]) {
            if (q == Quantity::Full) {
                const int x = int(i % std::size_t(g.width));
                const int y = int(i / std::size_t(g.width));
                r.radiance.pixels[i] = sky.radiance(cameraRays.getDirection(x, y));
            }
            continue;
        }
        ++r.stats.surfacePixels;
        sampleSum += e.samples;
        r.sampleCount.pixels[i] = e.samples;
        if (!e.converged)
            ++r.stats.pixelsAtCap;
        for (int c = 0; c < channels; ++c)
            r.stats.maxStdErr = std::max(r.stats.maxStdErr, e.getStdErr(c));

        switch (q) {
        case Quantity::Ao:
        case Quantity::AoUniform:
        case Quantity::Obscurance:
            r.occlusion.pixels[i] = float(e.mean[0]);
            r.occlusionStdErr.pixels[i] = float(e.getStdErr(0));
            break;
        case Quantity::Bent:
            storeBentEstimate(r, i, e, prepared.getPoint(i).normal);
            break;
        case Quantity::Direct:
        case Quantity::Indirect:
        case Quantity::Full: {
            // The estimator is E / pi: radiance = Le + albedo * E / pi, irradiance = pi * E / pi.
            const glm::dvec3 mean(e.mean[0], e.mean[1], e.mean[2]);
            const glm::dvec3 se(e.getStdErr(0), e.getStdErr(1), e.getStdErr(2));
            const glm::dvec3 albedo(g.albedo.pixels[i]);
            const glm::dvec3 emission =
                q == Quantity::Full ? glm::dvec3(g.emission.pixels[i]) : glm::dvec3(0.0);
            r.radiance.pixels[i] = glm::vec3(emission + albedo * mean);
            r.radianceStdErr.pixels[i] = glm::vec3(albedo * se);
            r.irradiance.pixels[i] = glm::vec3(kPi * mean);
            r.irradianceStdErr.pixels[i] = glm::vec3(kPi * se);
            break;
        }
        }
    }
    r.stats.meanSamples = r.stats.surfacePixels > 0 ? sampleSum / r.stats.surfacePixels : 0.0;
    r.stats.rayCount = out.rayCount;
}

} // namespace

const char* getQuantityName(Quantity quantity)
{
    for (const auto& q : kQuantityNames)
        if (q.quantity == quantity)
            return q.name;
    return "unknown";
}

Quantity parseQuantity(std::string_view name)
{
    std::vector<std::string> names;
    for (const auto& q : kQuantityNames) {
        if (name == q.name)
            return q.quantity;
        names.push_back(q.name);
    }
    throw Error("reference: unknown quantity '" + std::string(name) +
                "'. Valid: " + joinList(names, "or") + ".");
}

const std::vector<Quantity>& getAllQuantities()
{
    static const std::vector<Quantity> all = [] {
        std::vector<Quantity> v;
        for (const auto& q : kQuantityNames)
            v.push_back(q.quantity);
        return v;
    }();
    return all;
}

const char* getFalloffName(Falloff falloff)
{
    return falloff == Falloff::Linear ? "linear" : "smoothstep";
}

Falloff parseFalloff(std::string_view name)
{
    if (name == "linear")
        return Falloff::Linear;
    if (name == "smoothstep")
        return Falloff::Smoothstep;
    throw Error("reference: unknown falloff '" + std::string(name) +
                "'. Valid: linear or smoothstep.");
}

double evaluateFalloff(Falloff falloff, double x)
{
    // rho of the obscurance [Zhukov et al. 1998; Iones et al. 2003]: 0 at contact, 1 from r on.
    const double t = std::clamp(x, 0.0, 1.0);
    return falloff == Falloff::Linear ? t : t * t * (3.0 - 2.0 * t);
}

ReferenceSettings makeFixedSampleSettings(Quantity quantity, int bounces, int samples,
                                          std::uint64_t seed)
{
    ReferenceSettings s;
    s.quantity = quantity;
    s.bounces = bounces;
    s.targetStdErr = 0.0;
    s.targetRelStdErr = 0.0;
    s.batchSize = samples;
    s.maxSamples = samples;
    s.seed = seed;
    s.useCache = false;
    return s;
}

ReferenceResult computeReference(const scene::RenderScene& scene, const scene::GBuffer& gbuffer,
                                 const ReferenceSettings& settings)
{
    validateSettings(settings);
    validateGBuffer(gbuffer);
    if (scene.triangleCount() == 0)
        throw Error("reference: the scene has no triangles to trace against");

    const std::string key = computeReferenceCacheKey(scene, gbuffer, settings);
    std::string root;
    if (settings.useCache) {
        root = getReferenceCacheDirectory(settings);
        if (auto cached =
                loadCachedReference(root, key, settings.quantity, gbuffer.width, gbuffer.height)) {
            cached->settings = settings;
            cached->stats.fromCache = true;
            cached->stats.cachePath = getCacheEntryPath(root, key);
            return std::move(*cached);
        }
    }

    ReferenceResult result;
    allocateResultImages(result, settings.quantity, gbuffer.width, gbuffer.height);
    result.settings = settings;
    const auto start = std::chrono::steady_clock::now();
    tbb::task_arena arena(settings.threadCount > 0 ? settings.threadCount
                                                   : int(tbb::task_arena::automatic));
    arena.execute([&] {
        const PreparedReference prepared(scene, gbuffer, settings);
        ProgressiveRule rule;
        rule.channels = getChannelCount(settings.quantity);
        rule.targetStdErr = settings.targetStdErr;
        rule.targetRelStdErr = settings.targetRelStdErr;
        rule.batchSize = settings.batchSize;
        rule.maxSamples = settings.maxSamples;
        const ProgressiveOutput out =
            runProgressive(gbuffer.width, gbuffer.height, prepared.getActive(), rule,
                           [&](std::size_t pixel, std::uint32_t first, std::uint32_t count, SampleValue* values) {
                               return prepared.evaluateBatch(pixel, first, count, values);
                           });
        finalize(result, out, prepared, gbuffer);
        result.stats.rayEpsilon = prepared.getContext().rayEpsilon;
        result.stats.sceneScale = prepared.getEmbree().getSceneScale();
    });
    result.stats.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.stats.cacheKey = key;
    if (settings.useCache) {
        try {
            result.stats.cachePath = storeCachedReference(root, key, result);
        } catch (const Error&) {
            result.stats.cachePath.clear(); // an unwritable cache costs the next call, not this one
        }
    }
    return result;
}

} // namespace rtlab::reference
