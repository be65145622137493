#pragma once
// Internal to the SDF evaluator (evaluator.cpp): a pruned CSG edit list and what is evaluated on
// it, the value (bit-identical to SdfModel::evaluate), the gradient, and the crossings of grid
// edges (the Hermite data).

#include "core/sampled_field.h"
#include "scene/csg.h"
#include "sdf/evaluator.h"

#include <glm/vec3.hpp>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace rtlab::sdf::detail {

// One entry of a pruned edit list. Set / SetNegated replace the field by s / -s: what an edit
// that provably overrides everything before it computes, bit for bit.
enum class OpKind : std::uint8_t { Add, Subtract, Intersect, Set, SetNegated };

struct Op {
    const scene::CsgEdit* edit = nullptr;
    OpKind kind = OpKind::Add;
    //! The primitive's value over the cell the list was pruned for (the evaluator's bound), or
    //! no bound: what lets one sample skip the op (isUnchangedBy).
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
};

//! The edits of `model` that apply at `frame`, in order.
std::vector<Op> getActiveOps(const scene::SdfModel& model, int frame);

// The same arithmetic as SdfModel::evaluate, so that the results are bit-identical.
inline double applyOp(OpKind kind, double d, double s, double blend)
{
    switch (kind) {
    case OpKind::Add:
        return scene::computeSmoothMin(d, s, blend);
    case OpKind::Subtract:
        return -scene::computeSmoothMin(-d, s, blend);
    case OpKind::Intersect:
        return -scene::computeSmoothMin(-d, -s, blend);
    case OpKind::Set:
        return s;
    case OpKind::SetNegated:
        return -s;
    }
    return d;
}

//! Whether applyOp(op.kind, d, s, blend) returns d itself for every s in [op.lo, op.hi]: the
//! soft min is the hard one once |a - b| >= k (scene::computeSmoothMin), and min(d, s) = d for
//! s >= d. `margin` (>= 0) covers the rounding of the bound. A sample whose running value is d
//! then needs no evaluation of the op, and its value keeps every bit.
inline bool isUnchangedBy(const Op& op, double d, double margin)
{
    const double need = std::max(op.edit->blend, 0.0) + margin;
    switch (op.kind) {
    case OpKind::Add:
        return op.lo - d >= need; // min(d, s)
    case OpKind::Subtract:
        return op.lo + d >= need; // max(d, -s)
    case OpKind::Intersect:
        return d - op.hi >= need; // max(d, s)
    case OpKind::Set:
    case OpKind::SetNegated:
        return false;
    }
    return false;
}

//! The pruned field at p.
double evaluateOps(const std::vector<Op>& ops, const glm::dvec3& p);

//! True when the list is one primitive, added (to nothing) or set, of a convex shape with an
//! exact distance (sphere, box, rounded box, cylinder, cone, capsule; rigid frames only): its
//! field is the signed distance to a convex solid, which is a convex function.
bool isSingleConvexPrimitive(const std::vector<Op>& ops);

//! Value (bit-identical to evaluateOps) and gradient (central differences of each primitive with
//! step h, chained through the CSG operations); `kink` is set where the gradient is undefined.
double evaluateOpsWithGradient(const std::vector<Op>& ops, const glm::dvec3& p, double h,
                               glm::dvec3& gradient, bool& kink);

//! g normalised, or zero at a kink or where it has no finite length.
glm::dvec3 normalizeOrZero(const glm::dvec3& g, bool kink);

double getMaxAbs(const glm::dvec3& v);

//! A step that stays well above the rounding of coordinates far from the origin.
double getGradientStep(double step, const glm::dvec3& p);

//! A sample is inside when its value is <= 0.
inline bool isInside(float v)
{
    return v <= 0.0f;
}

inline glm::dvec3 getSamplePosition(const GridSpec& g, int x, int y, int z)
{
    // Written as SampledField::position, so that positions are bit-identical.
    return g.origin + g.spacing * glm::dvec3(x, y, z);
}

// Edge crossings of the samples [first, last] (each sample's +x, +y, +z edges inside the grid),
// solved on `ops`, which must be exact on the box [first, min(last + 1, samples - 1)].
void findCrossings(const std::vector<Op>& ops, const GridSpec& grid, const SampledField& field,
                   const glm::ivec3& first, const glm::ivec3& last,
                   const EvaluationOptions& options, std::vector<HermiteEdge>& out,
                   std::uint64_t& evaluations);

} // namespace rtlab::sdf::detail
