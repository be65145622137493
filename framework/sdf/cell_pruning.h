#pragma once
// Internal to the evaluator (evaluator.cpp): an edit list pruned to an axis-aligned cell by the
// interval bounds of its primitives [Evans 2015], and the interval of the field over the cell.

#include "sdf/edit_ops.h"
#include "sdf/primitive_bounds.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

namespace rtlab::sdf::detail {

//! The interval of an op's result from the intervals of its input `d` and its primitive `s`,
//! blend radius k, widened by `margin` (NaN: no bound).
Interval combineIntervals(OpKind kind, Interval d, Interval s, double k, double margin);

//! `parentOps` pruned to the box [lo, hi] into `ops`, each kept op carrying its primitive's bound
//! over the box (Op::lo, Op::hi): an op is dropped where it provably returns its input unchanged
//! everywhere in the box (isUnchangedBy), and the list restarts at an op that provably replaces
//! the field by its own value (Set / SetNegated). Returns the interval of the field over the box;
//! adds one to `boundEvaluations` per primitive bounded.
Interval pruneOps(const std::vector<Op>& parentOps, const glm::dvec3& lo, const glm::dvec3& hi,
                  double margin, std::vector<Op>& ops, std::uint64_t& boundEvaluations);

//! Material candidates: the additive edits of `parent` that can still be the material of a sample
//! in the box, where the field lies in `d` (SdfModel::evaluateMaterial takes the last additive
//! edit with s <= d + max(blend, tol)).
void pruneCandidates(const std::vector<const scene::CsgEdit*>& parent, const glm::dvec3& lo,
                     const glm::dvec3& hi, Interval d, double margin,
                     std::vector<const scene::CsgEdit*>& out, std::uint64_t& boundEvaluations);

} // namespace rtlab::sdf::detail
