#include "families/voxel_gi/cone_tracing.h"

#include "core/error.h"
#include "core/hash.h"

#include <glm/gtc/constants.hpp>
#include <glm/trigonometric.hpp>

#include <string>

namespace rtlab::voxelgi {

std::string computeLightsKey(const scene::RenderScene& g)
{
    Hasher h;
    h.addValue(g.pointLights.size());
    for (const auto& l : g.pointLights)
        h.addValue(l.position).addValue(l.intensity);
    h.addValue(int(g.sky.kind))
        .addValue(g.sky.constant)
        .addValue(g.sky.zenith)
        .addValue(g.sky.horizon)
        .addValue(g.sky.ground)
        .addValue(g.sky.lobes)
        .addValue(g.sky.sharpness);
    return h.hexDigest();
}

ConeSet ConeSet::make(double halfAngleDegrees)
{
    if (!(halfAngleDegrees > 0.0 && halfAngleDegrees < 90.0))
        throw Error("cone half-angle must be in (0, 90) degrees, found " +
                    std::to_string(halfAngleDegrees));
    ConeSet set;
    set.directions = scene::getConeDirections();
    set.halfAngle = glm::radians(halfAngleDegrees);
    set.tanHalfAngle = std::tan(set.halfAngle);
    return set;
}

std::array<double, kConeCount> computeIrradianceWeights(const ConeSet& cones, const glm::dvec3& n)
{
    std::array<double, kConeCount> w{};
    double sum = 0.0;
    for (int k = 0; k < kConeCount; ++k) {
        w[std::size_t(k)] = std::max(0.0, glm::dot(cones.directions[std::size_t(k)], n));
        sum += w[std::size_t(k)];
    }
    // The design covers the sphere, so some cone is above any plane; a zero normal gets none.
    if (sum > 0.0)
        for (double& x : w)
            x *= glm::pi<double>() / sum;
    return w;
}

std::array<glm::vec3, kConeCount> computeSkyPerCone(const scene::Sky& sky, const ConeSet& cones)
{
    std::array<glm::vec3, kConeCount> out{};
    constexpr int kRings = 8, kAzimuths = 16;
    const double cosMax = std::cos(cones.halfAngle);
    for (int k = 0; k < kConeCount; ++k) {
        const glm::dvec3 axis = cones.directions[std::size_t(k)];
        // An orthonormal frame about the axis.
        const glm::dvec3 helper =
            std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
        const glm::dvec3 t = glm::normalize(glm::cross(helper, axis));
        const glm::dvec3 b = glm::cross(axis, t);
        glm::dvec3 sum(0.0);
        // Midpoints in cos(theta) and azimuth: equal solid angle per sample.
        for (int i = 0; i < kRings; ++i) {
            const double c = 1.0 - (i + 0.5) / kRings * (1.0 - cosMax);
            const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
            for (int j = 0; j < kAzimuths; ++j) {
                const double phi = (j + 0.5) / kAzimuths * 2.0 * glm::pi<double>();
                const glm::dvec3 d = c * axis + s * (std::cos(phi) * t + std::sin(phi) * b);
                sum += glm::dvec3(sky.radiance(d));
            }
        }
        out[std::size_t(k)] = glm::vec3(sum / double(kRings * kAzimuths));
    }
    return out;
}

glm::dvec3 getShadingNormal(const InjectionVoxel& voxel, int face)
{
    glm::dvec3 axis(0.0);
    axis[face / 2] = (face % 2 == 0) ? 1.0 : -1.0;
    const glm::dvec3 n(voxel.normal);
    return glm::dot(n, axis) > 0.0 ? n : axis;
}

} // namespace rtlab::voxelgi
