#pragma once
// Conservative bounds on one CSG primitive's value over an axis-aligned box: what the hierarchical
// evaluator (sdf/evaluator.h) culls with.
//
// Every shape except the ellipsoid evaluates an exact Euclidean distance, which is 1-Lipschitz:
// over a box of centre c and half-diagonal r the value lies in [s(c) - r, s(c) + r]. For the box,
// rounded box, cylinder, capsule, torus and sphere this is intersected with interval arithmetic in
// the primitive's frame: their value is non-decreasing in each |q_i| (or in the radial distance
// and |y|; for the torus in |radial - major| and |y|), so the ends of the box's local extent
// bound it. The cone has the Lipschitz bound only. The ellipsoid
// evaluates the first-order bound k0 (k0 - 1) / k1 [Quilez 2008] (k0 = |q / size|,
// k1 = |q / size^2|, q in the ellipsoid's frame), which is not 1-Lipschitz; it is bounded by
// interval arithmetic instead: writing it as rho (k0 - 1) with rho = k0 / k1, rho always lies in
// [min(size), max(size)] (and in [k0_min / k1_max, k0_max / k1_min] over the box), and k0, k1 are
// bounded from the box's extent in the ellipsoid's frame.

#include "scene/csg.h"

#include <glm/vec3.hpp>

namespace rtlab::sdf {

//! A closed interval of field values, world units. [-inf, +inf] means "no bound known".
struct Interval {
    double lo = 0.0;
    double hi = 0.0;
};

//! An interval that contains edit.evaluatePrimitive(p), as computed in floating point, for every
//! p in the box [boxLo, boxHi], widened on each side by `margin` (world units, >= 0, to absorb
//! rounding). Returns [-inf, +inf] where no bound is known: a rotation that is not a unit
//! quaternion, a negative or non-finite size or rounding, a zero-size ellipsoid (whose value is
//! NaN), or a non-finite value at the centre.
Interval boundPrimitive(const scene::CsgEdit& edit, const glm::dvec3& boxLo, const glm::dvec3& boxHi,
                        double margin);

//! Whether edit.evaluatePrimitive is an exact Euclidean distance, hence 1-Lipschitz: every shape
//! but the ellipsoid, with a unit rotation and finite, non-negative size and rounding (where
//! boundPrimitive uses the Lipschitz bound).
bool isLipschitzPrimitive(const scene::CsgEdit& edit);

//! An upper bound L of |grad edit.evaluatePrimitive| over the box [boxLo, boxHi], so that two
//! points p, q of the box have values within L |p - q|: 1 for the exact distances
//! (isLipschitzPrimitive). For the ellipsoid's k0 (k0 - 1) / k1 (see the top of this file),
//! 1 + max|1 - 1/k0| (R^2 - 1) over the box, R = max(size) / min(size): near its surface
//! (k0 ~ 1) the bound is barely above 1, and it grows without limit towards the centre, where
//! +inf is returned (as for anything else with no bound known).
double boundLipschitzConstant(const scene::CsgEdit& edit, const glm::dvec3& boxLo,
                              const glm::dvec3& boxHi);

} // namespace rtlab::sdf
