// Light transport estimators: direct, indirect and full radiance of diffuse surfaces. A path
// tracer with next-event estimation (point lights, emissive triangles, SRBF sky lobes) combined
// with cosine-weighted BSDF sampling by multiple importance sampling, balance heuristic
// [Veach & Guibas 1995]. Estimates E/pi at the G-buffer point (white-albedo reflected radiance);
// the caller turns it into radiance with the G-buffer albedo.
#include "reference/integrators.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::reference {

namespace {

// Each path vertex owns a fixed block of 2D dimension pairs, so that a choice at one vertex
// never shifts the samples of another.
constexpr std::uint32_t kPairBsdf = 0;
constexpr std::uint32_t kPairPointLight = 1;
constexpr std::uint32_t kPairEmitterPick = 2;
constexpr std::uint32_t kPairEmitterPoint = 3;
constexpr std::uint32_t kPairSky = 4;
constexpr std::uint32_t kPairRoulette = 5;
constexpr std::uint32_t kPairsPerVertex = 6;

constexpr int kMaxPathVertices = 256; // unlimited bounces: hard stop (0.95^256 < 2e-6)
constexpr int kRouletteStartBounce = 3;
constexpr double kMaxRouletteSurvival = 0.95;

double balanceHeuristic(double pdfA, double pdfB)
{
    return pdfA + pdfB > 0.0 ? pdfA / (pdfA + pdfB) : 0.0;
}

//! A surface point a path leaves from.
struct Vertex {
    glm::dvec3 position{0.0};
    glm::dvec3 shadingNormal{0.0};   //!< on the side the path arrived from
    glm::dvec3 geometricNormal{0.0}; //!< same side; rays below it would enter the surface
    glm::vec3 origin{0.0f};          //!< position offset along the geometric normal
};

//! The G-buffer point as the path's first vertex.
Vertex makeFirstVertex(const SurfacePoint& point, double rayEpsilon)
{
    Vertex v;
    v.position = point.position;
    v.shadingNormal = point.normal;
    v.geometricNormal = point.normal; // the G-buffer has no other
    v.origin = glm::vec3(v.position + rayEpsilon * v.geometricNormal);
    return v;
}

//! Whether light arriving directly at the G-buffer point (bounce 0) is kept.
bool recordsFirstVertex(Quantity q)
{
    return q != Quantity::Indirect;
}

class LightPathTracer {
public:
    LightPathTracer(const TraceContext& context, const PixelSequence& sequence, std::uint32_t index,
                    const SobolStream* streams, std::uint32_t streamCount,
                    const glm::dvec3* firstVertexPointLights = nullptr)
        : mContext(context), mLights(*context.lights), mEmbree(*context.embree),
          mSequence(sequence), mStreams(streams), mStreamCount(streamCount), mIndex(index),
          mFirstVertexPointLights(firstVertexPointLights)
    {
    }

    glm::dvec3 trace(const SurfacePoint& point);
    std::uint32_t getRayCount() const { return mRays; }
    //! Every point light's term at `v` when all of them are evaluated (no pick): a sum that uses
    //! no sample dimension, the same for every sample that starts at `v`.
    glm::dvec3 sumAllPointLights(const Vertex& v)
    {
        glm::dvec3 sum(0.0);
        for (std::size_t i = 0; i < mLights.getPointLights().size(); ++i)
            sum += estimatePointLight(v, i, 1.0);
        return sum;
    }

private:
    glm::dvec2 get2D(int vertex, std::uint32_t pair) const
    {
        const std::uint32_t dimensionPair = std::uint32_t(vertex) * kPairsPerVertex + pair;
        return dimensionPair < mStreamCount ? PixelSequence::get2D(mStreams[dimensionPair], mIndex)
                                            : mSequence.get2D(mIndex, dimensionPair);
    }
    bool isVisible(const glm::vec3& origin, const glm::dvec3& direction, double distance)
    {
        ++mRays;
        const float tFar = std::isinf(distance)
                               ? kInfiniteDistance
                               : float(std::max(0.0, distance - mContext.rayEpsilon));
        return !mEmbree.occluded(origin, glm::vec3(direction), tFar);
    }
    //! Next-event estimation at `v`: (1/pi) Int L_emitted V cos dw, MIS-weighted against the
    //! cosine-weighted BSDF ray for the emitters that ray can find too.
    glm::dvec3 estimateDirect(int vertex, const Vertex& v);
    glm::dvec3 estimatePointLight(const Vertex& v, std::size_t light, double pmf);

    const TraceContext& mContext;
    const SceneLights& mLights;
    const EmbreeScene& mEmbree;
    const PixelSequence& mSequence;
    const SobolStream* mStreams; //!< mSequence.getStream(p) for p < mStreamCount
    std::uint32_t mStreamCount;
    std::uint32_t mIndex;
    //! sumAllPointLights at the first vertex, computed once for a batch of the pixel's samples
    //! (same bits as computing it here); null: computed here.
    const glm::dvec3* mFirstVertexPointLights;
    std::uint32_t mRays = 0;
};

glm::dvec3 LightPathTracer::estimatePointLight(const Vertex& v, std::size_t light, double pmf)
{
    const scene::PointLight& l = mLights.getPointLights()[light];
    const glm::dvec3 toLight = glm::dvec3(l.position) - glm::dvec3(v.origin);
    const double distance = glm::length(toLight);
    if (!(distance > 0.0))
        return glm::dvec3(0.0);
    const glm::dvec3 w = toLight / distance;
    const double cosSurface = glm::dot(w, v.shadingNormal);
    if (cosSurface <= 0.0 || glm::dot(w, v.geometricNormal) <= 0.0)
        return glm::dvec3(0.0);
    if (!isVisible(v.origin, w, distance))
        return glm::dvec3(0.0);
    // Irradiance I cos / d^2 of an isotropic point source, / pi, / probability of the pick.
    return glm::dvec3(l.intensity) * (cosSurface / (distance * distance * kPi * pmf));
}

glm::dvec3 LightPathTracer::estimateDirect(int vertex, const Vertex& v)
{
    glm::dvec3 sum(0.0);

    // Point lights: all of them when few, else one picked by power.
    const std::size_t pointLights = mLights.getPointLights().size();
    if (pointLights > 0 && !mLights.pointLightPick.empty()) {
        if (mLights.evaluateAllPointLights) {
            // The sum starts from 0 either way, so the shared value is the same bits.
            sum = vertex == 0 && mFirstVertexPointLights != nullptr ? *mFirstVertexPointLights
                                                                    : sumAllPointLights(v);
        } else {
            const std::size_t i = mLights.pointLightPick.sample(get2D(vertex, kPairPointLight).x);
            sum += estimatePointLight(v, i, mLights.pointLightPick.pmf(i));
        }
    }

    // Emissive triangles: pick by power, a uniform point on its area.
    if (!mLights.emitterPick.empty()) {
        const std::size_t slot = mLights.emitterPick.sample(get2D(vertex, kPairEmitterPick).x);
        const std::uint32_t triangle = mLights.emitterTriangles[slot];
        const glm::dvec2 b = sampleTriangleBarycentrics(get2D(vertex, kPairEmitterPoint));
        const glm::dvec3 y = mLights.getPoint(triangle, b.x, b.y);
        const glm::dvec3 toLight = y - glm::dvec3(v.origin);
        const double distance = glm::length(toLight);
        if (distance > mContext.rayEpsilon) {
            const glm::dvec3 w = toLight / distance;
            const double cosSurface = glm::dot(w, v.shadingNormal);
            const double cosLight = std::abs(glm::dot(w, mLights.getGeometricNormal(triangle)));
            if (cosSurface > 0.0 && glm::dot(w, v.geometricNormal) > 0.0 && cosLight > 0.0) {
                const double pdfLight = mLights.pdfEmitter(triangle, distance, cosLight);
                const double weight = balanceHeuristic(pdfLight, cosSurface / kPi);
                if (pdfLight > 0.0 && isVisible(v.origin, w, distance))
                    sum += mLights.getEmission(triangle) * (cosSurface / (kPi * pdfLight) * weight);
            }
        }
    }

    // SRBF sky: a direction from the lobe mixture.
    if (mLights.skyLobes.active()) {
        const glm::dvec3 w = mLights.skyLobes.sample(get2D(vertex, kPairSky));
        const double cosSurface = glm::dot(w, v.shadingNormal);
        if (cosSurface > 0.0 && glm::dot(w, v.geometricNormal) > 0.0) {
            glm::dvec3 radiance;
            const double pdfSky = mLights.skyLobes.evaluate(w, mLights.getSky(), radiance);
            const double weight = balanceHeuristic(pdfSky, cosSurface / kPi);
            if (pdfSky > 0.0 && isVisible(v.origin, w, std::numeric_limits<double>::infinity()))
                sum += radiance * (cosSurface / (kPi * pdfSky) * weight);
        }
    }
    return sum;
}

glm::dvec3 LightPathTracer::trace(const SurfacePoint& point)
{
    const Quantity q = mContext.quantity;
    const bool unlimited = mContext.bounces < 0;
    // Contributions of light that bounced k times before reaching the G-buffer point are kept
    // for k in [minBounce, maxBounce]; vertex k is where such light is gathered.
    const int minBounce = q == Quantity::Indirect ? 1 : 0;
    const int maxBounce = q == Quantity::Direct ? 0
                          : unlimited           ? kMaxPathVertices - 1
                                                : mContext.bounces;

    if (maxBounce < minBounce)
        return glm::dvec3(0.0); // indirect with 0 bounces

    Vertex v = makeFirstVertex(point, mContext.rayEpsilon);

    glm::dvec3 sum(0.0);
    glm::dvec3 throughput(1.0); // product of the albedos of vertices 1..k (and roulette)
    for (int k = 0;; ++k) {
        const bool record = k >= minBounce;
        if (record)
            sum += throughput * estimateDirect(k, v);

        // Cosine-weighted BSDF ray: (1/pi) L cos / pdf = L.
        const Frame frame = Frame::fromNormal(v.shadingNormal);
        const glm::dvec3 local = sampleCosineHemisphere(get2D(k, kPairBsdf));
        const glm::dvec3 w = frame.toWorld(local);
        const double pdfBsdf = local.z / kPi;
        if (glm::dot(w, v.geometricNormal) <= 0.0)
            break; // into the surface itself
        ++mRays;
        RayHit hit;
        if (!mEmbree.intersect(v.origin, glm::vec3(w), kInfiniteDistance, hit)) {
            if (record) {
                if (mLights.skyLobes.active()) {
                    glm::dvec3 radiance;
                    const double pdfSky = mLights.skyLobes.evaluate(w, mLights.getSky(), radiance);
                    sum += throughput * radiance * balanceHeuristic(pdfBsdf, pdfSky);
                } else {
                    sum += throughput * glm::dvec3(mLights.getSky().radiance(w));
                }
            }
            break;
        }

        glm::dvec3 ng = glm::normalize(glm::dvec3(hit.geometricNormal));
        if (glm::dot(ng, w) > 0.0)
            ng = -ng; // face the side the path arrives from
        const glm::dvec3& emission = mLights.getEmission(hit.triangle);
        if (record && (emission.x > 0.0 || emission.y > 0.0 || emission.z > 0.0)) {
            const double pdfLight =
                mLights.pdfEmitter(hit.triangle, double(hit.t), -glm::dot(ng, w));
            sum += throughput * emission * balanceHeuristic(pdfBsdf, pdfLight);
        }
        if (k >= maxBounce)
            break;

        const glm::dvec3& albedo = mLights.getAlbedo(hit.triangle);
        throughput *= albedo;
        if (throughput.x <= 0.0 && throughput.y <= 0.0 && throughput.z <= 0.0)
            break;
        if (unlimited && k + 1 >= kRouletteStartBounce) {
            // Russian roulette [Arvo & Kirk 1990]: survive with q, reweight by 1/q (unbiased).
            const double survive =
                std::min(kMaxRouletteSurvival, std::max({albedo.x, albedo.y, albedo.z}));
            if (get2D(k + 1, kPairRoulette).x >= survive)
                break;
            throughput /= survive;
        }

        v.geometricNormal = ng;
        mLights.getSurface(hit.triangle, hit.u, hit.v, ng, v.position, v.shadingNormal);
        if (glm::dot(v.shadingNormal, ng) < 0.0)
            v.shadingNormal = -v.shadingNormal;
        v.origin = glm::vec3(v.position + mContext.rayEpsilon * ng);
    }
    return sum;
}

} // namespace

std::uint32_t evaluateFirstVertexPointLights(const TraceContext& context, const SurfacePoint& point,
                                             const PixelSequence& sequence, glm::dvec3& sum,
                                             bool& shared)
{
    shared = context.lights->evaluateAllPointLights && !context.lights->getPointLights().empty() &&
             !context.lights->pointLightPick.empty() && recordsFirstVertex(context.quantity);
    if (!shared) {
        sum = glm::dvec3(0.0);
        return 0;
    }
    LightPathTracer tracer(context, sequence, 0, nullptr, 0);
    sum = tracer.sumAllPointLights(makeFirstVertex(point, context.rayEpsilon));
    return tracer.getRayCount();
}

std::uint32_t evaluateLightSample(const TraceContext& context, const SurfacePoint& point,
                                  const PixelSequence& sequence, std::uint32_t index,
                                  SampleValue& value, const SobolStream* streams,
                                  std::uint32_t streamCount,
                                  const glm::dvec3* firstVertexPointLights)
{
    LightPathTracer tracer(context, sequence, index, streams, streamCount, firstVertexPointLights);
    const glm::dvec3 e = tracer.trace(point);
    value[0] = e.x;
    value[1] = e.y;
    value[2] = e.z;
    return tracer.getRayCount();
}

} // namespace rtlab::reference
