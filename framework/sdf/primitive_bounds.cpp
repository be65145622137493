#include "sdf/primitive_bounds.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat3x3.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::sdf {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Interval makeUnbounded()
{
    return {-kInf, kInf};
}

bool isUnitRotation(const glm::dquat& q)
{
    const double n = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    return std::abs(n - 1.0) <= 1e-9;
}

// Interval arithmetic on rho (k0 - 1), rho = k0 / k1 (see the header).
Interval boundEllipsoid(const scene::CsgEdit& edit, const glm::dvec3& c, const glm::dvec3& half,
                        double margin)
{
    const glm::dvec3 s = edit.size;
    if (!(s.x > 0.0 && s.y > 0.0 && s.z > 0.0) || !std::isfinite(s.x + s.y + s.z))
        return makeUnbounded();
    const glm::dmat3 toLocal = glm::mat3_cast(glm::inverse(edit.rotation));
    const glm::dvec3 lc = toLocal * (c - edit.center);
    const glm::dvec3 le = glm::abs(toLocal[0]) * half.x + glm::abs(toLocal[1]) * half.y +
                          glm::abs(toLocal[2]) * half.z;
    glm::dvec3 minAbs, maxAbs;
    for (int i = 0; i < 3; ++i) {
        const double lo = lc[i] - le[i], hi = lc[i] + le[i];
        minAbs[i] = (lo <= 0.0 && hi >= 0.0) ? 0.0 : std::min(std::abs(lo), std::abs(hi));
        maxAbs[i] = std::max(std::abs(lo), std::abs(hi));
    }
    const double k0Lo = glm::length(minAbs / s), k0Hi = glm::length(maxAbs / s);
    const double k1Lo = glm::length(minAbs / (s * s)), k1Hi = glm::length(maxAbs / (s * s));
    const double sMin = std::min({s.x, s.y, s.z}), sMax = std::max({s.x, s.y, s.z});
    // rho = |q/s| / |q/s^2| lies in [sMin, sMax] for every q != 0, and at q = 0 the primitive
    // returns -sMin, which the bound below also contains.
    const double rhoLo = k1Hi > 0.0 ? std::max(sMin, k0Lo / k1Hi) : sMin;
    const double rhoHi = k1Lo > 0.0 ? std::min(sMax, k0Hi / k1Lo) : sMax;
    const double aLo = k0Lo - 1.0, aHi = k0Hi - 1.0;
    Interval r;
    r.lo = aLo >= 0.0 ? rhoLo * aLo : rhoHi * aLo;
    r.hi = aHi >= 0.0 ? rhoHi * aHi : rhoLo * aHi;
    // Rounding in k0 and k1 is relative to their size; this term covers it with a wide margin.
    const double rounding = 1e-12 * rhoHi * (k0Hi + 1.0);
    r.lo -= margin + rounding;
    r.hi += margin + rounding;
    if (!(r.lo <= r.hi))  // NaN
        return makeUnbounded();
    return r;
}

} // namespace

Interval boundPrimitive(const scene::CsgEdit& edit, const glm::dvec3& boxLo, const glm::dvec3& boxHi,
                        double margin)
{
    if (!isUnitRotation(edit.rotation))
        return makeUnbounded();
    const glm::dvec3 s = edit.size;
    if (!(s.x >= 0.0 && s.y >= 0.0 && s.z >= 0.0) || !std::isfinite(s.x + s.y + s.z) ||
        !(edit.rounding >= 0.0) || !std::isfinite(edit.rounding))
        return makeUnbounded();
    const glm::dvec3 c = 0.5 * (boxLo + boxHi);
    const glm::dvec3 half = 0.5 * (boxHi - boxLo);
    if (edit.shape == scene::CsgShape::Ellipsoid)
        return boundEllipsoid(edit, c, half, margin);
    // Exact distances are 1-Lipschitz: |s(p) - s(c)| <= |p - c| <= |half|.
    const double radius = glm::length(half);
    const double v = edit.evaluatePrimitive(c);
    if (!std::isfinite(v) || !std::isfinite(radius))
        return makeUnbounded();
    return {v - radius - margin, v + radius + margin};
}

} // namespace rtlab::sdf
