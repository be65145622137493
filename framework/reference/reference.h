#pragma once
// Embree ground truth, traced from the very same G-buffer surface points a technique reads, so
// that a technique's error is its own and not a difference of geometry.
//
// Conventions (every quantity; x = GBuffer::position, n = GBuffer::normal of a pixel):
//  * Ray origins. Every ray leaves o = x + eps * n, eps = rayEpsilonScale * D (default 1e-5 D),
//    where D is the length of the diagonal of the triangles' bounding box (the scene scale). Ray
//    distances (radius tests, obscurance) are measured from o. Path vertices further down a path
//    are offset the same way along their geometric normal, on the side the path arrives from. A
//    parallel occluder at distance h is therefore seen at h - eps: the bias this introduces is
//    reported as ReferenceStats::rayEpsilon so that tests can bound it exactly.
//  * Hemisphere. H is the hemisphere around the G-buffer shading normal n as stored; cos(theta)
//    = dot(w, n). Triangles are two-sided for visibility.
//  * Pixels without a surface (materialId == kNoMaterial) get fixed values and standard error 0:
//    occlusion 1 (ao, ao_uniform, obscurance), bent normal (0, 0, 0), apertures 0, direct and
//    indirect radiance and irradiance 0, full radiance = Sky::radiance of the camera ray through
//    the pixel (from GBuffer::view/projection). Their sample count is 0.
//
// Quantities (V_r(w) = 1 when the ray from o along w hits nothing closer than r, else 0):
//  * ao          A = (1/pi) Int_H V_r(w) cos(theta) dw           cosine-weighted visibility
//  * ao_uniform  A_u = (1/2pi) Int_H V_r(w) dw                     uniform visibility
//  * obscurance  W = (1/pi) Int_H rho(d(w)/r) cos(theta) dw        [Zhukov et al. 1998]
//                d(w) = distance to the first hit along w, rho(x) = 1 for x >= 1 and for no hit;
//                Falloff::Linear rho(x) = x, Falloff::Smoothstep rho(x) = 3x^2 - 2x^3. r finite.
//  * bent        bent normal b = normalize(Int_H V_r(w) w cos(theta) dw) (cosine-weighted mean
//                unoccluded direction [Landis 2002]); b = n where nothing is visible.
//                aperture alpha (cosine convention): the cone around the normal whose
//                cosine-weighted solid angle equals the visible fraction. A cone of half-angle a
//                around n covers (1/pi) Int_0^2pi Int_0^a cos t sin t dt dphi = sin^2(a) of the
//                cosine-weighted hemisphere, so sin^2(alpha) = A, alpha = asin(sqrt(A)).
//                apertureUniform (solid-angle convention of screen-space bent cones
//                [Klehm et al. 2011]): the cone's solid angle 2pi(1 - cos a) equals the visible
//                solid angle 2pi A_u, so 1 - cos(alpha_u) = A_u. A_u is estimated with its own
//                uniformly distributed rays (two rays per sample).
//                occlusion holds A (same radius).
//  * direct      outgoing diffuse radiance at x of light that reached x straight from an emitter
//                (sky, point lights with 1/d^2 falloff, emissive triangles), with shadows:
//                L = albedo/pi * E_0. irradiance holds E_0.
//  * indirect    the same for light that was reflected by k = 1..bounces other surfaces first:
//                L = albedo/pi * sum_k E_k. irradiance holds sum_k E_k.
//  * full        emission + direct + indirect: L = Le + albedo/pi * sum_{k=0..bounces} E_k.
//    Bounce convention: bounces = B counts reflections before the light reaches x (x's own
//    reflection toward the camera is not counted). In a closed furnace of albedo a and emission Le
//    full = Le * sum_{k=0..B+1} a^k; bounces = -1 is unlimited (Russian roulette after 3 bounces,
//    paths cut at 256 vertices). Albedo and emission at x come from the G-buffer.
//    Estimators: next-event estimation toward point lights (all of them when there are at most 8,
//    else one picked by power), emissive triangles (picked by luminance(Le) * area, a uniform
//    point on the triangle) and the SRBF sky's lobes, combined with one cosine-weighted ray per
//    vertex by multiple importance sampling (balance heuristic); constant and gradient skies are
//    reached by the cosine-weighted ray alone. A cosine-weighted direction about a vertex's
//    shading normal that points below its geometric surface ends the path (no light through it).
//
// Sampling: samples of pixel p are sample indices 0, 1, 2, ... of an Owen-scrambled, shuffled
// Sobol sequence seeded by hash(seed, p) (see sequences.h); a pixel's result depends only on its
// index, the seed and its own samples, so images are bitwise identical for any thread count.
//
// Progressive estimation: each surface pixel takes batches of batchSize samples until every
// channel c of its estimator satisfies se_c <= max(targetStdErr, targetRelStdErr * |mean_c|)
// (after at least one batch and two samples) or maxSamples is reached. se is the standard error
// of the mean, sqrt(sample variance / n), i.e. computed as if the samples were independent; for
// scrambled Sobol points that is a conservative estimate of the actual error, except for events
// rarer than about 1/n (a pixel that saw no occluder in its first batch reports 0). The channels
// are the occlusion estimate (ao, ao_uniform, obscurance), the bent vector's three components plus
// A and A_u (bent), and the reflected radiance of a white surface E/pi per colour (direct,
// indirect, full), which bounds the radiance's own standard error from above.
//
// Cache: results are stored under cacheDirectory (default $RTLAB_CACHE_DIR/reference, else
// ~/.cache/rtlab/reference) in a folder named by computeReferenceCacheKey; a second call with
// the same scene, G-buffer and settings reads it back (ReferenceStats::fromCache).

#include "core/image.h"
#include "scene/camera.h"
#include "scene/gbuffer.h"
#include "scene/render_scene.h"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace rtlab::reference {

enum class Quantity { Ao, AoUniform, Obscurance, Bent, Direct, Indirect, Full };
enum class Falloff { Linear, Smoothstep };

//! "ao", "ao_uniform", "obscurance", "bent", "direct", "indirect", "full".
const char* getQuantityName(Quantity quantity);
//! Inverse of getQuantityName; throws rtlab::Error naming the valid names.
Quantity parseQuantity(std::string_view name);
const std::vector<Quantity>& getAllQuantities();
//! "linear", "smoothstep".
const char* getFalloffName(Falloff falloff);
Falloff parseFalloff(std::string_view name);
//! rho(x) of the obscurance: 1 for x >= 1, the falloff below, 0 at x = 0.
double evaluateFalloff(Falloff falloff, double x);

struct ReferenceSettings {
    Quantity quantity = Quantity::Ao;
    //! World units; ao, ao_uniform, bent may use infinity, obscurance needs a finite radius.
    double radius = std::numeric_limits<double>::infinity();
    Falloff falloff = Falloff::Linear; //!< obscurance
    int bounces = 2;                   //!< indirect, full; -1 = unlimited
    double targetStdErr = 0.005;       //!< absolute part of the stopping rule
    double targetRelStdErr = 0.01;     //!< relative part of the stopping rule
    int batchSize = 64;                //!< samples per pixel per batch (powers of 2 suit Sobol)
    int maxSamples = 4096;             //!< per pixel
    std::uint64_t seed = 0;
    int threadCount = 0;           //!< 0 = as many as the TBB scheduler allows
    double rayEpsilonScale = 1e-5; //!< ray offset relative to the scene diagonal
    bool useCache = true;
    std::string cacheDirectory; //!< "" = $RTLAB_CACHE_DIR/reference or ~/.cache/...
};

struct ReferenceStats {
    bool fromCache = false;
    std::string cacheKey;       //!< 32 hex digits
    std::string cachePath;      //!< folder of the cache entry, "" when off or unwritable
    double seconds = 0.0;       //!< time of the computation (also when read from the cache)
    std::uint64_t rayCount = 0; //!< rays traced by the computation
    double meanSamples = 0.0;   //!< per surface pixel
    int surfacePixels = 0;
    int pixelsAtCap = 0;     //!< surface pixels that reached maxSamples above the target
    double maxStdErr = 0.0;  //!< largest stopping-rule standard error over pixels, channels
    double rayEpsilon = 0.0; //!< eps in world units
    double sceneScale = 0.0; //!< D, world units
};

//! Images of the quantity computed; the others are empty. Standard errors are per pixel.
struct ReferenceResult {
    ReferenceSettings settings;
    int width = 0;
    int height = 0;
    Image<float> occlusion; //!< ao, ao_uniform, obscurance; bent: A
    Image<float> occlusionStdErr;
    Image<glm::vec3> bentNormal;   //!< bent: unit world-space vector
    Image<float> bentNormalStdErr; //!< bent: radians (delta method on the mean vector)
    Image<float> aperture;         //!< bent: radians, sin^2(alpha) = A
    Image<float> apertureStdErr;
    Image<float> apertureUniform; //!< bent: radians, 1 - cos(alpha) = A_u
    Image<float> apertureUniformStdErr;
    Image<glm::vec3> radiance; //!< direct, indirect, full
    Image<glm::vec3> radianceStdErr;
    Image<glm::vec3> irradiance; //!< direct, indirect, full: incident irradiance at x
    Image<glm::vec3> irradianceStdErr;
    Image<std::uint32_t> sampleCount;
    ReferenceStats stats;
};

//! Settings of a fixed-cost estimate by the ground truth's estimator (an equal-time baseline, a
//! bake; not the ground truth): `samples` paths per pixel, no stopping rule, no cache, `seed`
//! (choose one other than the ground truth's 0).
ReferenceSettings makeFixedSampleSettings(Quantity quantity, int bounces, int samples,
                                          std::uint64_t seed);

//! The ground truth of settings.quantity at every pixel of `gbuffer`. Throws rtlab::Error for an
//! empty or malformed scene, a G-buffer whose images do not match its size, or bad settings.
ReferenceResult computeReference(const scene::RenderScene& scene, const scene::GBuffer& gbuffer,
                                 const ReferenceSettings& settings);

//! Writes <directory>/<quantity>.exr (values) and <quantity>_stderr.exr (standard errors and
//! the channel "samples"), float32, with the settings and statistics as header attributes.
void writeReferenceExr(const ReferenceResult& result, const std::string& directory);
//! Reads what writeReferenceExr wrote; throws rtlab::Error when a file or channel is missing.
ReferenceResult readReferenceExr(const std::string& directory, Quantity quantity);

//! Hash of the scene content, the G-buffer (camera, size, jitter, matrices, pixels) and every
//! setting that changes the result (not threadCount, useCache, cacheDirectory).
std::string computeReferenceCacheKey(const scene::RenderScene& scene, const scene::GBuffer& gbuffer,
                                     const ReferenceSettings& settings);
//! The cache root the settings select.
std::string getReferenceCacheDirectory(const ReferenceSettings& settings);

//! A G-buffer made by casting one primary ray per pixel (centre + jitter) with Embree: the same
//! layout a rasteriser fills (depth, position, shading normal facing the camera, albedo,
//! emission, material id, view and projection).
scene::GBuffer castGBuffer(const scene::RenderScene& scene, const scene::Camera& camera, int width,
                           int height, glm::vec2 jitter = glm::vec2(0.0f));

struct RayThroughput {
    double referenceMraysPerSecond = 0.0;    //!< computeReference's estimator, everything included
    double rawIntersectMraysPerSecond = 0.0; //!< rtcIntersect1 alone on the same rays
    double rawOccludedMraysPerSecond = 0.0;  //!< rtcOccluded1 alone on the same rays
    //! The estimator's own rays (logged in an untimed round: its paths' bounces, shadow rays,
    //! streams), each through the bare call it was traced with (rtcIntersect1 or rtcOccluded1).
    double replayMraysPerSecond = 0.0;
    std::uint64_t referenceRays = 0;
    //! The estimator's samples per round (surface pixels x samples per pixel): rays per sample
    //! differ between quantities and fall where rays shared by a pixel's samples are traced once.
    std::uint64_t referenceSamples = 0;
    std::uint64_t rawRays = 0;
    std::uint64_t replayRays = 0;
    double referenceSeconds = 0.0;
    double rawIntersectSeconds = 0.0;
    double rawOccludedSeconds = 0.0;
    double replaySeconds = 0.0;
    int threads = 0;
    int repeats = 0; //!< timed rounds; each figure is the median over them
};

//! Traces samplesPerPixel samples of settings.quantity per surface pixel (no cache, no early
//! stop) and, in the same run on the same scene and thread count, the same number of cosine-
//! distributed rays from the same origins through bare rtcIntersect1 and rtcOccluded1 calls, and
//! the estimator's own rays (its bounces and shadow rays, logged in an untimed round) through the
//! bare calls it made. After one untimed round of each, `repeats` rounds alternate the four;
//! medians are reported.
RayThroughput measureRayThroughput(const scene::RenderScene& scene, const scene::GBuffer& gbuffer,
                                   const ReferenceSettings& settings, int samplesPerPixel,
                                   int repeats = 5);

} // namespace rtlab::reference
