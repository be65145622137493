// Occlusion estimators: cosine AO, uniform AO, obscurance, bent normal and cones.
#include "reference/integrators.h"

#include <glm/geometric.hpp>

#include <cmath>

namespace rtlab::reference {

namespace {

constexpr std::uint32_t kPairCosine = 0;
constexpr std::uint32_t kPairUniform = 1;

} // namespace

int getChannelCount(Quantity quantity)
{
    switch (quantity) {
    case Quantity::Ao:
    case Quantity::AoUniform:
    case Quantity::Obscurance:
        return 1;
    case Quantity::Bent:
        return 5;
    case Quantity::Direct:
    case Quantity::Indirect:
    case Quantity::Full:
        return 3;
    }
    return 1;
}

std::uint32_t evaluateOcclusionSample(const TraceContext& context, const SurfacePoint& point,
                                      const PixelSequence& sequence, std::uint32_t index,
                                      SampleValue& value)
{
    const Frame frame = Frame::fromNormal(point.normal);
    const glm::vec3 origin(point.position + context.rayEpsilon * point.normal);
    const float tFar = std::isinf(context.radius) ? kInfiniteDistance : float(context.radius);
    const EmbreeScene& embree = *context.embree;

    switch (context.quantity) {
    case Quantity::Ao: {
        // Cosine-weighted hemisphere: (1/pi) V cos / pdf = V.
        const glm::dvec3 w =
            frame.toWorld(sampleCosineHemisphere(sequence.get2D(index, kPairCosine)));
        value[0] = embree.occluded(origin, glm::vec3(w), tFar) ? 0.0 : 1.0;
        return 1;
    }
    case Quantity::AoUniform: {
        // Uniform hemisphere: (1/2pi) V / pdf = V.
        const glm::dvec3 w =
            frame.toWorld(sampleUniformHemisphere(sequence.get2D(index, kPairCosine)));
        value[0] = embree.occluded(origin, glm::vec3(w), tFar) ? 0.0 : 1.0;
        return 1;
    }
    case Quantity::Obscurance: {
        // [Zhukov et al. 1998]: rho(d / r) of the first hit, 1 beyond r; cosine-weighted.
        const glm::dvec3 w =
            frame.toWorld(sampleCosineHemisphere(sequence.get2D(index, kPairCosine)));
        RayHit hit;
        value[0] = embree.intersect(origin, glm::vec3(w), tFar, hit)
                       ? evaluateFalloff(context.falloff, double(hit.t) / context.radius)
                       : 1.0;
        return 1;
    }
    case Quantity::Bent: {
        // Bent normal [Landis 2002]: the mean of V w under cosine-weighted sampling is
        // (1/pi) Int V w cos dw; its direction is the cosine-weighted mean unoccluded direction.
        const glm::dvec3 w =
            frame.toWorld(sampleCosineHemisphere(sequence.get2D(index, kPairCosine)));
        const double visible = embree.occluded(origin, glm::vec3(w), tFar) ? 0.0 : 1.0;
        value[0] = visible * w.x;
        value[1] = visible * w.y;
        value[2] = visible * w.z;
        value[3] = visible;
        // Uniform visibility for the solid-angle aperture, from its own uniform ray.
        const glm::dvec3 wu =
            frame.toWorld(sampleUniformHemisphere(sequence.get2D(index, kPairUniform)));
        value[4] = embree.occluded(origin, glm::vec3(wu), tFar) ? 0.0 : 1.0;
        return 2;
    }
    default:
        return 0;
    }
}

} // namespace rtlab::reference
