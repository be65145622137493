// The C++ GTAO estimator: the same per-pixel computation as shaders/gtao.comp, statement for
// statement, so that the two agree to float rounding (see gtao.cpp for the algorithm).

#include "gtao_kernel.h"

#include "gtao_math.h"

#include "plugin/screen_space.h"

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numbers>

namespace rtlab::occlusion {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr float kHalfPi = 0.5f * std::numbers::pi_v<float>;

//! A depth that belongs to a surface: finite and positive (not NaN, not +inf sky).
bool isSurfaceDepth(float depth)
{
    return depth > 0.0f && depth <= FLT_MAX;
}

struct PixelResult {
    float ambient = 1.0f;
    glm::vec3 bentNormal{0.0f};
    float aperture = 0.0f;
};

class PixelEstimator {
public:
    PixelEstimator(const GtaoFrameConstants& c, const Image<float>& depth,
                   const Image<glm::vec3>& normal)
        : mC(c), mDepth(depth), mNormal(normal), mProjection{c.projScale, c.projOffset, c.size}
    {
    }

    PixelResult evaluate(int x, int y) const;

private:
    //! View-space point at continuous pixel coordinate `pos` (inside the texel-centre hull):
    //! bilinear interpolation of 1 / depth, which reproduces planes exactly (1 / depth is affine
    //! in screen space on a plane). False when one of the four texels has no surface.
    bool sampleViewPosition(glm::vec2 pos, glm::vec3& q) const;
    //! Screen-space search length on the side `sideSign` of direction s, px.
    float computeExtent(const glm::vec3& p, const glm::vec3& u, const glm::vec3& s,
                        float sideSign) const;

    const GtaoFrameConstants& mC;
    const Image<float>& mDepth;
    const Image<glm::vec3>& mNormal;
    plugin::ScreenProjection mProjection;
};

bool PixelEstimator::sampleViewPosition(glm::vec2 pos, glm::vec3& q) const
{
    const glm::vec2 f = pos - 0.5f;
    const int x0 = int(std::floor(f.x));
    const int y0 = int(std::floor(f.y));
    const int x1 = std::min(x0 + 1, mDepth.width - 1);
    const int y1 = std::min(y0 + 1, mDepth.height - 1);
    const float fx = f.x - float(x0);
    const float fy = f.y - float(y0);
    const float d00 = mDepth.at(x0, y0);
    const float d10 = mDepth.at(x1, y0);
    const float d01 = mDepth.at(x0, y1);
    const float d11 = mDepth.at(x1, y1);
    if (!(isSurfaceDepth(d00) && isSurfaceDepth(d10) && isSurfaceDepth(d01) && isSurfaceDepth(d11)))
        return false;
    const float top = 1.0f / d00 + (1.0f / d10 - 1.0f / d00) * fx;
    const float bottom = 1.0f / d01 + (1.0f / d11 - 1.0f / d01) * fx;
    const float inverseDepth = top + (bottom - top) * fy;
    q = mProjection.toView(pos, 1.0f / inverseDepth);
    return true;
}

float PixelEstimator::computeExtent(const glm::vec3& p, const glm::vec3& u, const glm::vec3& s,
                                    float sideSign) const
{
    if ((mC.flags & kGtaoFlagSphereExtent) == 0u) // [Jimenez et al. 2016]: radius at p's depth
        return std::min(mProjection.toPixelLength(mC.radius, -p.z), mC.maxPixelRadius);
    // The sphere of radius r around p meets the slice plane (which holds the camera) in a disk;
    // seen from the camera it spans the angle asin(r / |p|) on each side of p's ray, and the
    // screen line of the slice is the projection of that plane, so the tangent rays project to
    // the two ends of the search interval.
    const float sinAngle = mC.radius / gtao::length3(p);
    if (!(sinAngle < 1.0f))
        return mC.maxPixelRadius; // the camera is inside the sphere
    const float cosAngle = std::sqrt(1.0f - sinAngle * sinAngle);
    const glm::vec3 tangent = cosAngle * u + (sideSign * sinAngle) * s;
    if (!(tangent.z < 0.0f))
        return mC.maxPixelRadius; // the tangent ray leaves the front of the camera
    // Screen distance between the projections of the tangent ray and of p (the jitter offset
    // cancels).
    const glm::vec2 offset =
        (0.5f * mC.size * mC.projScale) *
        (glm::vec2(tangent.x, tangent.y) / -tangent.z - glm::vec2(p.x, p.y) / -p.z);
    const float extent = gtao::length2(offset);
    return extent < mC.maxPixelRadius ? extent : mC.maxPixelRadius; // NaN -> max
}

PixelResult PixelEstimator::evaluate(int x, int y) const
{
    PixelResult result;
    const float depth = mDepth.at(x, y);
    glm::vec3 n = mNormal.at(x, y);
    const float normalLength2 = gtao::dot3(n, n);
    if (!isSurfaceDepth(depth) || !(normalLength2 > 1e-12f) || !(normalLength2 <= FLT_MAX))
        return result;
    n = n / std::sqrt(normalLength2);

    const glm::vec2 centre = glm::vec2(float(x), float(y)) + 0.5f;
    const glm::vec3 p = mProjection.toView(centre, depth);
    const glm::vec3 u = p / gtao::length3(p); // camera -> p
    const glm::vec3 v = -u;                   // view vector
    // Orthonormal frame (t1, t2) of the plane orthogonal to v: slice directions are uniform in
    // the angle around v, the measure of the slice integral (the screen direction follows).
    glm::vec3 t1 = glm::vec3(1.0f, 0.0f, 0.0f) - v.x * v;
    t1 = t1 / gtao::length3(t1);
    const glm::vec3 t2 = gtao::cross3(v, t1);

    const float rotation = gtao::computeSliceRotation(x, y, mC.temporalRotation);
    const float jitter = gtao::computeStepJitter(x, y, mC.temporalStepOffset);
    const glm::vec2 lowCorner(0.5f);
    const glm::vec2 highCorner = mC.size - 0.5f;

    float visibleSum = 0.0f;
    float fullSum = 0.0f;
    glm::vec3 bentVisible(0.0f);
    glm::vec3 bentFull(0.0f);
    for (int slice = 0; slice < mC.slices; ++slice) {
        // [Jimenez et al. 2016, Alg. 1] slice direction, projected normal, its angle gamma.
        const float phi = (float(slice) + rotation) * mC.sliceAngle;
        const glm::vec2 cosSin = gtao::computeCosSin(phi);
        const glm::vec3 s = cosSin.x * t1 + cosSin.y * t2;
        const float ns = gtao::dot3(n, s);
        const float nv = gtao::dot3(n, v);
        const float projectedLength = std::sqrt(ns * ns + nv * nv);
        // gamma = atan2(ns, nv), limited to [-pi/2, pi/2] (normals facing away from the camera,
        // nv < 0, are taken as grazing).
        const float cosGamma = projectedLength > 0.0f ? nv / projectedLength : 1.0f;
        const float gammaMagnitude =
            std::min(gtao::computeAcos(std::clamp(cosGamma, -1.0f, 1.0f)), kHalfPi);
        const float gamma = ns < 0.0f ? -gammaMagnitude : gammaMagnitude;

        // Screen direction of the slice at p: the derivative of the projection along s.
        glm::vec2 dir(mC.size.x * mC.projScale.x * (s.x * depth + p.x * s.z),
                      mC.size.y * mC.projScale.y * (s.y * depth + p.y * s.z));
        const float dirLength = gtao::length2(dir);
        dir = dirLength > 0.0f ? dir / dirLength : glm::vec2(0.0f);

        // Horizon search on both sides: the largest cos(angle to v) of the samples within the
        // radius, starting from the normal's hemisphere boundary. [Jimenez et al. 2016, Alg. 1]
        float horizonCos[2];
        for (int side = 0; side < 2; ++side) {
            const float sideSign = side == 0 ? 1.0f : -1.0f;
            const float lowCos = -sideSign * std::sin(gamma); // cos(gamma +- pi/2)
            float maxCos = lowCos;
            const float extent = dirLength > 0.0f ? computeExtent(p, u, s, sideSign) : 0.0f;
            for (int step = 0; step < mC.steps && extent > 1.0f; ++step) {
                const float t = 1.0f + (extent - 1.0f) * ((float(step) + jitter) / float(mC.steps));
                const glm::vec2 pos = centre + (sideSign * t) * dir;
                if (!(pos.x >= lowCorner.x && pos.y >= lowCorner.y && pos.x <= highCorner.x &&
                      pos.y <= highCorner.y))
                    break; // farther steps are farther off screen
                glm::vec3 q;
                if (!sampleViewPosition(pos, q))
                    continue;
                const glm::vec3 delta = q - p;
                const float distance = gtao::length3(delta);
                if (!(distance <= mC.radius) || !(distance > 0.0f) || !(distance <= FLT_MAX))
                    continue; // occluders beyond the radius do not count
                const float weight = distance <= mC.falloffStart
                                         ? 1.0f
                                         : 1.0f - (distance - mC.falloffStart) * mC.falloffScale;
                const float sampleCos = gtao::dot3(delta, v) / distance;
                maxCos = std::max(maxCos, lowCos + (sampleCos - lowCos) * weight);
            }
            horizonCos[side] = maxCos;
        }
        // Signed horizon angles clamped to the normal's hemisphere. [Jimenez et al. 2016, Alg. 1]
        const float h2 =
            std::min(gtao::computeAcos(std::clamp(horizonCos[0], -1.0f, 1.0f)), gamma + kHalfPi);
        const float h1 =
            std::max(-gtao::computeAcos(std::clamp(horizonCos[1], -1.0f, 1.0f)), gamma - kHalfPi);

        // Cosine-weighted visible arc, weighted by |n_p|. [Jimenez et al. 2016, inner integral]
        visibleSum +=
            projectedLength * (gtao::integrateArc(h1, gamma) + gtao::integrateArc(h2, gamma));
        fullSum += projectedLength * gtao::integrateFullSlice(gamma);
        // Cosine-weighted mean direction of the visible arc. [Jimenez et al. 2016, bent normals]
        const float bs = gtao::integrateBentS(h1, gamma) + gtao::integrateBentS(h2, gamma);
        const float bv = gtao::integrateBentV(h1, gamma) + gtao::integrateBentV(h2, gamma);
        bentVisible += projectedLength * (bs * s + bv * v);
        bentFull += projectedLength *
                    ((4.0f / 3.0f) * std::sin(gamma) * s + (2.0f / 3.0f) * std::cos(gamma) * v);
    }

    float ambient;
    glm::vec3 bent;
    if ((mC.flags & kGtaoFlagNormalize) != 0u) {
        // Ratio to the unoccluded integral of the same slices, and the hemisphere's exact bent
        // vector (2/3) n minus the estimated occluded part (both exact when nothing occludes).
        ambient = fullSum > 0.0f ? visibleSum / fullSum : 1.0f;
        bent = ((2.0f / 3.0f) * float(mC.slices)) * n - (bentFull - bentVisible);
    } else {
        ambient = visibleSum / float(mC.slices);
        bent = bentVisible;
    }
    ambient = std::clamp(ambient, 0.0f, 1.0f);
    const float bentLength = gtao::length3(bent);
    result.ambient = ambient;
    result.bentNormal = bentLength > 1e-6f ? bent / bentLength : n;
    // sin^2(alpha) = A (cosine convention): alpha = asin(sqrt(A)) = pi/2 - acos(sqrt(A)).
    result.aperture = kHalfPi - gtao::computeAcos(std::sqrt(ambient));
    return result;
}

} // namespace

GtaoFrameConstants makeGtaoFrameConstants(const GtaoSettings& settings,
                                          const plugin::OcclusionInput& input, int width,
                                          int height)
{
    const auto projection = plugin::ScreenProjection::fromMatrix(input.projection, width, height);
    GtaoFrameConstants c;
    c.projScale = projection.scale;
    c.projOffset = projection.offset;
    c.size = projection.size;
    c.radius = float(settings.radius);
    const bool finiteRadius = std::isfinite(c.radius);
    if (settings.falloffFraction > 0.0 && finiteRadius && c.radius > 0.0f) {
        c.falloffStart = float(settings.radius * (1.0 - settings.falloffFraction));
        c.falloffScale = float(1.0 / (settings.falloffFraction * settings.radius));
    } else {
        c.falloffStart = c.radius; // hard cutoff (also for radius 0 and +inf)
        c.falloffScale = 0.0f;
    }
    c.maxPixelRadius = float(settings.maxPixelRadius);
    c.sliceAngle = kPi / float(settings.slices);
    const int frame = settings.temporalRotation ? input.frameIndex : 0;
    const auto wrap = [](int value, int period) { return ((value % period) + period) % period; };
    c.temporalRotation = gtao::kTemporalRotations[std::size_t(wrap(frame, 6))];
    c.temporalStepOffset = gtao::kTemporalStepOffsets[std::size_t(wrap(frame, 4))];
    c.slices = settings.slices;
    c.steps = settings.steps;
    c.flags = (settings.normalize ? kGtaoFlagNormalize : 0u) |
              (settings.searchExtent == GtaoSearchExtent::Sphere ? kGtaoFlagSphereExtent : 0u);
    return c;
}

void computeGtaoCpu(const GtaoFrameConstants& constants, const Image<float>& depth,
                    const Image<glm::vec3>& normal, plugin::OcclusionOutput& out)
{
    const int width = depth.width;
    const int height = depth.height;
    out.ambient = Image<float>(width, height, 1.0f);
    out.bentNormal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    out.coneAperture = Image<float>(width, height, 0.0f);
    out.coneVisibility.clear();
    const PixelEstimator estimator(constants, depth, normal);
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y) {
            for (int x = 0; x < width; ++x) {
                const PixelResult r = estimator.evaluate(x, y);
                out.ambient.at(x, y) = r.ambient;
                out.bentNormal.at(x, y) = r.bentNormal;
                out.coneAperture.at(x, y) = r.aperture;
            }
        }
    });
}

} // namespace rtlab::occlusion
