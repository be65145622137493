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

#include <algorithm>
#include <array>
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
//! (the field kDirect of the sampler's result: the gathered light), and with `sky` the cones' sky
//! and emitters in the same layout. Returns the mean number of steps per cone traced.
template <class Prepare, class Sampler>
double traceGBufferCones(const scene::GBuffer& gbuffer, const ConeSet& cones, const Prepare& prepare,
                         const Sampler& sampler, std::vector<glm::vec3>& out,
                         const ConeSkyOutput* sky = nullptr)
{
    const int W = gbuffer.width, H = gbuffer.height;
    out.assign(std::size_t(W) * std::size_t(H) * kConeCount, glm::vec3(0.0f));
    std::vector<glm::vec3>* skyOut = sky != nullptr ? sky->out : nullptr;
    if (skyOut != nullptr)
        skyOut->assign(out.size(), glm::vec3(0.0f));
    // The pixels' cone origins first; then the cones one direction at a time over a block of
    // rows, so that a thread's lookups stay in one direction's data (a pre-combined structure
    // keeps a buffer per cone: 16 x 512 KiB per 32^3 level, against 1 MiB of L2 here).
    struct Start {
        glm::dvec3 origin{0.0};
        ConeMarchSettings march;
        std::uint32_t cones = 0; // bit k: cone k has a non-zero irradiance weight
    };
    std::vector<Start> starts(std::size_t(W) * std::size_t(H));
    tbb::parallel_for(0, H, [&](int y) {
        for (int x = 0; x < W; ++x) {
            Start& s = starts[std::size_t(y) * std::size_t(W) + std::size_t(x)];
            glm::dvec3 n;
            if (!prepare(gbuffer, x, y, s.origin, n, s.march))
                continue; // no surface, or outside the structure: no indirect light
            s.march.tanHalfAngle = cones.tanHalfAngle;
            s.march.sky = skyOut != nullptr; // else no cone marches on for the sky alone
            const auto w = computeIrradianceWeights(cones, n);
            for (int k = 0; k < kConeCount; ++k)
                if (w[std::size_t(k)] != 0.0)
                    s.cones |= 1u << k;
        }
    });
    constexpr int kRowsPerTask = 4;
    const int blocks = (H + kRowsPerTask - 1) / kRowsPerTask;
    std::vector<std::uint64_t> stepsPerTask(std::size_t(blocks) * kConeCount, 0);
    std::vector<std::uint64_t> conesPerTask(std::size_t(blocks) * kConeCount, 0);
    tbb::parallel_for(0, blocks * kConeCount, [&](int task) {
        const int k = task / blocks, block = task % blocks;
        const glm::dvec3& dir = cones.directions[std::size_t(k)];
        for (int y = block * kRowsPerTask; y < std::min(H, (block + 1) * kRowsPerTask); ++y)
            for (int x = 0; x < W; ++x) {
                const std::size_t pixel = std::size_t(y) * std::size_t(W) + std::size_t(x);
                const Start& s = starts[pixel];
                if (!(s.cones >> k & 1u))
                    continue;
                const ConeResult r = marchCone(sampler, s.origin, dir, k, s.march);
                stepsPerTask[std::size_t(task)] += std::uint64_t(r.steps);
                ++conesPerTask[std::size_t(task)];
                out[pixel * kConeCount + std::size_t(k)] =
                    glm::max(r.light[kDirect], glm::vec3(0.0f));
                if (skyOut != nullptr)
                    (*skyOut)[pixel * kConeCount + std::size_t(k)] =
                        computeConeSkyRadiance(r, sky->skyPerCone[std::size_t(k)]);
            }
    });
    std::uint64_t steps = 0, traced = 0;
    for (std::size_t i = 0; i < stepsPerTask.size(); ++i) {
        steps += stepsPerTask[i];
        traced += conesPerTask[i];
    }
    return traced ? double(steps) / double(traced) : 0.0;
}

//! Irradiance at every pixel from `rays` cosine-distributed rays (zero aperture) through the
//! sampler's gathered light, E = pi * mean radiance. The directions are a stratified grid on the
//! disk (Malley's method) turned per pixel by a hash, so the result is deterministic. With `sky`,
//! the irradiance from the sky and emitters instead: per ray what computeConeSkyRadiance gives a
//! cone, the sky's radiance in the ray's own direction (the error split of the cones' sky).
template <class Prepare, class Sampler>
void traceGBufferRays(const scene::GBuffer& gbuffer, int rays, const Prepare& prepare,
                      const Sampler& sampler, Image<glm::vec3>& out, const scene::Sky* sky = nullptr)
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
            march.sky = sky != nullptr;
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
                    const ConeResult ray = marchCone(sampler, origin, d, -1, march);
                    sum += sky != nullptr ? glm::dvec3(computeConeSkyRadiance(ray, sky->radiance(d)))
                                          : glm::dvec3(ray.light[kDirect]);
                }
            out.at(x, y) =
                glm::vec3(glm::max(glm::pi<double>() * sum / double(side * side), glm::dvec3(0.0)));
        }
    });
}

} // namespace rtlab::voxelgi
