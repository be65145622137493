// raytraced_ao: Monte Carlo ray-traced ambient occlusion at a fixed number of rays per pixel, the
// equal-time baseline of the occlusion studies: how good is brute force for the time a
// screen-space technique takes?
//
// Registry key: occlusion/raytraced_ao
//
// What it computes: the cosine-weighted AO within `radius` (OcclusionQuantity::CosineAo), with the
// bent normal and the cone aperture of the same rays, by the estimator of the ground truth
// (reference/reference.h, quantity "bent": A = cosine-weighted visible fraction, sin^2(alpha) = A)
// stopped after exactly samples_per_pixel rays per pixel: no stopping rule, no cache. Rays start
// at the G-buffer's world positions and go against the frame's full triangle scene with Embree on
// the CPU (all threads), so its time is CPU time, not GPU time (the rows say which:
// technique_time_source). On a machine whose Vulkan device is a CPU (lavapipe) the two are times
// on the same processor, which makes the equal-time comparison direct; on a GPU they are not the
// same resource, and the comparison is of the ray budget a CPU gets in that time.
// Bent normal: the mean visible direction of the rays (the ground truth's estimator), except where
// all rays are unoccluded, where it is the normal (see compute()).
// The directions are scrambled Sobol points like the ground truth's, but from another seed (and a
// new one each frame unless rotate_seed_per_frame is off), so the baseline's error is not
// correlated with the ground truth's own noise.
// Without a scene (synthetic inputs, the family suite) it traces the depth buffer as a height
// field (reference/screen_space_reference.h) with the same settings.
//
// Parameters
// | name                  | type  | default | range       | unit        |
// |-----------------------|-------|---------|-------------|-------------|
// | samples_per_pixel     | int   | 4       | [1, 65536]  | rays        |
// | radius                | float | 1.0     | [0, inf]    | world units |
// | rotate_seed_per_frame | bool  | true    |             |             |
//
// Config example (the equal-time sweep of experiments/occlusion.yaml):
//   techniques: {occlusion: {technique: raytraced_ao, params: {samples_per_pixel: 8, radius: 1.0}}}
//   sweep: {occlusion.samples_per_pixel: [1, 2, 4, 8, 16, 32]}

#include "raytraced_ao.h"

#include "reference/reference.h"
#include "reference/screen_space_reference.h"

#include <glm/mat3x3.hpp>

#include <chrono>
#include <limits>
#include <stdexcept>

namespace rtlab::occlusion {

plugin::TechniqueInfo RaytracedAo::describe()
{
    plugin::TechniqueInfo info;
    info.summary =
        "ray-traced AO with Embree at a fixed ray count per pixel: the equal-time baseline";
    info.reference =
        "Monte Carlo estimate of the cosine-weighted AO integral (the ground truth's estimator, "
        "reference/reference.h, stopped at N rays)";
    return info;
}

config::ParamSchema RaytracedAo::declareParams()
{
    config::ParamSchema schema;
    schema.addInt("samples_per_pixel", 4, 1, 65536, "rays",
                  "cosine-distributed rays per pixel and frame");
    schema.addFloat("radius", 1.0, 0.0, std::numeric_limits<double>::infinity(), "world units",
                    "occluders farther than this from the receiver do not count");
    schema.addBool("rotate_seed_per_frame", true,
                   "new ray directions every frame (the frame index joins the seed)");
    return schema;
}

RaytracedAo::RaytracedAo(const config::ParamSet& params)
{
    mSettings.samplesPerPixel = int(params.getInt("samples_per_pixel"));
    mSettings.radius = params.getFloat("radius");
    mSettings.rotateSeedPerFrame = params.getBool("rotate_seed_per_frame");
    if (mSettings.samplesPerPixel < 1 || !(mSettings.radius >= 0.0))
        throw std::invalid_argument("raytraced_ao: samples_per_pixel must be >= 1 and radius >= 0");
}

config::ParamSet RaytracedAo::effectiveParams() const
{
    config::ParamSet p;
    p.set("samples_per_pixel", std::int64_t(mSettings.samplesPerPixel));
    p.set("radius", mSettings.radius);
    p.set("rotate_seed_per_frame", mSettings.rotateSeedPerFrame);
    return p;
}

plugin::OcclusionDefinition RaytracedAo::definition() const
{
    return {plugin::OcclusionQuantity::CosineAo, mSettings.radius};
}

void RaytracedAo::compute(const plugin::OcclusionInput& input, plugin::OcclusionOutput& out)
{
    if (!input.linearDepth || !input.normal)
        throw std::invalid_argument("raytraced_ao: the input needs linearDepth and normal");
    const int width = input.linearDepth->width, height = input.linearDepth->height;
    reference::ReferenceSettings settings;
    settings.quantity = reference::Quantity::Bent;
    settings.radius = mSettings.radius;
    settings.maxSamples = mSettings.samplesPerPixel;
    settings.batchSize = mSettings.samplesPerPixel; // one batch: exactly N rays, no stopping rule
    settings.targetStdErr = 0.0;
    settings.targetRelStdErr = 0.0;
    settings.useCache = false;
    settings.seed =
        mSettings.seed + (mSettings.rotateSeedPerFrame ? std::uint64_t(input.frameIndex) : 0u);

    const auto start = std::chrono::steady_clock::now();
    reference::ReferenceResult r;
    mTracedScene = input.scene && input.gbuffer;
    if (mTracedScene && mSettings.radius > 0.0) {
        r = reference::computeReference(*input.scene, *input.gbuffer, settings);
    } else {
        // Radius 0 (nothing is within it) and inputs without a scene: the height-field tracer,
        // which defines radius 0 as unoccluded.
        const reference::ScreenSpaceView view{input.linearDepth, input.normal, input.projection,
                                              input.view};
        r = reference::computeScreenSpaceReference(view, settings).reference;
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    mRaysPerSecond = seconds > 0.0 ? double(r.stats.rayCount) / seconds : 0.0;

    // World-space bent normals to view space.
    const glm::mat3 toView(input.view);
    out.ambient = Image<float>(width, height, 1.0f);
    out.bentNormal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    out.coneAperture = Image<float>(width, height, 0.0f);
    out.coneVisibility.clear();
    for (std::size_t i = 0; i < out.ambient.pixels.size(); ++i) {
        const float a = r.occlusion.pixels[i];
        out.ambient.pixels[i] = std::isfinite(a) ? std::clamp(a, 0.0f, 1.0f) : 1.0f;
        // Where every ray was unoccluded (A = 1) the bent normal is the normal itself: the value
        // of the control-variate estimator (2/3) n - mean((1 - V) w), exact there, which removes
        // the sampling noise of the mean direction on open surfaces (the same idea as GTAO's
        // "unoccluded vector minus the occluded part").
        const glm::vec3 b = a >= 1.0f ? (*input.normal).pixels[i] : toView * r.bentNormal.pixels[i];
        const float length = glm::length(b);
        out.bentNormal.pixels[i] =
            length > 0.0f && std::isfinite(length) ? b / length : glm::vec3(0.0f);
        const float alpha = r.aperture.pixels[i];
        out.coneAperture.pixels[i] =
            std::isfinite(alpha) ? std::clamp(alpha, 0.0f, 1.57079633f) : 0.0f;
    }
}

std::vector<std::pair<std::string, double>> RaytracedAo::counters() const
{
    return {{"rays_per_second", mRaysPerSecond}, {"traced_scene", mTracedScene ? 1.0 : 0.0}};
}

} // namespace rtlab::occlusion

RTLAB_REGISTER_TECHNIQUE(occlusion, raytraced_ao, rtlab::occlusion::RaytracedAo)
