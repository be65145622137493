#pragma once
// Hierarchical evaluator of CSG edit lists (scene::SdfModel) onto a regular grid, after the
// "evaluator" of Media Molecule's Dreams (Alex Evans, SIGGRAPH 2015, "Learning from failure";
// shared/seeds/001_5c6096db92814698.txt, the "CS of doom" part): start from a coarse grid of
// cells, split each cell 4x4x4 at once, mark cells proven empty or full early, and carry a
// per-cell edit list pruned to the edits that can still change the field inside the cell.
//
// What it produces (EvaluationResult):
//   - field: the signed distance at every sample, exact within the narrow band |d| <= band
//     (bit-identical to SdfModel::evaluate at the same frame: the pruned list evaluates the same
//     primitives with the same operations in the same order, only without edits proven to leave
//     the value unchanged), and clamped to +band / -band with the correct sign outside it. Cells
//     proven outside the band are filled with the clamped constant without evaluating any
//     primitive at their samples.
//   - hermite: for every grid edge whose end samples lie on different sides (a sample is
//     *inside* when its value is <= 0, *outside* when > 0; a value of exactly 0 is inside), the
//     crossing t found on the exact pruned field by the Illinois variant of regula falsi to within
//     `precision` (world units) of a sign change, and the unit normal there (gradient of the pruned
//     field: chain rule through the CSG operations, central differences of each primitive with a
//     step tied to the spacing; zero where it is not finite or at an exact tie of a hard min/max).
//   - materials (optional): SdfModel::evaluateMaterial at every sample of a cell that is not
//     proven outside the band (so at least every sample with |d| <= band); 0 elsewhere.
//   - stats: primitive evaluations against brute force, culling rate, cells proven empty/full per
//     level, samples in the band, timings.
//
// Culling (per cell, a forward pass over the parent's pruned list with interval bounds):
//   - Each primitive's value over the cell is bounded by sdf/primitive_bounds.h: the 1-Lipschitz
//     bound s(centre) +- half-diagonal for exact distances, intersected with interval arithmetic
//     in the primitive's frame (box, rounded box, cylinder, capsule, torus, sphere), and interval
//     arithmetic alone for the ellipsoid (whose value is only a distance bound, not 1-Lipschitz,
//     so the half-diagonal bound would not be safe; primitive_bounds.h gives the derivation).
//     The talk evaluates max-norm distances so that a cell is a max-norm ball; with the exact L2
//     distances of scene/csg.h the cell is bounded by the ball of its half-diagonal instead.
//   - With D the interval of the field before an edit and S the primitive's, an edit is dropped
//     when it provably returns its input unchanged at every point of the cell, and the list is
//     restarted at an edit that provably replaces the field by its own value (s or -s). Both
//     tests include the edit's soft-blend radius k: the soft min reverts exactly to min/max once
//     |a - b| >= k (scene::computeSmoothMin), which is what makes culling possible at all ("soft
//     blend breaks all the culling", and later soft edits enlarge the region an edit influences).
//     Because dropped edits change no value bit, later tests that use D stay valid.
//   - A cell is proven empty (full) when the final D lies above +band (below -band).
//   - Inside a leaf whose pruned list holds exact distances only (no ellipsoid), the field is
//     1-Lipschitz (hard and soft min/max keep it so): a sample at distance r from a sample of
//     value v has |value| >= |v| - r, so where that exceeds the band its clamped value is +-band
//     with the sign of v, known without evaluating anything (not with materials, which need the
//     unclamped value). The 64 leaves of a cell are bounded first; a leaf then takes from each
//     culled sibling across one of its faces that sibling's interval, one spacing in, as a bound
//     on its face samples (both lists exact distances, so the field is 1-Lipschitz across the
//     two). Its 8 corners are evaluated (unless a sibling's interval as narrow as the sibling's
//     extent, a face parallel to the grid, already proves them) and bound every sample by their
//     balls; the rest are swept outside in (each axis away from the corners of larger |value|),
//     each also taking the bound of its neighbours one spacing back. On the gallery at 256 the
//     culling rate is 0.4-1.2 points from the ideal (was 1.2-2.5 with the +x+y+z sweep alone,
//     which saved 0.5-1.5 over none), at the same wall time.
//   - With ellipsoidGradientBound, a leaf with an ellipsoid in its list does the same with its
//     distances scaled by a bound L
//     of the field's gradient over the leaf (primitive_bounds.h: boundLipschitzConstant, 1 plus
//     a term that vanishes at the ellipsoid's surface; the largest over the list's ops), without
//     the siblings' face bounds (those cross the gap between two leaves, where no L is known).
//     A list with no bound known (a box around an ellipsoid's centre) evaluates every sample.
//   - Bounds are widened by a margin of 1e-10 x the largest coordinate or size involved, which
//     absorbs floating-point rounding with a wide safety factor.
//
// Options (EvaluationOptions): bandCells (cells, default 2: band = bandCells x spacing, world
// units), leafSamples (samples per axis of a leaf block, default 4), crossingPrecisionCells (cells,
// default 1e-6: HermiteData::precision = that x spacing, world units), gradientStepCells (cells,
// default 1e-5), computeHermite, computeMaterials, keepExactValues (the clamped doubles, for
// tests), threadCount (0 = TBB's default), ellipsoidGradientBound (default off). The output is
// identical for every thread count and every choice of these that keeps the band.
//
// Every evaluated sample skips the ops of its leaf's list whose bound over the leaf lies beyond
// the sample's running value by the blend radius (they provably return it unchanged, every bit).
//
// Assumptions: rotations are unit quaternions and sizes are >= 0 (otherwise the edit is never
// culled, which stays exact); blend radii are finite.

#include "core/sampled_field.h"
#include "scene/csg.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace rtlab::sdf {

//! Every edit applies (the default frame of SdfModel::evaluate).
inline constexpr int kAllFrames = 1 << 30;

//! A regular grid of samples: sample (x, y, z) lies at origin + spacing * (x, y, z).
struct GridSpec {
    glm::dvec3 origin{0.0};  //!< world position of sample (0, 0, 0)
    double spacing = 1.0;    //!< world distance between neighbouring samples, > 0
    glm::ivec3 samples{0};   //!< sample count per axis, >= 1 each
};

//! A grid over the model's bounds with one padding cell on each side and `samplesAlongLongest`
//! samples (>= 4) along the bounds' longest side (fewer along the others).
GridSpec makeModelGrid(const scene::SdfModel& model, int samplesAlongLongest);

struct EvaluationOptions {
    double bandCells = 2.0;               //!< exact band half-width, cells (x spacing), > 0
    int leafSamples = 4;                  //!< samples per axis of a leaf block, [1, 64]
    bool computeHermite = true;           //!< edge crossings and normals
    double crossingPrecisionCells = 1e-6; //!< crossing precision along an edge, cells, > 0
    double gradientStepCells = 1e-5;      //!< central-difference step for normals, cells, > 0
    bool computeMaterials = false;        //!< material per sample
    bool keepExactValues = false;         //!< also return the clamped values as doubles
    int threadCount = 0;                  //!< worker threads; 0 = TBB's default
    //! Leaves whose list holds an ellipsoid prove their out-of-band samples with its gradient
    //! bound (see Culling): fewer primitive evaluations, but where primitives are as cheap as
    //! these the proofs' bookkeeping costs more than it saves (tomorrow_town's landscape at 256:
    //! 13 % fewer evaluations for 8 % more time; sdf_evaluator_benchmark's rock_field: 15 % fewer
    //! for 14 % more). Off: those leaves evaluate every sample, edit-major.
    bool ellipsoidGradientBound = false;
};

struct EvaluationStats {
    std::uint64_t samples = 0;               //!< grid samples
    std::uint64_t activeEdits = 0;           //!< edits with frame <= the evaluated frame
    std::uint64_t bruteForceEvaluations = 0; //!< samples x activeEdits
    std::uint64_t sampleEvaluations = 0;     //!< primitive evaluations at samples (exact values)
    std::uint64_t boundEvaluations = 0;      //!< primitive bounds computed for culling
    std::uint64_t materialEvaluations = 0;   //!< primitive evaluations for materials
    std::uint64_t hermiteEvaluations = 0;    //!< primitive evaluations for crossings and normals
    std::uint64_t samplesEvaluated = 0;      //!< samples in leaves evaluated exactly
    std::uint64_t samplesInBand = 0;         //!< samples with |d| <= band
    std::uint64_t leavesEvaluated = 0;
    std::uint64_t hermiteEdges = 0;
    std::vector<int> cellSamples;            //!< per level (0 = coarsest): samples per axis of a cell
    std::vector<std::uint64_t> cellsVisited; //!< per level
    std::vector<std::uint64_t> cellsEmpty;   //!< per level: proven d > band everywhere
    std::vector<std::uint64_t> cellsFull;    //!< per level: proven d < -band everywhere
    double fieldSeconds = 0.0;               //!< wall time of the values (and materials)
    double hermiteSeconds = 0.0;             //!< wall time of the Hermite data
    double totalSeconds = 0.0;

    //! Primitive evaluations done for the field: sampleEvaluations + boundEvaluations.
    std::uint64_t getFieldEvaluations() const { return sampleEvaluations + boundEvaluations; }
    //! 1 - getFieldEvaluations() / bruteForceEvaluations (0 when brute force does nothing).
    double getCullingRate() const;
    //! The best culling rate any exact evaluator can reach on this grid and band: every sample in
    //! the band needs at least one primitive evaluation, so 1 - samplesInBand /
    //! bruteForceEvaluations (0 when brute force does nothing).
    double getIdealCullingRate() const;
    //! samples / fieldSeconds.
    double getSamplesPerSecond() const;
};

struct EvaluationResult {
    SampledField field;         //!< clamped to [-band, band]; see toFieldValue()
    HermiteData hermite;        //!< sorted; empty unless computeHermite
    std::vector<std::uint32_t> materials;  //!< per sample, same layout; empty unless computeMaterials
    std::vector<double> exactValues;    //!< clamped doubles, same layout; empty unless keepExactValues
    double band = 0.0;                  //!< world units
    EvaluationStats stats;
};

//! Hierarchical evaluation of `model` at `frame` (edits with edit.frame > frame are ignored).
//! Throws std::invalid_argument on an invalid grid or options.
EvaluationResult evaluateModel(const scene::SdfModel& model, const GridSpec& grid,
                               int frame = kAllFrames, const EvaluationOptions& options = {});

//! The same outputs by brute force: SdfModel::evaluate (and evaluateMaterial) at every sample, and
//! the Hermite data from the full edit list. The reference the tests and the benchmark compare to.
EvaluationResult evaluateModelBruteForce(const scene::SdfModel& model, const GridSpec& grid,
                                         int frame = kAllFrames, const EvaluationOptions& options = {});

//! value clamped to [-band, band] (NaN stays NaN).
double clampToBand(double value, double band);
//! The float stored in SampledField: the nearest float, except that a positive value too small
//! for a float becomes the smallest positive float, so that the inside/outside classification
//! (inside when <= 0) of the float is that of the double.
float toFieldValue(double value);

//! Exact field and unit gradient of a model at a frame, for IsosurfaceInput::exactValue and
//! exactGradient. The value is SdfModel::evaluate; the gradient is the chain rule through the
//! edit list with central differences of each primitive (step `gradientStep`, world units;
//! 0 = 1e-6 x the diagonal of the model's bounds), zero where it is undefined. The functions
//! keep their own copy of the model.
struct ExactFunctions {
    std::function<double(const glm::dvec3&)> value;
    std::function<glm::dvec3(const glm::dvec3&)> gradient;
};
ExactFunctions makeExactFunctions(const scene::SdfModel& model, int frame = kAllFrames,
                                  double gradientStep = 0.0);

} // namespace rtlab::sdf
