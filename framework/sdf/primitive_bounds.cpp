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

// The box in the primitive's frame: the local axis-aligned box around the rotated world box, as
// per-axis ranges of |q_i| (minAbs, maxAbs). Conservative for rotated primitives.
struct LocalRange {
    glm::dvec3 minAbs, maxAbs;
};

LocalRange getLocalRange(const scene::CsgEdit& edit, const glm::dvec3& c, const glm::dvec3& half)
{
    const glm::dmat3 toLocal = glm::mat3_cast(glm::inverse(edit.rotation));
    const glm::dvec3 lc = toLocal * (c - edit.center);
    const glm::dvec3 le = glm::abs(toLocal[0]) * half.x + glm::abs(toLocal[1]) * half.y +
                          glm::abs(toLocal[2]) * half.z;
    LocalRange r;
    for (int i = 0; i < 3; ++i) {
        const double lo = lc[i] - le[i], hi = lc[i] + le[i];
        r.minAbs[i] = (lo <= 0.0 && hi >= 0.0) ? 0.0 : std::min(std::abs(lo), std::abs(hi));
        r.maxAbs[i] = std::max(std::abs(lo), std::abs(hi));
    }
    return r;
}

double boxDistance(const glm::dvec3& q, const glm::dvec3& halfExtents)
{
    const glm::dvec3 d = q - halfExtents;
    return glm::length(glm::max(d, 0.0)) + std::min(std::max(d.x, std::max(d.y, d.z)), 0.0);
}

double cylinderDistance(double radial, double y, double radius, double halfHeight)
{
    const glm::dvec2 d(radial - radius, y - halfHeight);
    return std::min(std::max(d.x, d.y), 0.0) + glm::length(glm::max(d, 0.0));
}

double capsuleDistance(double radial, double y, double radius, double halfLength)
{
    return std::sqrt(radial * radial + std::max(y - halfLength, 0.0) * std::max(y - halfLength, 0.0)) - radius;
}

// Interval arithmetic in the primitive's frame for the shapes whose value is non-decreasing in
// each |q_i| (box, rounded box), in the radial distance and |y| (cylinder, capsule), or in |y|
// and |radial - major| (torus): the range over the box is spanned by the extreme |q_i|. Returns
// false for the cone (Lipschitz only).
bool boundInLocalFrame(const scene::CsgEdit& edit, const LocalRange& r, Interval& out)
{
    const glm::dvec3 s = edit.size;
    const double radialLo = glm::length(glm::dvec2(r.minAbs.x, r.minAbs.z));
    const double radialHi = glm::length(glm::dvec2(r.maxAbs.x, r.maxAbs.z));
    switch (edit.shape) {
    case scene::CsgShape::Box:
        out = {boxDistance(r.minAbs, s), boxDistance(r.maxAbs, s)};
        return true;
    case scene::CsgShape::RoundedBox:
        out = {boxDistance(r.minAbs, s - glm::dvec3(edit.rounding)) - edit.rounding,
               boxDistance(r.maxAbs, s - glm::dvec3(edit.rounding)) - edit.rounding};
        return true;
    case scene::CsgShape::Cylinder:
        out = {cylinderDistance(radialLo, r.minAbs.y, s.x, s.y), cylinderDistance(radialHi, r.maxAbs.y, s.x, s.y)};
        return true;
    case scene::CsgShape::Capsule:
        out = {capsuleDistance(radialLo, r.minAbs.y, s.x, s.y), capsuleDistance(radialHi, r.maxAbs.y, s.x, s.y)};
        return true;
    case scene::CsgShape::Torus: {
        const double ringLo = (radialLo <= s.x && radialHi >= s.x)
                                  ? 0.0
                                  : std::min(std::abs(radialLo - s.x), std::abs(radialHi - s.x));
        const double ringHi = std::max(std::abs(radialLo - s.x), std::abs(radialHi - s.x));
        out = {std::sqrt(ringLo * ringLo + r.minAbs.y * r.minAbs.y) - s.y,
               std::sqrt(ringHi * ringHi + r.maxAbs.y * r.maxAbs.y) - s.y};
        return true;
    }
    case scene::CsgShape::Sphere:
        out = {glm::length(r.minAbs) - s.x, glm::length(r.maxAbs) - s.x};
        return true;
    default: return false;
    }
}

// Interval arithmetic on rho (k0 - 1), rho = k0 / k1 (see the header).
Interval boundEllipsoid(const scene::CsgEdit& edit, const LocalRange& range, double margin)
{
    const glm::dvec3 s = edit.size;
    if (!(s.x > 0.0 && s.y > 0.0 && s.z > 0.0))
        return makeUnbounded();
    const glm::dvec3 minAbs = range.minAbs, maxAbs = range.maxAbs;
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

bool isLipschitzPrimitive(const scene::CsgEdit& edit)
{
    const glm::dvec3 s = edit.size;
    return edit.shape != scene::CsgShape::Ellipsoid && isUnitRotation(edit.rotation) &&
           s.x >= 0.0 && s.y >= 0.0 && s.z >= 0.0 && std::isfinite(s.x + s.y + s.z) &&
           edit.rounding >= 0.0 && std::isfinite(edit.rounding);
}

double boundLipschitzConstant(const scene::CsgEdit& edit, const glm::dvec3& boxLo,
                              const glm::dvec3& boxHi)
{
    constexpr double kNone = std::numeric_limits<double>::infinity();
    if (isLipschitzPrimitive(edit))
        return 1.0;
    const glm::dvec3 s = edit.size;
    if (edit.shape != scene::CsgShape::Ellipsoid || !isUnitRotation(edit.rotation) ||
        !(s.x > 0.0 && s.y > 0.0 && s.z > 0.0) || !std::isfinite(s.x + s.y + s.z))
        return kNone;
    // f = rho (k0 - 1) with rho = k0 / k1 (q = p / s, r = p / s^2, w = p / s^4 componentwise;
    // k0 = |q|, k1 = |r|). grad k0 = r / k0, so rho grad k0 = r / k1, a unit vector, and
    //   grad f = r / k1 + (k0 - 1) grad rho,  |grad f| <= 1 + |k0 - 1| |grad rho|.
    // rho is constant along rays from the centre; grad rho = (r / k1 - rho^2 w / k1) / k0.
    // Writing t_i = q_i^2 / k0^2 (weights summing to 1) and Z_i = s_i^-2 / sum_j t_j s_j^-2
    // (mean 1 under t, within [1/R^2, R^2]), |grad rho|^2 = E_t[Z (Z - 1)^2] / k0^2
    // <= R^2 Var_t(Z) / k0^2 <= R^2 (R^2 - 1)(1 - 1/R^2) / k0^2 = (R^2 - 1)^2 / k0^2, the
    // variance bounded by the Bhatia-Davis inequality [Bhatia & Davis 2000]. Hence
    //   |grad f| <= 1 + |1 - 1/k0| (R^2 - 1),
    // and |1 - 1/k0| is largest at an end of the box's range of k0.
    const glm::dvec3 c = 0.5 * (boxLo + boxHi);
    const glm::dvec3 half = 0.5 * (boxHi - boxLo);
    const LocalRange range = getLocalRange(edit, c, half);
    const double k0Lo = glm::length(range.minAbs / s), k0Hi = glm::length(range.maxAbs / s);
    if (!(k0Lo > 0.0) || !std::isfinite(k0Hi))
        return kNone;
    const double ratio = std::max({s.x, s.y, s.z}) / std::min({s.x, s.y, s.z});
    const double farthest = std::max(std::abs(1.0 - 1.0 / k0Lo), std::abs(1.0 - 1.0 / k0Hi));
    // Rounded up well past the relative rounding of the terms (a few ulps each).
    const double l = (1.0 + farthest * (ratio * ratio - 1.0)) * (1.0 + 1e-9);
    return std::isfinite(l) ? l : kNone;
}

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
    const LocalRange range = getLocalRange(edit, c, half);
    if (edit.shape == scene::CsgShape::Ellipsoid)
        return boundEllipsoid(edit, range, margin);
    // Exact distances are 1-Lipschitz: |s(p) - s(c)| <= |p - c| <= |half|. In the L2 norm a cell
    // is bounded by the ball of its half-diagonal; [Evans 2015] uses max-norm distances so that a
    // cell is exactly a ball. The interval in the primitive's frame recovers most of that gap
    // where the primitive is aligned with the grid, and the two are intersected.
    const double radius = glm::length(half);
    const double v = edit.evaluatePrimitive(c);
    if (!std::isfinite(v) || !std::isfinite(radius))
        return makeUnbounded();
    Interval r{v - radius, v + radius};
    Interval local;
    if (boundInLocalFrame(edit, range, local) && local.lo <= local.hi) {
        // Rounding of the local evaluation is relative to the coordinates, which `margin` covers.
        r.lo = std::max(r.lo, local.lo);
        r.hi = std::min(r.hi, local.hi);
    }
    return {r.lo - margin, r.hi + margin};
}

} // namespace rtlab::sdf
