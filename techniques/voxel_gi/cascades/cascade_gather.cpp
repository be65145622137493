// The C++ pixel gather of the cascades: the cones (or, for the error split, rays) from every
// G-buffer pixel through the levels (cascade_volume.h; the Vulkan twin is cascade_gather_gpu.h).

#include "cascade_volume.h"

#include "families/voxel_gi/pixel_cones.h"
#include "families/voxel_gi/upsample.h"

#include <algorithm>
#include <cmath>

namespace rtlab::voxelgi {

bool CascadeVolume::preparePixel(const scene::GBuffer& gbuffer, int x, int y, glm::dvec3& origin,
                                 glm::dvec3& n, ConeMarchSettings& march) const
{
    glm::dvec3 p;
    if (!readPixelSurface(gbuffer, x, y, p, n))
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
    const auto prepare = [this](const scene::GBuffer& g, int x, int y, glm::dvec3& origin,
                                glm::dvec3& n, ConeMarchSettings& march) {
        return preparePixel(g, x, y, origin, n, march);
    };
    mCounters.meanStepsPerCone =
        traceGBufferCones(gbuffer, mCones, prepare, GatheredSampler{this, true}, out);
}

void CascadeVolume::gatherRays(const scene::GBuffer& gbuffer, int rays, Image<glm::vec3>& out) const
{
    const auto prepare = [this](const scene::GBuffer& g, int x, int y, glm::dvec3& origin,
                                glm::dvec3& n, ConeMarchSettings& march) {
        return preparePixel(g, x, y, origin, n, march);
    };
    // Rays: the faces blended along each direction (no per-cone pre-combined buffer).
    traceGBufferRays(gbuffer, rays, prepare, GatheredSampler{this, false}, out);
}

} // namespace rtlab::voxelgi
