#pragma once
// EXR layout of reference results (internal to rtlab_reference; the entry points are
// writeReferenceExr / readReferenceExr in reference.h).
//
// <quantity>.exr             <quantity>_stderr.exr (same channels, standard errors, + "samples")
//   ao, ao_uniform, obscurance:  Y
//   bent:      R, G, B (bent normal), ao, aperture, aperture_uniform
//              (stderr file: bent_angle instead of R, G, B)
//   direct, indirect, full:  R, G, B (radiance), irradiance.R, irradiance.G, irradiance.B
// Header attributes "rtlab:<setting>" and "rtlab:<statistic>" hold the settings and statistics as
// text that reads back exactly; <quantity>.json beside them is the same for people.

#include "reference/reference.h"

namespace rtlab::reference {

//! Sizes the images of `quantity` in `result` (values at their no-surface defaults, zero errors).
void allocateResultImages(ReferenceResult& result, Quantity quantity, int width, int height);

//! Text of a double that strtod reads back to the same value ("inf" for infinity).
std::string formatExact(double value);

} // namespace rtlab::reference
