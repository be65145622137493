#include "sdf/edit_ops.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::sdf::detail {

using scene::CsgEdit;
using scene::CsgOp;
using scene::SdfModel;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

OpKind toOpKind(CsgOp op)
{
    switch (op) {
    case CsgOp::Add:
        return OpKind::Add;
    case CsgOp::Subtract:
        return OpKind::Subtract;
    case CsgOp::Intersect:
        return OpKind::Intersect;
    }
    return OpKind::Add;
}

} // namespace

std::vector<Op> getActiveOps(const SdfModel& model, int frame)
{
    std::vector<Op> ops;
    for (const auto& e : model.edits)
        if (e.frame <= frame)
            ops.push_back({&e, toOpKind(e.op)});
    return ops;
}

double evaluateOps(const std::vector<Op>& ops, const glm::dvec3& p)
{
    double d = kInf;
    for (const Op& op : ops)
        d = applyOp(op.kind, d, op.edit->evaluatePrimitive(p), op.edit->blend);
    return d;
}

namespace {

// Smooth minimum with its gradient: the value is computeSmoothMin's; the weights are its partial
// derivatives (for a <= b inside the blend, u = k - (b - a): d/da = 1 - u / 2k, d/db = u / 2k).
double smoothMinWithGradient(double a, const glm::dvec3& ga, bool kinkA, double b,
                             const glm::dvec3& gb, double k, glm::dvec3& g, bool& kink)
{
    const double v = scene::computeSmoothMin(a, b, k);
    const double diff = std::abs(a - b);
    if (k > 0.0 && diff < k) {
        const double w = (k - diff) / (2.0 * k);
        const double wa = a <= b ? 1.0 - w : w;
        g = wa * ga + (1.0 - wa) * gb;
        kink = kinkA;
    } else if (a < b) {
        g = ga;
        kink = kinkA;
    } else if (b < a) {
        g = gb;
        kink = false;
    } else {
        // An exact tie of a hard min: the gradient is defined only if both sides agree.
        g = ga;
        kink = kinkA || ga != gb;
    }
    return v;
}

glm::dvec3 getPrimitiveGradient(const CsgEdit& e, const glm::dvec3& p, double h)
{
    glm::dvec3 g;
    for (int i = 0; i < 3; ++i) {
        glm::dvec3 a = p, b = p;
        a[i] += h;
        b[i] -= h;
        g[i] = (e.evaluatePrimitive(a) - e.evaluatePrimitive(b)) / (a[i] - b[i]);
    }
    return g;
}

} // namespace

// Value (bit-identical to evaluateOps) and gradient of the pruned field. `kink` is set where the
// gradient is undefined.
double evaluateOpsWithGradient(const std::vector<Op>& ops, const glm::dvec3& p, double h,
                               glm::dvec3& grad, bool& kink)
{
    double d = kInf;
    glm::dvec3 g(0.0);
    kink = false;
    for (const Op& op : ops) {
        const CsgEdit& e = *op.edit;
        const double s = e.evaluatePrimitive(p);
        const glm::dvec3 gs = getPrimitiveGradient(e, p, h);
        switch (op.kind) {
        case OpKind::Add:
            d = smoothMinWithGradient(d, g, kink, s, gs, e.blend, g, kink);
            break;
        case OpKind::Subtract:
            d = -smoothMinWithGradient(-d, -g, kink, s, gs, e.blend, g, kink);
            g = -g;
            break;
        case OpKind::Intersect:
            d = -smoothMinWithGradient(-d, -g, kink, -s, -gs, e.blend, g, kink);
            g = -g;
            break;
        case OpKind::Set:
            d = s;
            g = gs;
            kink = false;
            break;
        case OpKind::SetNegated:
            d = -s;
            g = -gs;
            kink = false;
            break;
        }
    }
    grad = g;
    return d;
}

glm::dvec3 normalizeOrZero(const glm::dvec3& g, bool kink)
{
    const double len = glm::length(g);
    if (kink || !(len > 0.0) || !std::isfinite(len))
        return glm::dvec3(0.0);
    return g / len;
}

bool isSingleConvexPrimitive(const std::vector<Op>& ops)
{
    if (ops.size() != 1 || (ops[0].kind != OpKind::Add && ops[0].kind != OpKind::Set))
        return false;
    switch (ops[0].edit->shape) {
    case scene::CsgShape::Sphere:
    case scene::CsgShape::Box:
    case scene::CsgShape::RoundedBox:
    case scene::CsgShape::Cylinder:
    case scene::CsgShape::Cone:
    case scene::CsgShape::Capsule:
        return true;
    case scene::CsgShape::Torus:     // not convex
    case scene::CsgShape::Ellipsoid: // a bound, not the distance
        return false;
    }
    return false;
}

double getMaxAbs(const glm::dvec3& v)
{
    return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
}

// A step that stays well above the rounding of coordinates far from the origin.
double getGradientStep(double step, const glm::dvec3& p)
{
    return std::max(step, 1e-10 * getMaxAbs(p));
}

// Edge crossings of the samples [first, last] (each sample's +x, +y, +z edges inside the grid),
// solved on `ops`, which must be exact on the box [first, min(last + 1, samples - 1)].
void findCrossings(const std::vector<Op>& ops, const GridSpec& grid, const SampledField& field,
                   const glm::ivec3& first, const glm::ivec3& last,
                   const EvaluationOptions& options, std::vector<HermiteEdge>& out,
                   std::uint64_t& evaluations)
{
    const double tolerance = options.crossingPrecisionCells; // along t, where an edge is 1 cell
    const double step = options.gradientStepCells * grid.spacing;
    const std::uint64_t opCount = ops.size();
    for (int z = first.z; z <= last.z; ++z)
        for (int y = first.y; y <= last.y; ++y)
            for (int x = first.x; x <= last.x; ++x) {
                const glm::ivec3 s(x, y, z);
                const bool inside0 = isInside(field.values[field.index(x, y, z)]);
                for (int axis = 0; axis < 3; ++axis) {
                    glm::ivec3 n = s;
                    n[axis] += 1;
                    if (n[axis] >= grid.samples[axis])
                        continue;
                    if (isInside(field.values[field.index(n.x, n.y, n.z)]) == inside0)
                        continue;
                    const glm::dvec3 p0 = getSamplePosition(grid, x, y, z);
                    const glm::dvec3 p1 = getSamplePosition(grid, n.x, n.y, n.z);
                    const glm::dvec3 dir = p1 - p0;
                    // Illinois variant of regula falsi [Dowell and Jarratt 1971] on the bracket
                    // [ta, tb], ta on the side of sample s; a bisection step whenever two steps
                    // did not halve the bracket, and each trial point kept at least `tolerance`
                    // inside it so that the far end moves too.
                    double ta = 0.0, tb = 1.0;
                    double fa = evaluateOps(ops, p0), fb = evaluateOps(ops, p1);
                    evaluations += 2 * opCount;
                    int lastSide = 0;
                    double widthBefore = 1.0;
                    for (int iteration = 0; tb - ta > 2.0 * tolerance && iteration < 200;
                         ++iteration) {
                        double t = ta - fa * (tb - ta) / (fb - fa);
                        const bool bisect = (iteration % 2 == 1 && tb - ta > 0.5 * widthBefore);
                        if (iteration % 2 == 1)
                            widthBefore = tb - ta;
                        if (bisect || !std::isfinite(t))
                            t = 0.5 * (ta + tb);
                        t = std::clamp(t, ta + tolerance, tb - tolerance);
                        const double ft = evaluateOps(ops, p0 + dir * t);
                        evaluations += opCount;
                        if (isInside(toFieldValue(ft)) == inside0) {
                            ta = t;
                            fa = ft;
                            if (lastSide == -1)
                                fb *= 0.5;
                            lastSide = -1;
                        } else {
                            tb = t;
                            fb = ft;
                            if (lastSide == 1)
                                fa *= 0.5;
                            lastSide = 1;
                        }
                    }
                    HermiteEdge edge;
                    edge.sample = s;
                    edge.axis = axis;
                    edge.t = 0.5 * (ta + tb);
                    const glm::dvec3 at = p0 + dir * edge.t;
                    glm::dvec3 grad;
                    bool kink = false;
                    evaluateOpsWithGradient(ops, at, getGradientStep(step, at), grad, kink);
                    evaluations += 7 * opCount;
                    edge.normal = normalizeOrZero(grad, kink);
                    out.push_back(edge);
                }
            }
}

} // namespace rtlab::sdf::detail
