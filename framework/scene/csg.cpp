#include "scene/csg.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::scene {

const char* toString(CsgShape shape)
{
    switch (shape) {
    case CsgShape::Sphere: return "sphere";
    case CsgShape::Box: return "box";
    case CsgShape::RoundedBox: return "rounded_box";
    case CsgShape::Cylinder: return "cylinder";
    case CsgShape::Cone: return "cone";
    case CsgShape::Torus: return "torus";
    case CsgShape::Ellipsoid: return "ellipsoid";
    case CsgShape::Capsule: return "capsule";
    }
    return "?";
}

const char* toString(CsgOp op)
{
    switch (op) {
    case CsgOp::Add: return "add";
    case CsgOp::Subtract: return "subtract";
    case CsgOp::Intersect: return "intersect";
    }
    return "?";
}

const std::vector<std::string>& getCsgShapeNames()
{
    static const std::vector<std::string> names = {"sphere", "box", "rounded_box", "cylinder",
                                                   "cone", "torus", "ellipsoid", "capsule"};
    return names;
}

const std::vector<std::string>& getCsgOpNames()
{
    static const std::vector<std::string> names = {"add", "subtract", "intersect"};
    return names;
}

double computeSmoothMin(double a, double b, double k)
{
    if (k <= 0.0)
        return std::min(a, b);
    // [Quilez 2013, "smooth minimum", quadratic polynomial]: h is 0 once |a-b| >= k.
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

namespace {

double boxDistance(const glm::dvec3& p, const glm::dvec3& halfExtents)
{
    const glm::dvec3 q = glm::abs(p) - halfExtents;
    return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

// Exact distance to a capped cone with base radius r at y = -h and apex at y = +h
// (the cone is the solid of revolution of a right triangle; distance in the (radial, y) plane).
double coneDistance(const glm::dvec3& p, double r, double h)
{
    const glm::dvec2 q(std::sqrt(p.x * p.x + p.z * p.z), p.y);
    // 2D: triangle with vertices (0, -h), (r, -h), (0, h); distance to its boundary, signed.
    const glm::dvec2 a(0.0, h), b(r, -h);
    const glm::dvec2 ab = b - a;
    const glm::dvec2 onSlant = a + ab * std::clamp(glm::dot(q - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    const glm::dvec2 onBase(std::clamp(q.x, 0.0, r), -h);
    const double d = std::min(glm::length(q - onSlant), glm::length(q - onBase));
    // Inside when below the slant line and above the base.
    const double cross = ab.x * (q.y - a.y) - ab.y * (q.x - a.x);  // < 0 on the axis side of a->b
    const bool inside = q.y > -h && cross < 0.0;
    return inside ? -d : d;
}

} // namespace

double CsgEdit::evaluatePrimitive(const glm::dvec3& pw) const
{
    const glm::dvec3 p = glm::inverse(rotation) * (pw - center);
    switch (shape) {
    case CsgShape::Sphere:
        return glm::length(p) - size.x;
    case CsgShape::Box:
        return boxDistance(p, size);
    case CsgShape::RoundedBox:
        return boxDistance(p, size - glm::dvec3(rounding)) - rounding;
    case CsgShape::Cylinder: {
        const glm::dvec2 d = glm::abs(glm::dvec2(std::sqrt(p.x * p.x + p.z * p.z), p.y)) -
                             glm::dvec2(size.x, size.y);
        return std::min(std::max(d.x, d.y), 0.0) + glm::length(glm::max(d, 0.0));
    }
    case CsgShape::Cone:
        return coneDistance(p, size.x, size.y);
    case CsgShape::Torus: {
        const double ring = std::sqrt(p.x * p.x + p.z * p.z) - size.x;
        return std::sqrt(ring * ring + p.y * p.y) - size.y;
    }
    case CsgShape::Ellipsoid: {
        // First-order bound k0 (k0 - 1) / k1 [Quilez 2008]; exact on the surface.
        const double k0 = glm::length(p / size);
        const double k1 = glm::length(p / (size * size));
        if (k1 == 0.0)
            return -std::min(size.x, std::min(size.y, size.z));
        return k0 * (k0 - 1.0) / k1;
    }
    case CsgShape::Capsule: {
        const double y = std::clamp(p.y, -size.y, size.y);
        return glm::length(p - glm::dvec3(0.0, y, 0.0)) - size.x;
    }
    }
    return std::numeric_limits<double>::infinity();
}

void CsgEdit::getBounds(glm::dvec3& lo, glm::dvec3& hi) const
{
    // Local half extents, then the world box of the rotated local box. (Every shape sets e; the
    // initial value only keeps the compiler from warning that an out-of-range enum would not.)
    glm::dvec3 e(0.0);
    switch (shape) {
    case CsgShape::Sphere: e = glm::dvec3(size.x); break;
    case CsgShape::Box:
    case CsgShape::RoundedBox:
    case CsgShape::Ellipsoid: e = size; break;
    case CsgShape::Cylinder:
    case CsgShape::Cone: e = glm::dvec3(size.x, size.y, size.x); break;
    case CsgShape::Torus: e = glm::dvec3(size.x + size.y, size.y, size.x + size.y); break;
    case CsgShape::Capsule: e = glm::dvec3(size.x, size.y + size.x, size.x); break;
    }
    const glm::dmat3 r = glm::mat3_cast(rotation);
    const glm::dvec3 world = glm::abs(r[0]) * e.x + glm::abs(r[1]) * e.y + glm::abs(r[2]) * e.z;
    lo = center - world;
    hi = center + world;
}

double CsgEdit::applyTo(double d, const glm::dvec3& p) const
{
    const double s = evaluatePrimitive(p);
    switch (op) {
    case CsgOp::Add: return computeSmoothMin(d, s, blend);
    case CsgOp::Subtract: return -computeSmoothMin(-d, s, blend);   // max(d, -s)
    case CsgOp::Intersect: return -computeSmoothMin(-d, -s, blend); // max(d, s)
    }
    return d;
}

double SdfModel::evaluate(const glm::dvec3& p, int frame) const
{
    double d = std::numeric_limits<double>::infinity();
    for (const auto& e : edits)
        if (e.frame <= frame)
            d = e.applyTo(d, p);
    return d;
}

glm::dvec3 SdfModel::evaluateGradient(const glm::dvec3& p, int frame) const
{
    const double h = 1e-5 * std::max(1.0, glm::length(boundsMax - boundsMin));
    const glm::dvec3 g(evaluate(p + glm::dvec3(h, 0, 0), frame) - evaluate(p - glm::dvec3(h, 0, 0), frame),
                       evaluate(p + glm::dvec3(0, h, 0), frame) - evaluate(p - glm::dvec3(0, h, 0), frame),
                       evaluate(p + glm::dvec3(0, 0, h), frame) - evaluate(p - glm::dvec3(0, 0, h), frame));
    const double len = glm::length(g);
    return (len > 0.0 && std::isfinite(len)) ? g / len : glm::dvec3(0.0, 1.0, 0.0);
}

std::uint32_t SdfModel::evaluateMaterial(const glm::dvec3& p, int frame) const
{
    const double d = evaluate(p, frame);
    std::uint32_t material = 0;
    for (const auto& e : edits) {
        if (e.frame > frame || e.op != CsgOp::Add)
            continue;
        if (std::abs(e.evaluatePrimitive(p) - d) <= std::max(e.blend, 1e-9 * (1.0 + std::abs(d))) ||
            e.evaluatePrimitive(p) <= d)
            material = e.material;
    }
    return material;
}

bool SdfModel::changesOverTime() const
{
    return std::any_of(edits.begin(), edits.end(), [](const CsgEdit& e) { return e.frame > 0; });
}

} // namespace rtlab::scene
