#pragma once
// Internal to dual_contouring: the structures its passes share and the passes themselves, one
// source file per role (edges.cpp: the crossed edges; cells.cpp: cell cases and vertex numbering;
// vertices.cpp: QEF vertex placement; relaxation.cpp: material boundary relaxation; extraction.cpp:
// the driver and the quads).

#include "extraction.h"
#include "qef.h"

#include "isosurface/case_table.h"
#include "isosurface/sign_rows.h"

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace rtlab::isosurface::dc::detail {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
//! A solved vertex counts as outside its cell when a coordinate leaves [0, 1] by more than this
//! (cells), which is far above the solvers' rounding and far below any visible displacement.
constexpr double kOutsideTolerance = 1e-9;
//! Newton steps when a relaxed vertex is projected back onto the exact surface.
constexpr int kProjectionSteps = 8;
//! Halvings of a relaxation step whose projection leaves the vertex's cell before it is dropped.
constexpr int kMaxStepHalvings = 4;
//! Boundary neighbours of a vertex at most: one per segment of its patch.
constexpr std::size_t kMaxNeighbours = 12;

inline bool isFinite(const glm::dvec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline glm::dvec3 normalizeOrZero(const glm::dvec3& v)
{
    const double length = glm::length(v);
    if (!std::isfinite(length) || !(length > 0.0))
        return glm::dvec3(0.0);
    return v / length;
}

inline glm::dvec3 axisVector(int axis)
{
    glm::dvec3 v(0.0);
    v[axis] = 1.0;
    return v;
}

//! Read-only view of the field shared by all passes. Coordinates are
//! grid units: sample (x, y, z) is at (x, y, z), world = origin + spacing * grid.
class Grid {
public:
    Grid(const plugin::SampledField& field, double isoValue)
        : mField(field), mIso(isoValue),
          mSize(field.samples), mStride{1, std::size_t(field.samples.x),
                                        std::size_t(field.samples.x) * field.samples.y}
    {
        const std::size_t total = mStride[2] * std::size_t(std::max(field.samples.z, 0));
        mFastDivide = total < (std::size_t(1) << 32) && mStride[1] >= 2 && mStride[2] >= 2;
        if (mFastDivide) {
            mRowReciprocal = computeReciprocal(mStride[1]);
            mLayerReciprocal = computeReciprocal(mStride[2]);
        }
    }

    int size(int axis) const { return mSize[axis]; }
    int cells(int axis) const { return mSize[axis] - 1; }
    std::size_t stride(int axis) const { return mStride[axis]; }
    std::size_t index(const glm::ivec3& s) const { return mField.index(s.x, s.y, s.z); }
    glm::ivec3 sampleOf(std::size_t i) const
    {
        if (!mFastDivide)
            return glm::ivec3(int(i % mStride[1]), int((i / mStride[1]) % mSize.y),
                              int(i / mStride[2]));
        // Every edge and quad decodes its sample: a multiply instead of each 64-bit division.
        const std::size_t z = divide(i, mLayerReciprocal);
        const std::size_t rest = i - z * mStride[2];
        const std::size_t y = divide(rest, mRowReciprocal);
        return glm::ivec3(int(rest - y * mStride[1]), int(y), int(z));
    }
    //! Value relative to the iso-value; f < iso exactly when relative < 0.
    double relative(std::size_t i) const { return double(mField.values[i]) - mIso; }
    double iso() const { return mIso; }
    glm::dvec3 toWorld(const glm::dvec3& grid) const
    {
        return mField.origin + mField.spacing * grid;
    }
    double spacing() const { return mField.spacing; }

    //! Field gradient at a sample, field units per sample step: central differences inside the
    //! grid, one-sided on its boundary.
    glm::dvec3 sampleGradient(const glm::ivec3& s) const
    {
        const std::size_t i = index(s);
        glm::dvec3 gradient(0.0);
        for (int axis = 0; axis < 3; ++axis) {
            const std::size_t step = mStride[axis];
            const int c = s[axis];
            if (c > 0 && c + 1 < mSize[axis])
                gradient[axis] = 0.5 * (relative(i + step) - relative(i - step));
            else if (c == 0)
                gradient[axis] = relative(i + step) - relative(i);
            else
                gradient[axis] = relative(i) - relative(i - step);
        }
        return gradient;
    }

private:
    //! floor((2^64 - 1) / d) + 1 for d >= 2, i.e. floor(2^64 / d) + 1, or 2^64 / d for a power of
    //! two: for i, d < 2^32, floor(i / d) = (i * r) >> 64 exactly (the product overshoots i / d by
    //! less than i / 2^64 < 1 / d, which no fractional part of i / d reaches).
    static std::uint64_t computeReciprocal(std::size_t d) { return ~std::uint64_t(0) / d + 1u; }
    static std::size_t divide(std::size_t i, std::uint64_t reciprocal)
    {
        return std::size_t((unsigned __int128)(i)*reciprocal >> 64);
    }

    const plugin::SampledField& mField;
    double mIso;
    glm::ivec3 mSize;
    std::size_t mStride[3];
    bool mFastDivide = false;
    std::uint64_t mRowReciprocal = 0;
    std::uint64_t mLayerReciprocal = 0;
};

//! One crossed grid edge's Hermite point and normal: the point at t (in [0, 1], cells) along the
//! edge from its low sample, the normal unit or zero. 32 bytes: the vertex pass reads one per
//! edge of a cell, from rows a layer apart, and is bound by those loads.
struct Crossing {
    double t = 0.0;
    glm::dvec3 normal{0.0};
};

//! The crossed edges, numbered in scan order (layer, row, sample, axis), and where to find them:
//! the sign bits of every sample row (framework/isosurface/sign_rows.h) and, per row and 64-sample
//! word, the number of the first crossed edge starting there; nothing per sample, so memory and
//! time follow the surface, not the grid.
struct EdgeTable {
    explicit EdgeTable(SignRows signs) : rows(std::move(signs)) {}

    SignRows rows;
    std::vector<std::uint32_t> wordBase; //!< per sample row (z * ny + y) and word
    std::vector<std::uint64_t> edges;    //!< per edge: sample index * 3 + axis
    std::vector<Crossing> crossings;     //!< per edge

    bool isInside(const glm::ivec3& s) const { return rows.isInside(s); }

    //! Number of the crossed edge (sample s, axis), or kNone when it is not crossed.
    std::uint32_t find(const glm::ivec3& s, int axis) const
    {
        const std::size_t w = std::size_t(s.x) >> 6;
        return findIn(getWord(s.y, s.z, w), s.x & 63, axis);
    }

    //! One 64-sample word of a sample row: its crossings and the number of its first edge.
    struct Word {
        SignRows::Crossings crossings;
        std::uint32_t base;
    };
    Word getWord(int y, int z, std::size_t w) const
    {
        const std::size_t row = std::size_t(z) * std::size_t(rows.size(1)) + std::size_t(y);
        return {rows.getCrossings(y, z, w), wordBase[row * rows.words() + w]};
    }
    //! find() within a word already fetched: `bit` is the sample's x within it.
    static std::uint32_t findIn(const Word& word, int bit, int axis)
    {
        const SignRows::Crossings& c = word.crossings;
        if (((c.axis[axis] >> bit) & 1u) == 0)
            return kNone;
        // Edges before this one in the word: all axes at lower samples, lower axes at this one.
        const std::uint64_t below = (std::uint64_t(1) << bit) - 1u;
        std::uint32_t index = std::uint32_t(std::popcount(c.axis[0] & below) +
                                            std::popcount(c.axis[1] & below) +
                                            std::popcount(c.axis[2] & below));
        for (int a = 0; a < axis; ++a)
            index += std::uint32_t((c.axis[a] >> bit) & 1u);
        return word.base + index;
    }
};

//! Pass 1 (after the sign bits): the crossed edges, numbered in scan order (edges.cpp).
void buildEdgeTable(const Grid& grid, EdgeTable& table);

//! Hermite data of the crossed edges, from the first available source (see ExtractionOptions).
class CrossingSource {
public:
    CrossingSource(const Grid& grid, const plugin::IsosurfaceInput& input,
                   const ExtractionOptions& options)
        : mGrid(grid), mInput(input), mOptions(options)
    {
        const bool automatic = options.hermite == HermiteMode::Auto;
        mUseHermite = automatic && input.hermite != nullptr;
        mUseExactValue = automatic && bool(input.exactValue);
        mUseExactGradient = automatic && bool(input.exactGradient);
        // Halvings until the bracketing interval is at most crossingPrecision cells wide.
        mBisectionSteps = int(std::ceil(std::log2(1.0 / options.crossingPrecision)));
        mBisectionSteps = std::clamp(mBisectionSteps, 1, 60);
    }

    HermiteSource source() const
    {
        if (mUseHermite)
            return HermiteSource::Hermite;
        return mUseExactValue || mUseExactGradient ? HermiteSource::Exact : HermiteSource::Samples;
    }
    bool hasExactProjection() const { return mUseExactValue && mUseExactGradient; }

    //! The crossing on edge (sample, axis); `missing` is set when input.hermite lacked it.
    Crossing compute(const glm::ivec3& s, int axis, bool& missing) const
    {
        return compute(s, axis, missing, mUseHermite ? mInput.hermite->find(s, axis) : nullptr);
    }

    //! The same for edges visited in increasing key order (scan order): `cursor` is the index
    //! into input.hermite->edges of the first entry not below the previous edge's key (start: 0
    //! or a lower bound), and walks forward with the edges instead of a binary search per edge.
    Crossing computeInOrder(const glm::ivec3& s, int axis, bool& missing, std::size_t& cursor) const
    {
        if (!mUseHermite)
            return compute(s, axis, missing, nullptr);
        const std::vector<plugin::HermiteEdge>& edges = mInput.hermite->edges;
        const std::uint64_t wanted = mInput.hermite->key(s, axis);
        while (cursor < edges.size() &&
               mInput.hermite->key(edges[cursor].sample, edges[cursor].axis) < wanted)
            ++cursor;
        const bool found = cursor < edges.size() &&
                           mInput.hermite->key(edges[cursor].sample, edges[cursor].axis) == wanted;
        return compute(s, axis, missing, found ? &edges[cursor] : nullptr);
    }

    //! Index of the first Hermite edge whose key is not below `key` (0 without Hermite data).
    std::size_t findHermiteLowerBound(std::uint64_t key) const
    {
        if (!mUseHermite)
            return 0;
        const std::vector<plugin::HermiteEdge>& edges = mInput.hermite->edges;
        const auto it = std::lower_bound(edges.begin(), edges.end(), key,
                                         [&](const plugin::HermiteEdge& e, std::uint64_t k) {
                                             return mInput.hermite->key(e.sample, e.axis) < k;
                                         });
        return std::size_t(it - edges.begin());
    }

private:
    Crossing compute(const glm::ivec3& s, int axis, bool& missing,
                     const plugin::HermiteEdge* edge) const
    {
        missing = false;
        if (mUseHermite) {
            if (edge != nullptr && std::isfinite(edge->t)) {
                Crossing c;
                c.t = std::clamp(edge->t, 0.0, 1.0);
                // The evaluator's normals are unit (or zero): those are kept as they are.
                const double squared = glm::dot(edge->normal, edge->normal);
                c.normal = std::abs(squared - 1.0) <= 1e-15 ? glm::dvec3(edge->normal)
                                                            : normalizeOrZero(edge->normal);
                return c;
            }
            missing = true;
        }
        const std::size_t i = mGrid.index(s);
        const std::size_t j = i + mGrid.stride(axis);
        double t;
        if (mUseExactValue)
            t = bisect(s, axis, mGrid.relative(i) < 0.0);
        else
            t = interpolateLinear(mGrid.relative(i), mGrid.relative(j));
        Crossing c;
        c.t = t;
        if (mUseExactGradient) {
            // Outward normal: the field grows outward. Uniform scaling keeps directions, so the
            // world gradient's direction is the grid-unit normal.
            c.normal = normalizeOrZero(
                mInput.exactGradient(mGrid.toWorld(glm::dvec3(s) + t * axisVector(axis))));
        } else {
            glm::ivec3 s1 = s;
            ++s1[axis];
            c.normal =
                normalizeOrZero((1.0 - t) * mGrid.sampleGradient(s) + t * mGrid.sampleGradient(s1));
        }
        return c;
    }

    //! Zero of the linear interpolant; an infinite end puts the crossing on the finite end.
    static double interpolateLinear(double a, double b)
    {
        const bool finiteA = std::isfinite(a);
        const bool finiteB = std::isfinite(b);
        if (!finiteA && !finiteB)
            return 0.5;
        if (!finiteA)
            return 1.0;
        if (!finiteB)
            return 0.0;
        return std::clamp(a / (a - b), 0.0, 1.0);
    }

    //! Bisection of exactValue along the edge, keeping the end whose sample is inside on the
    //! inside: after k halvings the crossing is bracketed within 2^-k cells; the midpoint of the
    //! bracket is returned (|t - t_true| <= crossingPrecision / 2 where the exact field's sign
    //! agrees with the samples' at the ends).
    double bisect(const glm::ivec3& s, int axis, bool lowInside) const
    {
        double a = 0.0;
        double b = 1.0;
        const glm::dvec3 start(s);
        const glm::dvec3 direction = axisVector(axis);
        for (int k = 0; k < mBisectionSteps; ++k) {
            const double mid = 0.5 * (a + b);
            const double f =
                mInput.exactValue(mGrid.toWorld(start + mid * direction)) - mGrid.iso();
            if (std::isnan(f))
                break;
            if ((f < 0.0) == lowInside)
                a = mid;
            else
                b = mid;
        }
        return 0.5 * (a + b);
    }

    const Grid& mGrid;
    const plugin::IsosurfaceInput& mInput;
    const ExtractionOptions& mOptions;
    bool mUseHermite = false;
    bool mUseExactValue = false;
    bool mUseExactGradient = false;
    int mBisectionSteps = 20;
};

//! The 12 edges of a cell: start corner offset and axis.
struct CellEdgeOffset {
    glm::ivec3 offset;
    int axis;
};

//! The 12 edges of a cell, in the order of the CellVertices edge masks.
const std::array<CellEdgeOffset, 12>& getCellEdgeOffsets();

//! Whether the crossed edge (sample, axis) has all four cells around it (gives a quad).
inline bool isInteriorEdge(const Grid& grid, const glm::ivec3& s, int axis)
{
    const int b = (axis + 1) % 3;
    const int c = (axis + 2) % 3;
    return s[b] >= 1 && s[b] + 1 < grid.size(b) && s[c] >= 1 && s[c] + 1 < grid.size(c);
}

//! Whether a position in a cell's frame lies in its box [0, 1]^3, within kOutsideTolerance.
inline bool isInsideBox(const glm::dvec3& p)
{
    for (int axis = 0; axis < 3; ++axis) {
        if (!(p[axis] >= -kOutsideTolerance && p[axis] <= 1.0 + kOutsideTolerance))
            return false;
    }
    return true;
}

//! The four cells around edge (sample, axis), counter-clockwise seen from +axis.
inline std::array<glm::ivec3, 4> getCellsAroundEdge(const glm::ivec3& s, int axis)
{
    const int b = (axis + 1) % 3;
    const int c = (axis + 2) % 3;
    std::array<glm::ivec3, 4> cells;
    constexpr int kOrder[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; ++k) {
        glm::ivec3 cell = s;
        cell[b] -= 1 - kOrder[k][0];
        cell[c] -= 1 - kOrder[k][1];
        cells[k] = cell;
    }
    return cells;
}

//! Marching cubes edge id (framework/isosurface/case_table.h numbering) of the cell edge that
//! starts at `offset` (0 or 1 per axis) from the cell's lowest sample and runs along `axis`.
inline int getTableEdge(const glm::ivec3& offset, int axis)
{
    const int u = axis == 0 ? 1 : 0;
    const int v = axis == 2 ? 1 : 2;
    return axis * 4 + offset[u] + 2 * offset[v];
}

//! What the vertex passes need to know about each cell.
struct CellCase {
    std::uint16_t entry = 0;  //!< index into the case table (per_component)
    std::uint8_t cube = 0;    //!< bit c set when corner c is inside
    std::uint8_t joined = 0;  //!< ambiguous faces whose inside corners are joined across them
    std::uint8_t paired = 0;  //!< faces that this cell's and the neighbour's patch both cross twice
    std::uint8_t patches = 0; //!< patch vertices of the cell (0 when it has no sign change)
    //! 2 bits per table edge: the loop (patch) a crossed edge lies on (the case table's edgeLoop,
    //! copied here so that a quad's vertex lookup does not reach into the case table).
    std::uint32_t edgeLoops = 0;
    std::uint32_t firstVertex = 0; //!< the cell's first vertex (its patches', then face vertices)
};

//! The active cells (those with a sign change) and their vertices. Cells are found through bit
//! masks per row of cells, like the sample rows: per cell row (z * cells.y + y) and 64-cell word,
//! the active cells' bits and the number of the first active cell in the word.
struct CellVertices {
    std::size_t words = 0; //!< words per cell row
    int rowsPerLayer = 0;  //!< cells along y
    std::vector<std::uint64_t> active;
    std::vector<std::uint32_t> activeBase;
    std::vector<glm::ivec3> activeCell;      //!< per active cell, in scan order
    std::vector<CellCase> cases;             //!< per active cell
    std::vector<glm::ivec3> cell;            //!< per vertex
    std::vector<std::uint16_t> edges; //!< per vertex: its cell edges (getCellEdgeOffsets bits)
    std::vector<std::uint8_t> onFace; //!< per vertex: 1 for a face vertex (see numberCells)
    std::vector<glm::dvec3> local;    //!< per vertex, position relative to its cell, cells
    std::vector<glm::dvec3> normal;   //!< per vertex, unit
    std::vector<QefSystem> qef;       //!< per vertex, kept for the relaxation only
    //! per vertex, placeVertices' counters before their serial sum: rank, left its cell, normals
    //! skipped, no plane (kept here so that a reused workspace allocates nothing per call).
    std::vector<std::array<std::uint8_t, 4>> placement;

    //! Number of the active cell `cell` (inside the grid), or kNone when it has no sign change.
    std::uint32_t findActive(const glm::ivec3& cell) const
    {
        const std::size_t k =
            (std::size_t(cell.z) * std::size_t(rowsPerLayer) + std::size_t(cell.y)) * words +
            (std::size_t(cell.x) >> 6);
        const int bit = cell.x & 63;
        if (((active[k] >> bit) & 1u) == 0)
            return kNone;
        return activeBase[k] +
               std::uint32_t(std::popcount(active[k] & ((std::uint64_t(1) << bit) - 1u)));
    }
    //! The case of `cell`; an all-zero case (no patch, entry 0) for a cell without sign change.
    const CellCase& getCase(const glm::ivec3& cell) const
    {
        static const CellCase kInactive{};
        const std::uint32_t k = findActive(cell);
        return k == kNone ? kInactive : cases[k];
    }
};

//! Bit f of a face mask for the faces on the high side of a cell (x, y, z).
constexpr unsigned kHighFaces = (1u << 1) | (1u << 3) | (1u << 5);

//! Pass 2: the case of every active cell and its vertices, numbered in cell scan order
//! (cells.cpp).
void numberCells(const Grid& grid, const EdgeTable& table, const ExtractionOptions& options,
                 CellVertices& vertices);

//! The vertex that the quads around the crossed grid edge (sample s, axis) use in `cell` (per
//! cell: the cell's only vertex, its edge loops being all 0).
inline std::uint32_t findEdgeVertex(const CellVertices& vertices, const glm::ivec3& cell,
                                    const glm::ivec3& s, int axis)
{
    const std::uint32_t k = vertices.findActive(cell);
    if (k == kNone)
        return kNone;
    const CellCase& c = vertices.cases[k];
    return c.firstVertex + ((c.edgeLoops >> (2 * getTableEdge(s - cell, axis))) & 3u);
}

//! The face vertex between `cell` and its neighbour `other` for the segment holding the crossed
//! grid edge (sample s, axis), or kNone when that face has none.
std::uint32_t findFaceVertex(const Grid& grid, const CellVertices& vertices, glm::ivec3 cell,
                             glm::ivec3 other, const glm::ivec3& s, int axis);

//! The diagonal a quad (q[0..3], positions p[0..3] in any common frame) is split along: true
//! for v1-v3 (extraction.cpp; the rule is documented there).
bool chooseDiagonal13(const std::array<std::uint32_t, 4>& q, const std::array<glm::dvec3, 4>& p);

//! Pass 3: one QEF vertex per cell or patch (vertices.cpp).
void placeVertices(const Grid& grid, const EdgeTable& table, const ExtractionOptions& options,
                   bool keepQef, CellVertices& vertices, ExtractionStats& stats);

//! Finds the material boundary vertices (stats.boundaryVertices) and, when `relax` is set, runs
//! the elastic relaxation on them (stats.maxRelaxationShift) (relaxation.cpp).
void relaxMaterialBoundaries(const Grid& grid, const EdgeTable& table,
                             const std::vector<std::uint32_t>& materials,
                             const ExtractionOptions& options, const CrossingSource& source,
                             const plugin::IsosurfaceInput& input, bool relax,
                             CellVertices& vertices, ExtractionStats& stats);

} // namespace rtlab::isosurface::dc::detail
