#include "sdf/evaluator.h"

#include "sdf/cell_pruning.h"
#include "sdf/edit_ops.h"
#include "sdf/leaf_bounds.h"
#include "sdf/primitive_bounds.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

namespace rtlab::sdf {

using scene::CsgEdit;
using scene::CsgOp;
using scene::SdfModel;
using namespace detail;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void validate(const GridSpec& grid, const EvaluationOptions& options)
{
    if (!(grid.spacing > 0.0) || !std::isfinite(grid.spacing))
        throw std::invalid_argument("sdf evaluator: grid spacing must be finite and > 0");
    if (grid.samples.x < 1 || grid.samples.y < 1 || grid.samples.z < 1)
        throw std::invalid_argument("sdf evaluator: grid needs at least one sample per axis");
    if (!std::isfinite(grid.origin.x + grid.origin.y + grid.origin.z))
        throw std::invalid_argument("sdf evaluator: grid origin must be finite");
    if (!(options.bandCells > 0.0) || !std::isfinite(options.bandCells))
        throw std::invalid_argument("sdf evaluator: bandCells must be finite and > 0");
    if (options.leafSamples < 1 || options.leafSamples > 64)
        throw std::invalid_argument("sdf evaluator: leafSamples must be in [1, 64]");
    if (!(options.crossingPrecisionCells > 0.0))
        throw std::invalid_argument("sdf evaluator: crossingPrecisionCells must be > 0");
    if (!(options.gradientStepCells > 0.0))
        throw std::invalid_argument("sdf evaluator: gradientStepCells must be > 0");
}

// The largest coordinate or size involved; bounds are widened by a tiny multiple of it.
double getScale(const SdfModel& model, const GridSpec& grid, int frame)
{
    const glm::dvec3 far = grid.origin + grid.spacing * glm::dvec3(grid.samples - 1);
    double scale = std::max(getMaxAbs(grid.origin), getMaxAbs(far));
    for (const auto& e : model.edits) {
        if (e.frame > frame)
            continue;
        const double extent = getMaxAbs(e.center) + getMaxAbs(e.size) + std::abs(e.rounding) +
                              std::abs(e.blend);
        if (std::isfinite(extent))
            scale = std::max(scale, extent);
    }
    return scale;
}

struct Counters {
    std::uint64_t sampleEvaluations = 0, boundEvaluations = 0, materialEvaluations = 0;
    std::uint64_t hermiteEvaluations = 0, samplesEvaluated = 0, samplesInBand = 0;
    std::uint64_t leavesEvaluated = 0;
    std::vector<std::uint64_t> cellsVisited, cellsEmpty, cellsFull;
};

struct Outputs {
    SampledField* field = nullptr;
    std::vector<std::uint32_t>* materials = nullptr;  // null unless computed
    std::vector<double>* exactValues = nullptr;       // null unless kept
};

struct LeafRecord {
    glm::ivec3 first{0}, last{0};
    std::vector<Op> ops;
};

class Hierarchy {
public:
    Hierarchy(const SdfModel& model, const GridSpec& grid, int frame, const EvaluationOptions& options,
              Outputs outputs)
        : model(model), grid(grid), frame(frame), options(options), outputs(outputs)
    {
        band = options.bandCells * grid.spacing;
        margin = 1e-10 * getScale(model, grid, frame) + std::numeric_limits<double>::denorm_min();
        const int maxSamples = std::max({grid.samples.x, grid.samples.y, grid.samples.z});
        std::int64_t size = options.leafSamples;
        int levels = 1;
        while (size * 4 < maxSamples) {
            size *= 4;
            ++levels;
        }
        for (int level = 0; level < levels; ++level) {
            cellSamples.push_back(int(size));
            size /= 4;
        }
        // Distances between two samples of a leaf by their squared offset in samples, rounded up
        // through the margin (the leaves' Lipschitz bounds subtract them).
        const int span = cellSamples.back() - 1;
        reach.resize(std::size_t(3 * span * span) + 1);
        for (std::size_t k = 0; k < reach.size(); ++k)
            reach[k] = (grid.spacing + margin) * std::sqrt(double(k));
    }

    void run(std::vector<Op> rootOps, std::vector<const CsgEdit*> rootCandidates)
    {
        const int rootSize = cellSamples[0];
        const glm::ivec3 roots = (grid.samples + rootSize - 1) / rootSize;
        tbb::parallel_for(0, roots.x * roots.y * roots.z, [&](int i) {
            const glm::ivec3 r(i % roots.x, (i / roots.x) % roots.y, i / (roots.x * roots.y));
            processCell(0, r * rootSize, rootOps, rootCandidates);
        });
    }

    const SdfModel& model;
    const GridSpec& grid;
    int frame;
    const EvaluationOptions& options;
    Outputs outputs;
    double band = 0.0;
    double margin = 0.0;
    std::vector<int> cellSamples;  // per level
    std::vector<double> reach;     // by squared sample offset inside a leaf: its world distance
    tbb::enumerable_thread_specific<Counters> counters;
    tbb::enumerable_thread_specific<std::vector<LeafRecord>> leaves;
    //! Per thread, the arrays a leaf works in (kept between leaves: no allocation per leaf).
    struct LeafScratch {
        std::vector<glm::dvec3> positions;
        std::vector<double> values;
        std::vector<double> bound;
        std::vector<std::uint8_t> known;
    };
    tbb::enumerable_thread_specific<LeafScratch> scratch;

private:
    Counters& getCounters()
    {
        Counters& c = counters.local();
        if (c.cellsVisited.empty()) {
            c.cellsVisited.assign(cellSamples.size(), 0);
            c.cellsEmpty.assign(cellSamples.size(), 0);
            c.cellsFull.assign(cellSamples.size(), 0);
        }
        return c;
    }

    void fill(const glm::ivec3& first, const glm::ivec3& last, double value)
    {
        const float v = toFieldValue(value);
        SampledField& f = *outputs.field;
        for (int z = first.z; z <= last.z; ++z)
            for (int y = first.y; y <= last.y; ++y) {
                const std::size_t row = f.index(0, y, z);
                std::fill(f.values.begin() + row + first.x, f.values.begin() + row + last.x + 1, v);
                if (outputs.materials)
                    std::fill(outputs.materials->begin() + row + first.x,
                              outputs.materials->begin() + row + last.x + 1, 0u);
                if (outputs.exactValues)
                    std::fill(outputs.exactValues->begin() + row + first.x,
                              outputs.exactValues->begin() + row + last.x + 1, value);
            }
    }

    //! The largest of the ops' gradient bounds over the box [lo, hi] (+inf for an
    //! empty list, one with no bound known, or an ellipsoid without
    //! options.ellipsoidGradientBound): what the leaf's proofs scale distances by.
    double getLipschitzConstant(const std::vector<Op>& ops, const glm::dvec3& lo,
                                const glm::dvec3& hi, Counters& c) const
    {
        if (ops.empty())
            return kInf;
        double l = 1.0;
        for (const Op& op : ops) {
            if (isLipschitzPrimitive(*op.edit))
                continue; // 1, nothing computed
            if (!options.ellipsoidGradientBound)
                return kInf;
            ++c.boundEvaluations;
            l = std::max(l, boundLipschitzConstant(*op.edit, lo, hi));
        }
        return l;
    }

    void evaluateLeaf(const glm::ivec3& first, const glm::ivec3& last, const std::vector<Op>& ops,
                      const std::vector<const CsgEdit*>& candidates, Counters& c,
                      const FaceSeeds* seeds = nullptr)
    {
        const glm::ivec3 n = last - first + 1;
        const std::size_t count = std::size_t(n.x) * n.y * n.z;
        LeafScratch& work = scratch.local();
        std::vector<glm::dvec3>& positions = work.positions;
        positions.resize(count);
        std::vector<double>& values = work.values;
        values.assign(count, kInf);
        std::size_t i = 0;
        for (int z = first.z; z <= last.z; ++z)
            for (int y = first.y; y <= last.y; ++y)
                for (int x = first.x; x <= last.x; ++x)
                    positions[i++] = getSamplePosition(grid, x, y, z);
        std::size_t evaluated = count;
        std::uint64_t primitiveEvaluations = 0;
        const double lipschitz =
            outputs.materials ? kInf
                              : getLipschitzConstant(ops, positions.front(), positions.back(), c);
        if (!(lipschitz < kInf)) {
            // Edit-major: one primitive over the whole block, the coherent branch on primitive
            // type that the talk's 4x4x4 blocks are for.
            for (const Op& op : ops) {
                const CsgEdit& e = *op.edit;
                for (std::size_t j = 0; j < count; ++j) {
                    if (isUnchangedBy(op, values[j], margin))
                        continue; // this sample's value is already final for this op
                    values[j] =
                        applyOp(op.kind, values[j], e.evaluatePrimitive(positions[j]), e.blend);
                    ++primitiveEvaluations;
                }
            }
        } else {
            evaluated = evaluateLipschitzLeaf(
                n, ops, positions, {band, grid.spacing + margin, reach, margin, lipschitz}, seeds,
                values, work.bound, work.known, primitiveEvaluations);
        }
        c.sampleEvaluations += primitiveEvaluations;
        c.samplesEvaluated += evaluated;
        ++c.leavesEvaluated;
        SampledField& f = *outputs.field;
        i = 0;
        for (int z = first.z; z <= last.z; ++z)
            for (int y = first.y; y <= last.y; ++y)
                for (int x = first.x; x <= last.x; ++x, ++i) {
                    const double v = clampToBand(values[i], band);
                    if (std::abs(values[i]) <= band)
                        ++c.samplesInBand;
                    const std::size_t index = f.index(x, y, z);
                    f.values[index] = toFieldValue(v);
                    if (outputs.exactValues)
                        (*outputs.exactValues)[index] = v;
                    if (outputs.materials) {
                        // SdfModel::evaluateMaterial on the candidates, with the exact value.
                        const double d = values[i];
                        std::uint32_t material = 0;
                        for (const CsgEdit* e : candidates) {
                            const double s = e->evaluatePrimitive(positions[i]);
                            if (std::abs(s - d) <= std::max(e->blend, 1e-9 * (1.0 + std::abs(d))) ||
                                s <= d)
                                material = e->material;
                        }
                        c.materialEvaluations += candidates.size();
                        (*outputs.materials)[index] = material;
                    }
                }
    }

    void processCell(int level, const glm::ivec3& first, const std::vector<Op>& parentOps,
                     const std::vector<const CsgEdit*>& parentCandidates)
    {
        Counters& c = getCounters();
        ++c.cellsVisited[level];
        const int size = cellSamples[level];
        const glm::ivec3 last = glm::min(first + size - 1, grid.samples - 1);
        // With Hermite data the list must also be exact on the edges leaving the cell: the box
        // reaches one sample further on the upper sides.
        const glm::ivec3 boxLast =
            options.computeHermite ? glm::min(first + size, grid.samples - 1) : last;
        const glm::dvec3 lo = getSamplePosition(grid, first.x, first.y, first.z);
        const glm::dvec3 hi = getSamplePosition(grid, boxLast.x, boxLast.y, boxLast.z);
        std::vector<Op> ops;
        const Interval d = pruneOps(parentOps, lo, hi, margin, ops, c.boundEvaluations);
        // [Evans 2015] "empty cells and full cells are marked early in the tree".
        if (d.lo > band) {
            ++c.cellsEmpty[level];
            fill(first, last, band);
            return;
        }
        if (d.hi < -band) {
            ++c.cellsFull[level];
            fill(first, last, -band);
            return;
        }
        std::vector<const CsgEdit*> candidates;
        if (outputs.materials)
            pruneCandidates(parentCandidates, lo, hi, d, margin, candidates, c.boundEvaluations);
        if (level + 1 == int(cellSamples.size())) {
            evaluateLeaf(first, last, ops, candidates, c);
            // Only a box whose values can be on both sides of 0 can hold a crossing.
            if (options.computeHermite && d.lo <= 0.0 && d.hi > 0.0)
                leaves.local().push_back({first, last, std::move(ops)});
            return;
        }
        // [Evans 2015] "we actually split by 4x4x4 in one go".
        const int childSize = cellSamples[level + 1];
        if (level + 2 == int(cellSamples.size())) {
            processLeaves(level + 1, first, ops, candidates);
            return;
        }
        tbb::parallel_for(0, 64, [&](int i) {
            const glm::ivec3 child = first + childSize * glm::ivec3(i % 4, (i / 4) % 4, i / 16);
            if (child.x < grid.samples.x && child.y < grid.samples.y && child.z < grid.samples.z)
                processCell(level + 1, child, ops, candidates);
        });
    }

    //! The 64 leaves of one cell: all bounded first, then the ones not culled evaluated, each
    //! seeded by its culled siblings (see FaceSeeds).
    void processLeaves(int level, const glm::ivec3& parentFirst, const std::vector<Op>& parentOps,
                       const std::vector<const CsgEdit*>& parentCandidates)
    {
        struct Child {
            glm::ivec3 first{0}, last{0};
            glm::dvec3 lo{0.0}, hi{0.0};
            Interval d{0.0, 0.0};
            std::vector<Op> ops;
            int state = -1; // -1 outside the grid, 0 evaluated, 1 empty, 2 full
            bool exact = false; // the list holds exact distances only (1-Lipschitz)
        };
        std::array<Child, 64> children;
        const int size = cellSamples[level];
        tbb::parallel_for(0, 64, [&](int i) {
            Child& ch = children[std::size_t(i)];
            ch.first = parentFirst + size * glm::ivec3(i % 4, (i / 4) % 4, i / 16);
            if (ch.first.x >= grid.samples.x || ch.first.y >= grid.samples.y ||
                ch.first.z >= grid.samples.z)
                return;
            Counters& c = getCounters();
            ++c.cellsVisited[level];
            ch.last = glm::min(ch.first + size - 1, grid.samples - 1);
            const glm::ivec3 boxLast =
                options.computeHermite ? glm::min(ch.first + size, grid.samples - 1) : ch.last;
            ch.lo = getSamplePosition(grid, ch.first.x, ch.first.y, ch.first.z);
            ch.hi = getSamplePosition(grid, boxLast.x, boxLast.y, boxLast.z);
            ch.d = pruneOps(parentOps, ch.lo, ch.hi, margin, ch.ops, c.boundEvaluations);
            ch.exact = !outputs.materials && !ch.ops.empty() &&
                       std::all_of(ch.ops.begin(), ch.ops.end(),
                                   [](const Op& op) { return isLipschitzPrimitive(*op.edit); });
            if (ch.d.lo > band) {
                ++c.cellsEmpty[level];
                fill(ch.first, ch.last, band);
                ch.state = 1;
            } else if (ch.d.hi < -band) {
                ++c.cellsFull[level];
                fill(ch.first, ch.last, -band);
                ch.state = 2;
            } else {
                ch.state = 0;
            }
        });
        tbb::parallel_for(0, 64, [&](int i) {
            Child& ch = children[std::size_t(i)];
            if (ch.state != 0)
                return;
            Counters& c = getCounters();
            std::vector<const CsgEdit*> candidates;
            if (outputs.materials)
                pruneCandidates(parentCandidates, ch.lo, ch.hi, ch.d, margin, candidates,
                                c.boundEvaluations);
            FaceSeeds seeds;
            // Seeds cross the gap between two siblings' samples, outside both boxes: only where
            // the field is 1-Lipschitz everywhere, both lists of exact distances.
            if (ch.exact) {
                const glm::ivec3 at(i % 4, (i / 4) % 4, i / 16);
                const int stride[3] = {1, 4, 16};
                for (int axis = 0; axis < 3; ++axis)
                    for (int side = 0; side < 2; ++side) {
                        if (at[axis] + (side ? 1 : -1) < 0 || at[axis] + (side ? 1 : -1) > 3)
                            continue; // a cousin, in another cell: not known here
                        const Child& n = children[std::size_t(i + (side ? 1 : -1) * stride[axis])];
                        if (!n.exact || (n.state != 1 && n.state != 2))
                            continue;
                        seeds.bound[std::size_t(2 * axis + side)] = n.state == 1 ? n.d.lo : -n.d.hi;
                        seeds.sign[std::size_t(2 * axis + side)] = n.state == 1 ? 1.0 : -1.0;
                        seeds.tight[std::size_t(2 * axis + side)] =
                            n.d.hi - n.d.lo <= 1.01 * (n.hi[axis] - n.lo[axis]) + margin;
                    }
            }
            evaluateLeaf(ch.first, ch.last, ch.ops, candidates, c, &seeds);
            // Only a box whose values can be on both sides of 0 can hold a crossing.
            if (options.computeHermite && ch.d.lo <= 0.0 && ch.d.hi > 0.0)
                leaves.local().push_back({ch.first, ch.last, std::move(ch.ops)});
        });
    }
};

double getSeconds(std::chrono::steady_clock::time_point since)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

EvaluationResult makeResult(const SdfModel& model, const GridSpec& grid, int frame,
                            const EvaluationOptions& options)
{
    validate(grid, options);
    EvaluationResult r;
    r.band = options.bandCells * grid.spacing;
    r.field.samples = grid.samples;
    r.field.origin = grid.origin;
    r.field.spacing = grid.spacing;
    const std::size_t count = std::size_t(grid.samples.x) * grid.samples.y * grid.samples.z;
    r.field.values.assign(count, 0.0f);
    if (options.computeMaterials)
        r.materials.assign(count, 0u);
    if (options.keepExactValues)
        r.exactValues.assign(count, 0.0);
    r.hermite.samples = grid.samples;
    r.hermite.precision = options.crossingPrecisionCells * grid.spacing;
    r.stats.samples = count;
    for (const auto& e : model.edits)
        r.stats.activeEdits += e.frame <= frame ? 1 : 0;
    r.stats.bruteForceEvaluations = r.stats.samples * r.stats.activeEdits;
    return r;
}

Outputs getOutputs(EvaluationResult& r, const EvaluationOptions& options)
{
    Outputs o;
    o.field = &r.field;
    o.materials = options.computeMaterials ? &r.materials : nullptr;
    o.exactValues = options.keepExactValues ? &r.exactValues : nullptr;
    return o;
}

template <typename F>
void runInArena(int threadCount, F&& f)
{
    tbb::task_arena arena(threadCount > 0 ? threadCount : tbb::task_arena::automatic);
    arena.execute(std::forward<F>(f));
}

} // namespace

double EvaluationStats::getCullingRate() const
{
    if (bruteForceEvaluations == 0)
        return 0.0;
    return 1.0 - double(getFieldEvaluations()) / double(bruteForceEvaluations);
}

double EvaluationStats::getIdealCullingRate() const
{
    if (bruteForceEvaluations == 0)
        return 0.0;
    return 1.0 - double(samplesInBand) / double(bruteForceEvaluations);
}

double EvaluationStats::getSamplesPerSecond() const
{
    return fieldSeconds > 0.0 ? double(samples) / fieldSeconds : 0.0;
}

double clampToBand(double value, double band)
{
    if (value > band)
        return band;
    if (value < -band)
        return -band;
    return value;
}

float toFieldValue(double value)
{
    const float f = float(value);
    if (value > 0.0 && !(f > 0.0f))
        return std::numeric_limits<float>::denorm_min();
    return f;
}

GridSpec makeModelGrid(const SdfModel& model, int samplesAlongLongest)
{
    if (samplesAlongLongest < 4)
        throw std::invalid_argument("makeModelGrid: need at least 4 samples along the longest side");
    const glm::dvec3 extent = model.boundsMax - model.boundsMin;
    const double longest = std::max({extent.x, extent.y, extent.z});
    if (!(longest > 0.0) || !std::isfinite(longest))
        throw std::invalid_argument("makeModelGrid: model '" + model.name + "' has empty bounds");
    GridSpec g;
    g.spacing = longest / double(samplesAlongLongest - 3);
    for (int i = 0; i < 3; ++i)
        g.samples[i] = std::min(samplesAlongLongest, int(std::ceil(extent[i] / g.spacing - 1e-9)) + 3);
    g.origin = model.boundsMin - glm::dvec3(g.spacing);
    return g;
}

EvaluationResult evaluateModel(const SdfModel& model, const GridSpec& grid, int frame,
                               const EvaluationOptions& options)
{
    const auto start = std::chrono::steady_clock::now();
    EvaluationResult r = makeResult(model, grid, frame, options);
    Hierarchy h(model, grid, frame, options, getOutputs(r, options));
    std::vector<const CsgEdit*> rootCandidates;
    if (options.computeMaterials)
        for (const auto& e : model.edits)
            if (e.frame <= frame && e.op == CsgOp::Add)
                rootCandidates.push_back(&e);
    runInArena(options.threadCount, [&] { h.run(getActiveOps(model, frame), rootCandidates); });
    r.stats.fieldSeconds = getSeconds(start);

    EvaluationStats& st = r.stats;
    st.cellSamples = h.cellSamples;
    st.cellsVisited.assign(h.cellSamples.size(), 0);
    st.cellsEmpty.assign(h.cellSamples.size(), 0);
    st.cellsFull.assign(h.cellSamples.size(), 0);
    for (const Counters& c : h.counters) {
        st.sampleEvaluations += c.sampleEvaluations;
        st.boundEvaluations += c.boundEvaluations;
        st.materialEvaluations += c.materialEvaluations;
        st.samplesEvaluated += c.samplesEvaluated;
        st.samplesInBand += c.samplesInBand;
        st.leavesEvaluated += c.leavesEvaluated;
        for (std::size_t l = 0; l < c.cellsVisited.size(); ++l) {
            st.cellsVisited[l] += c.cellsVisited[l];
            st.cellsEmpty[l] += c.cellsEmpty[l];
            st.cellsFull[l] += c.cellsFull[l];
        }
    }

    if (options.computeHermite) {
        const auto hermiteStart = std::chrono::steady_clock::now();
        std::vector<const LeafRecord*> records;
        for (const auto& list : h.leaves)
            for (const auto& leaf : list)
                records.push_back(&leaf);
        tbb::enumerable_thread_specific<std::vector<HermiteEdge>> edges;
        tbb::enumerable_thread_specific<std::uint64_t> evaluations(0);
        runInArena(options.threadCount, [&] {
            tbb::parallel_for(std::size_t(0), records.size(), [&](std::size_t i) {
                const LeafRecord& leaf = *records[i];
                findCrossings(leaf.ops, grid, r.field, leaf.first, leaf.last, options, edges.local(),
                              evaluations.local());
            });
        });
        for (const auto& list : edges)
            r.hermite.edges.insert(r.hermite.edges.end(), list.begin(), list.end());
        for (std::uint64_t n : evaluations)
            st.hermiteEvaluations += n;
        r.hermite.sort();  // keys are unique, so the order does not depend on the threads
        st.hermiteEdges = r.hermite.edges.size();
        st.hermiteSeconds = getSeconds(hermiteStart);
    }
    st.totalSeconds = getSeconds(start);
    return r;
}

EvaluationResult evaluateModelBruteForce(const SdfModel& model, const GridSpec& grid, int frame,
                                         const EvaluationOptions& options)
{
    const auto start = std::chrono::steady_clock::now();
    EvaluationResult r = makeResult(model, grid, frame, options);
    const double band = r.band;
    tbb::enumerable_thread_specific<std::uint64_t> inBand(0);
    runInArena(options.threadCount, [&] {
        tbb::parallel_for(0, grid.samples.z, [&](int z) {
            std::uint64_t& n = inBand.local();
            for (int y = 0; y < grid.samples.y; ++y)
                for (int x = 0; x < grid.samples.x; ++x) {
                    const glm::dvec3 p = getSamplePosition(grid, x, y, z);
                    const double d = model.evaluate(p, frame);
                    n += std::abs(d) <= band ? 1 : 0;
                    const std::size_t i = r.field.index(x, y, z);
                    const double v = clampToBand(d, band);
                    r.field.values[i] = toFieldValue(v);
                    if (options.keepExactValues)
                        r.exactValues[i] = v;
                    if (options.computeMaterials)
                        r.materials[i] = model.evaluateMaterial(p, frame);
                }
        });
    });
    EvaluationStats& st = r.stats;
    st.fieldSeconds = getSeconds(start);
    st.sampleEvaluations = st.bruteForceEvaluations;
    st.samplesEvaluated = st.samples;
    for (std::uint64_t n : inBand)
        st.samplesInBand += n;
    if (options.computeMaterials)
        st.materialEvaluations = st.bruteForceEvaluations * 2;

    if (options.computeHermite) {
        const auto hermiteStart = std::chrono::steady_clock::now();
        const std::vector<Op> ops = getActiveOps(model, frame);
        tbb::enumerable_thread_specific<std::vector<HermiteEdge>> edges;
        tbb::enumerable_thread_specific<std::uint64_t> evaluations(0);
        runInArena(options.threadCount, [&] {
            tbb::parallel_for(0, grid.samples.z, [&](int z) {
                findCrossings(ops, grid, r.field, glm::ivec3(0, 0, z),
                              glm::ivec3(grid.samples.x - 1, grid.samples.y - 1, z), options,
                              edges.local(), evaluations.local());
            });
        });
        for (const auto& list : edges)
            r.hermite.edges.insert(r.hermite.edges.end(), list.begin(), list.end());
        for (std::uint64_t n : evaluations)
            st.hermiteEvaluations += n;
        r.hermite.sort();
        st.hermiteEdges = r.hermite.edges.size();
        st.hermiteSeconds = getSeconds(hermiteStart);
    }
    st.totalSeconds = getSeconds(start);
    return r;
}

ExactFunctions makeExactFunctions(const SdfModel& model, int frame, double gradientStep)
{
    auto shared = std::make_shared<const SdfModel>(model);
    auto ops = std::make_shared<const std::vector<Op>>(getActiveOps(*shared, frame));
    double step = gradientStep;
    if (!(step > 0.0)) {
        const double diagonal = glm::length(model.boundsMax - model.boundsMin);
        step = 1e-6 * (diagonal > 0.0 && std::isfinite(diagonal) ? diagonal : 1.0);
    }
    ExactFunctions f;
    f.value = [shared, frame](const glm::dvec3& p) { return shared->evaluate(p, frame); };
    // `shared` is captured too: the ops point into its edits.
    f.gradient = [shared, ops, step](const glm::dvec3& p) {
        glm::dvec3 g;
        bool kink = false;
        evaluateOpsWithGradient(*ops, p, getGradientStep(step, p), g, kink);
        return normalizeOrZero(g, kink);
    };
    return f;
}

} // namespace rtlab::sdf
