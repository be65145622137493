#pragma once
// The outputs of the bent quantity from one pixel's estimate (internal to rtlab_reference), shared
// by the Embree reference and the screen-space reference.

#include "reference/progressive.h"
#include "reference/reference.h"

#include <glm/vec3.hpp>

#include <cstddef>

namespace rtlab::reference {

//! Writes pixel `i` of the bent outputs of reference.h (bent normal, occlusion, aperture, uniform
//! aperture, each with its standard error) from the mean of the bent channels (V w, V, V_u).
//! Standard errors follow by the delta method on the mean vector; where nothing is visible the
//! bent normal falls back to `normal`.
void storeBentEstimate(ReferenceResult& r, std::size_t i, const PixelEstimate& e,
                       const glm::dvec3& normal);

} // namespace rtlab::reference
