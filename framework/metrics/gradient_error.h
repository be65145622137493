#pragma once
// Discontinuity error: how far an image's differences between neighbouring pixels are from the
// reference's, on pairs of pixels that lie on one smooth surface. A per-pixel error (RMSE) barely
// moves when an estimate jumps along a line (a level transition of a voxel structure, a seam
// between two interpolation domains) because the jump covers few pixels; the differences across
// that line carry all of it. The reference's own noise makes its differences noisy too, so its
// expected contribution (from the reference's standard errors) is reported beside the error and
// taken out of it.

#include "core/image.h"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>

namespace rtlab::metrics {

//! Per pixel, which of its two forward 4-neighbour pairs lie on one smooth surface: bit 0 for
//! (x, y)-(x + 1, y), bit 1 for (x, y)-(x, y + 1). A pair is smooth when both pixels have a
//! surface (finite depth > 0), their depths differ by at most `relativeJump` of the smaller one,
//! and their unit normals make an angle whose cosine is at least `minCosine`. Normals may be in any
//! space (they are only compared). relativeJump > 0, minCosine in [-1, 1]
//! (std::invalid_argument); depth and normal images of one size.
Image<std::uint8_t> makeSmoothPairMask(const Image<float>& depth, const Image<glm::vec3>& normal,
                                       double relativeJump = 0.05, double minCosine = 0.9);

struct GradientError {
    //! sqrt of the mean over smooth pairs (p, q) and channels of ((t_p - t_q) - (r_p - r_q))^2.
    double rmse = 0.0;
    //! The part of rmse^2 that the reference's noise alone gives, as an RMS: sqrt of the mean of
    //! s_p^2 + s_q^2 (s: the reference's standard errors; pixels are independent estimates). 0
    //! without standard errors.
    double noiseFloor = 0.0;
    //! sqrt(max(0, rmse^2 - noiseFloor^2)): the discontinuity error of the estimate itself.
    //! Conservative: standard errors computed as if the samples were independent overstate the
    //! error of a quasi-Monte Carlo reference, so the floor can exceed rmse^2 and this read 0
    //! (measured on tomorrow_town: rmse 0.028, floor 0.035). Comparing across and within level
    //! transitions (splitPairsByLabel) needs no floor: the reference's noise is in both alike.
    double excess = 0.0;
    std::size_t pairs = 0; //!< smooth pairs with finite values in both images
};

//! The smooth pairs split by a per-pixel label (e.g. the level of a hierarchy a lookup used):
//! `across` holds the pairs whose two labels differ, `within` those whose labels agree; pairs with
//! a pixel labelled `none` are in neither. Images of one size (std::invalid_argument).
struct LabelledPairs {
    Image<std::uint8_t> across;
    Image<std::uint8_t> within;
};
LabelledPairs splitPairsByLabel(const Image<std::uint8_t>& smoothPairs,
                                const Image<std::uint8_t>& labels, std::uint8_t none);

//! The discontinuity error of `test` against `reference` over the pairs of `smoothPairs` (see
//! makeSmoothPairMask); `referenceStdErr` may be null. Pairs with a non-finite value are skipped.
//! Images of one size (std::invalid_argument). No pairs: all zero.
GradientError computeGradientError(const Image<glm::vec3>& test,
                                   const Image<glm::vec3>& reference,
                                   const Image<glm::vec3>* referenceStdErr,
                                   const Image<std::uint8_t>& smoothPairs);

} // namespace rtlab::metrics
