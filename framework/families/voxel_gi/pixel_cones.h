#pragma once
// The pixel side of cone tracing, shared by every structure that is cone traced from the G-buffer
// (cascades, the sparse octree): the 16 cones of each pixel through a structure's Sampler
// (cone_tracing.h marchCone), and the zero-aperture rays of the error split. A structure gives
// `prepare(gbuffer, x, y, origin, n, march) -> bool` (where the pixel's cones start, false for
// no indirect light) and its Sampler.

#include "families/voxel_gi/cone_tracing.h"
#include "core/image.h"
#include "scene/gbuffer.h"

#include <glm/common.hpp>
#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace rtlab::voxelgi {

//! The pixel's surface point and unit normal; false without a surface, with a non-finite
//! position or without a normal (no indirect light there).
inline bool readPixelSurface(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& p, glm::dvec3& n)
{
    if (!gbuffer.hasSurface(x, y))
        return false;
    p = glm::dvec3(gbuffer.position.at(x, y));
    n = glm::dvec3(gbuffer.normal.at(x, y));
    return glm::dot(n, n) >= 0.5 && std::isfinite(p.x + p.y + p.z);
}

//! The radiance of each cone above the surface at every pixel, [pixel * 16 + cone], 0 elsewhere
//! (the field kDirect of the sampler's result: the gathered light). Returns the mean number of
//! steps per cone traced.
template <class Prepare, class Sampler>
double traceGBufferCones(const scene::GBuffer& gbuffer, const ConeSet& cones, const Prepare& prepare,
                         const Sampler& sampler, std::vector<glm::vec3>& out)
{
    out.assign(std::size_t(gbuffer.width) * std::size_t(gbuffer.height) * kConeCount, glm::vec3(0.0f));
    std::vector<std::uint64_t> stepsPerRow(std::size_t(gbuffer.height), 0);
    std::vector<std::uint64_t> conesPerRow(std::size_t(gbuffer.height), 0);
    tbb::parallel_for(0, gbuffer.height, [&](int y) {
        for (int x = 0; x < gbuffer.width; ++x) {
            glm::dvec3 origin, n;
            ConeMarchSettings march;
            if (!prepare(gbuffer, x, y, origin, n, march))
                continue; // no surface, or outside the structure: no indirect light
            march.tanHalfAngle = cones.tanHalfAngle;
            const auto w = computeIrradianceWeights(cones, n);
            const std::size_t base =
                (std::size_t(y) * std::size_t(gbuffer.width) + std::size_t(x)) * kConeCount;
            for (int k = 0; k < kConeCount; ++k) {
                if (w[std::size_t(k)] == 0.0)
                    continue;
                const ConeResult r = marchCone(sampler, origin, cones.directions[std::size_t(k)], k, march);
                stepsPerRow[std::size_t(y)] += std::uint64_t(r.steps);
                ++conesPerRow[std::size_t(y)];
                out[base + std::size_t(k)] = glm::max(r.light[kDirect], glm::vec3(0.0f));
            }
        }
    });
    std::uint64_t steps = 0, traced = 0;
    for (std::size_t i = 0; i < stepsPerRow.size(); ++i) {
        steps += stepsPerRow[i];
        traced += conesPerRow[i];
    }
    return traced ? double(steps) / double(traced) : 0.0;
}

//! Irradiance at every pixel from `rays` cosine-distributed rays (zero aperture) through the
//! sampler's gathered light, E = pi * mean radiance. The directions are a stratified grid on the
//! disk (Malley's method) turned per pixel by a hash, so the result is deterministic.
template <class Prepare, class Sampler>
void traceGBufferRays(const scene::GBuffer& gbuffer, int rays, const Prepare& prepare,
                      const Sampler& sampler, Image<glm::vec3>& out)
{
    out = Image<glm::vec3>(gbuffer.width, gbuffer.height, glm::vec3(0.0f));
    const int side = std::max(1, int(std::lround(std::sqrt(double(rays)))));
    tbb::parallel_for(0, gbuffer.height, [&](int y) {
        for (int x = 0; x < gbuffer.width; ++x) {
            glm::dvec3 origin, n;
            ConeMarchSettings march;
            if (!prepare(gbuffer, x, y, origin, n, march))
                continue;
            march.tanHalfAngle = 0.0; // rays
            const glm::dvec3 helper = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
            const glm::dvec3 t = glm::normalize(glm::cross(helper, n)), b = glm::cross(n, t);
            const double turn =
                double((std::uint32_t(x) * 73856093u) ^ (std::uint32_t(y) * 19349663u)) / 4294967296.0;
            glm::dvec3 sum(0.0);
            for (int i = 0; i < side; ++i)
                for (int j = 0; j < side; ++j) {
                    const double u1 = (i + 0.5) / side, u2 = (j + 0.5) / side + turn;
                    const double r = std::sqrt(u1), phi = 2.0 * glm::pi<double>() * u2;
                    const glm::dvec3 d = glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b +
                                                        std::sqrt(std::max(0.0, 1.0 - u1)) * n);
                    sum += glm::dvec3(marchCone(sampler, origin, d, -1, march).light[kDirect]);
                }
            out.at(x, y) =
                glm::vec3(glm::max(glm::pi<double>() * sum / double(side * side), glm::dvec3(0.0)));
        }
    });
}

} // namespace rtlab::voxelgi
