#pragma once
// Internal to the evaluator (evaluator.cpp): the samples of one leaf that its 1-Lipschitz field
// keeps out of the band, proven without evaluating them.

#include "sdf/edit_ops.h"

#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace rtlab::sdf::detail {

inline constexpr double kNoBound = -std::numeric_limits<double>::infinity();

//! What a leaf knows from its culled siblings: per face (2 axis + side, side 1 = the high one),
//! a lower bound of |value| over the sibling across it and the sign there (-inf: no sibling
//! culled there). The field is 1-Lipschitz across the two cells when both pruned lists hold
//! exact distances only, so the leaf's samples on that face have |value| >= bound - spacing.
struct FaceSeeds {
    std::array<double, 6> bound{kNoBound, kNoBound, kNoBound, kNoBound, kNoBound, kNoBound};
    std::array<double, 6> sign{1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
    //! The sibling's interval is as narrow as its extent along the axis allows (a face parallel
    //! to the cell: the bound is then the value itself), so a corner it proves needs no
    //! evaluation of its own; a looser bound (a tilted face) leaves the corner to be evaluated,
    //! whose exact value proves more of the leaf than the bound would.
    std::array<bool, 6> tight{};
};

//! The band and the distances a leaf's bounds subtract.
struct LeafBand {
    double band = 0.0; //!< half-width of the exact band, world units
    double step = 0.0; //!< the grid spacing, rounded up by the evaluator's margin
    //! By squared offset between two samples of a leaf (in samples): their distance, rounded up.
    const std::vector<double>& reach;
    //! The evaluator's rounding margin (world units), kept between a bound and the band.
    double margin = 0.0;
    //! A bound of the field's gradient over the leaf (boundLipschitzConstant of its ops, the
    //! largest: soft and hard min and max keep the largest of their inputs'); the distances
    //! above are multiplied by it. 1 where the list holds exact distances only.
    double lipschitz = 1.0;
};

//! The leaf's values where its pruned list has a known gradient bound L (limits.lipschitz: 1 for
//! exact distances); returns the samples evaluated. Samples the band cannot reach are not
//! evaluated: every op (hard or soft min and max, negation) keeps a field of exact distances
//! 1-Lipschitz (L-Lipschitz with the ellipsoid's bound), so a sample at distance r from
//! a sample of value v has |value| >= |v| - L r and, while that exceeds the band, the sign of v:
//! its clamped value (+-band) is known without evaluating it. Seeds are the leaf's 8 corners,
//! evaluated first: each bounds every sample of the leaf by its ball (a corner far outside
//! the band clears most of the leaf), unless a tight sibling's bound (`seeds`, may be null)
//! already proves the corner; the siblings' bounds also seed the face samples. The other samples
//! are then visited in scan order, each
//! axis swept away from the corners of larger |value| (outside in), and take the best of the
//! corners' balls and of their three neighbours one spacing back along the sweep (chained
//! through skipped samples). Where the pruned list is one convex primitive
//! (isSingleConvexPrimitive) the field is convex: it lies below the trilinear interpolation of
//! the corner values (proving samples inside) and above the line through two exact samples
//! behind a sample along the sweep (proving samples outside). Evaluated samples run the same ops in
//! the same order as the edit-major loop, so every value stays bit-identical.
//!
//! `n` is the leaf's sample count per axis; positions and values are in x-fastest order, values
//! filled with the exact value of the evaluated samples and +-(a bound above the band) for the
//! others; bound and known are scratch arrays (resized here). An evaluated sample skips the ops
//! that provably leave its running value unchanged (isUnchangedBy); primitiveEvaluations is
//! increased by the primitives evaluated.
std::size_t evaluateLipschitzLeaf(const glm::ivec3& n, const std::vector<Op>& ops,
                                  const std::vector<glm::dvec3>& positions, const LeafBand& limits,
                                  const FaceSeeds* seeds, std::vector<double>& values,
                                  std::vector<double>& bound, std::vector<std::uint8_t>& known,
                                  std::uint64_t& primitiveEvaluations);

} // namespace rtlab::sdf::detail
