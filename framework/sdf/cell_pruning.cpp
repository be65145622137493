#include "sdf/cell_pruning.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::sdf::detail {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Interval widen(Interval d, double margin)
{
    d.lo -= margin;
    d.hi += margin;
    if (!(d.lo <= d.hi)) // NaN
        return {-kInf, kInf};
    return d;
}

} // namespace

// computeSmoothMin is non-decreasing in both arguments (its partial derivatives lie in [0, 1]),
// so the ends of the inputs' intervals give the ends of the result's.
Interval combineIntervals(OpKind kind, Interval d, Interval s, double k, double margin)
{
    using scene::computeSmoothMin;
    switch (kind) {
    case OpKind::Add:
        return widen({computeSmoothMin(d.lo, s.lo, k), computeSmoothMin(d.hi, s.hi, k)}, margin);
    case OpKind::Subtract:
        return widen({-computeSmoothMin(-d.lo, s.hi, k), -computeSmoothMin(-d.hi, s.lo, k)},
                     margin);
    case OpKind::Intersect:
        return widen({-computeSmoothMin(-d.lo, -s.lo, k), -computeSmoothMin(-d.hi, -s.hi, k)},
                     margin);
    case OpKind::Set:
        return s;
    case OpKind::SetNegated:
        return {-s.hi, -s.lo};
    }
    return {-kInf, kInf};
}

Interval pruneOps(const std::vector<Op>& parentOps, const glm::dvec3& lo, const glm::dvec3& hi,
                  double margin, std::vector<Op>& ops, std::uint64_t& boundEvaluations)
{
    ops.clear();
    Interval d{kInf, kInf}; // the empty list is +inf
    for (const Op& parent : parentOps) {
        const Interval s = boundPrimitive(*parent.edit, lo, hi, margin);
        ++boundEvaluations;
        const Op op{parent.edit, parent.kind, s.lo, s.hi};
        // [Evans 2015] soft blend breaks the culling unless the soft min reverts to the hard
        // one: the edit of blend radius k returns its input d unchanged once its primitive is at
        // least k beyond d on the losing side (isUnchangedBy, at the input's worst end), and
        // returns its own value once the input is at least k beyond it.
        const double k = std::max(op.edit->blend, 0.0);
        const double need = k + margin;
        bool unchanged = false, replaced = false;
        OpKind replacement = OpKind::Set;
        switch (op.kind) {
        case OpKind::Add: // min(d, s)
            unchanged = isUnchangedBy(op, d.hi, margin);
            replaced = d.lo - s.hi >= need;
            break;
        case OpKind::Subtract: // max(d, -s)
            unchanged = isUnchangedBy(op, d.lo, margin);
            replaced = -d.hi - s.hi >= need;
            replacement = OpKind::SetNegated;
            break;
        case OpKind::Intersect: // max(d, s)
            unchanged = isUnchangedBy(op, d.lo, margin);
            replaced = s.lo - d.hi >= need;
            break;
        case OpKind::Set:
            replaced = true;
            break;
        case OpKind::SetNegated:
            replaced = true;
            replacement = OpKind::SetNegated;
            break;
        }
        if (unchanged)
            continue;
        if (replaced) {
            ops.clear();
            ops.push_back({op.edit, replacement, s.lo, s.hi});
            d = combineIntervals(replacement, d, s, k, margin);
            continue;
        }
        ops.push_back(op);
        d = combineIntervals(op.kind, d, s, k, margin);
    }
    return d;
}

void pruneCandidates(const std::vector<const scene::CsgEdit*>& parent, const glm::dvec3& lo,
                     const glm::dvec3& hi, Interval d, double margin,
                     std::vector<const scene::CsgEdit*>& out, std::uint64_t& boundEvaluations)
{
    out.clear();
    const double maxAbs = std::max(std::abs(d.lo), std::abs(d.hi));
    for (const scene::CsgEdit* e : parent) {
        const Interval s = boundPrimitive(*e, lo, hi, margin);
        ++boundEvaluations;
        const double tol = std::max(e->blend, 1e-9 * (1.0 + maxAbs));
        if (s.lo - d.hi > tol + margin)
            continue; // never chosen in the box
        if (s.hi + margin < d.lo)
            out.clear(); // always chosen in the box: the edits before it never win
        out.push_back(e);
    }
}

} // namespace rtlab::sdf::detail
