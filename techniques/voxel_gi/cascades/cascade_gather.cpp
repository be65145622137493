// The C++ pixel gather of the cascades: the cones (or, for the error split, rays) from every
// G-buffer pixel through the levels (cascade_volume.h; the Vulkan twin is cascade_gather_gpu.h).

#include "cascade_volume.h"

#include "families/voxel_gi/upsample.h"

#include <glm/common.hpp>
#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace rtlab::voxelgi {

bool CascadeVolume::preparePixel(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& origin,
                                 glm::dvec3& n, ConeMarchSettings& march) const
{
    if (!gbuffer.hasSurface(x, y))
        return false;
    const glm::dvec3 p(gbuffer.position.at(x, y));
    n = glm::dvec3(gbuffer.normal.at(x, y));
    if (glm::dot(n, n) < 0.5 || !std::isfinite(p.x + p.y + p.z))
        return false;
    const double start = selectLevel(p, 0.0);
    if (start < 0.0)
        return false;
    // Start a voxel of the pixel's start level out, along the normal and along the cone.
    const double v = mSettings.voxelSize * std::exp2(std::floor(start));
    march.stepScale = mSettings.stepScale;
    march.startDistance = mSettings.startOffset * v;
    origin = p + n * (0.5 * mSettings.startOffset * v);
    return true;
}

void CascadeVolume::gather(const scene::GBuffer& gbuffer,
                           const std::vector<Image<float>>* coneVisibility, Image<glm::vec3>& out)
{
    std::vector<glm::vec3> cones;
    gatherCones(gbuffer, cones);
    const ReducedGBuffer same = reduceGBuffer(gbuffer, 1);
    ConeCombineInputs in;
    in.coneRadiance = &cones;
    in.reduced = &same;
    in.full = &gbuffer;
    in.visibility = coneVisibility;
    in.coneHalfAngle = mCones.halfAngle;
    out = combineCones(in);
}

void CascadeVolume::gatherCones(const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out)
{
    out.assign(std::size_t(gbuffer.width) * std::size_t(gbuffer.height) * kConeCount,
               glm::vec3(0.0f));
    const GatheredSampler sampler{this, true};
    std::vector<std::uint64_t> stepsPerRow(std::size_t(gbuffer.height), 0);
    std::vector<std::uint64_t> conesPerRow(std::size_t(gbuffer.height), 0);
    tbb::parallel_for(0, gbuffer.height, [&](int y) {
        for (int x = 0; x < gbuffer.width; ++x) {
            glm::dvec3 origin, n;
            ConeMarchSettings march;
            if (!preparePixel(gbuffer, x, y, origin, n, march))
                continue; // no surface, or outside every level: no indirect light
            march.tanHalfAngle = mCones.tanHalfAngle;
            const auto w = computeIrradianceWeights(mCones, n);
            const std::size_t base =
                (std::size_t(y) * std::size_t(gbuffer.width) + std::size_t(x)) * kConeCount;
            for (int k = 0; k < kConeCount; ++k) {
                if (w[std::size_t(k)] == 0.0)
                    continue;
                const ConeResult r =
                    marchCone(sampler, origin, mCones.directions[std::size_t(k)], k, march);
                stepsPerRow[std::size_t(y)] += std::uint64_t(r.steps);
                ++conesPerRow[std::size_t(y)];
                out[base + std::size_t(k)] = glm::max(r.light[kDirect], glm::vec3(0.0f));
            }
        }
    });
    std::uint64_t steps = 0, cones = 0;
    for (std::size_t i = 0; i < stepsPerRow.size(); ++i) {
        steps += stepsPerRow[i];
        cones += conesPerRow[i];
    }
    mCounters.meanStepsPerCone = cones ? double(steps) / double(cones) : 0.0;
}

void CascadeVolume::gatherRays(const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out) const
{
    out = Image<glm::vec3>(gbuffer.width, gbuffer.height, glm::vec3(0.0f));
    const GatheredSampler sampler{this, false}; // rays: the faces blended along each direction
    const int side = std::max(1, int(std::lround(std::sqrt(double(rays)))));
    tbb::parallel_for(0, gbuffer.height, [&](int y) {
        for (int x = 0; x < gbuffer.width; ++x) {
            glm::dvec3 origin, n;
            ConeMarchSettings march;
            if (!preparePixel(gbuffer, x, y, origin, n, march))
                continue;
            march.tanHalfAngle = 0.0; // rays
            const glm::dvec3 helper = std::abs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
            const glm::dvec3 t = glm::normalize(glm::cross(helper, n)), b = glm::cross(n, t);
            // A stratified side x side grid on the disk (Malley), turned by the pixel's hash.
            const double turn = double((std::uint32_t(x) * 73856093u) ^ (std::uint32_t(y) * 19349663u)) /
                                4294967296.0;
            glm::dvec3 sum(0.0);
            for (int i = 0; i < side; ++i)
                for (int j = 0; j < side; ++j) {
                    const double u1 = (i + 0.5) / side, u2 = (j + 0.5) / side + turn;
                    const double r = std::sqrt(u1), phi = 2.0 * glm::pi<double>() * u2;
                    const glm::dvec3 d = glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b +
                                                        std::sqrt(std::max(0.0, 1.0 - u1)) * n);
                    sum += glm::dvec3(marchCone(sampler, origin, d, -1, march).light[kDirect]);
                }
            out.at(x, y) = glm::vec3(glm::max(glm::pi<double>() * sum / double(side * side), glm::dvec3(0.0)));
        }
    });
}

} // namespace rtlab::voxelgi
