#include "extraction.h"

#include "qef.h"

#include "isosurface/case_table.h"
#include "isosurface/sign_rows.h"

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace rtlab::isosurface::dc {
namespace {

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

bool isFinite(const glm::dvec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

glm::dvec3 normalizeOrZero(const glm::dvec3& v)
{
    const double length = glm::length(v);
    if (!std::isfinite(length) || !(length > 0.0))
        return glm::dvec3(0.0);
    return v / length;
}

glm::dvec3 axisVector(int axis)
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
    }

    int size(int axis) const { return mSize[axis]; }
    int cells(int axis) const { return mSize[axis] - 1; }
    std::size_t stride(int axis) const { return mStride[axis]; }
    std::size_t index(const glm::ivec3& s) const { return mField.index(s.x, s.y, s.z); }
    glm::ivec3 sampleOf(std::size_t i) const
    {
        return glm::ivec3(int(i % mStride[1]), int((i / mStride[1]) % mSize.y),
                          int(i / mStride[2]));
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
    const plugin::SampledField& mField;
    double mIso;
    glm::ivec3 mSize;
    std::size_t mStride[3];
};

//! One crossed grid edge's Hermite point and normal (grid units; normal unit or zero).
struct Crossing {
    glm::dvec3 point{0.0};
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
        const int bit = s.x & 63;
        const SignRows::Crossings c = rows.getCrossings(s.y, s.z, w);
        if (((c.axis[axis] >> bit) & 1u) == 0)
            return kNone;
        // Edges before this one in the word: all axes at lower samples, lower axes at this one.
        const std::uint64_t below = (std::uint64_t(1) << bit) - 1u;
        std::uint32_t index = std::uint32_t(std::popcount(c.axis[0] & below) +
                                            std::popcount(c.axis[1] & below) +
                                            std::popcount(c.axis[2] & below));
        for (int a = 0; a < axis; ++a)
            index += std::uint32_t((c.axis[a] >> bit) & 1u);
        const std::size_t row = std::size_t(s.z) * std::size_t(rows.size(1)) + std::size_t(s.y);
        return wordBase[row * rows.words() + w] + index;
    }
};

void validate(const plugin::IsosurfaceInput& input)
{
    if (input.field == nullptr)
        throw std::invalid_argument("dual_contouring: IsosurfaceInput::field is null");
    const plugin::SampledField& field = *input.field;
    if (!(std::isfinite(field.spacing) && field.spacing > 0.0))
        throw std::invalid_argument(
            "dual_contouring: the field spacing must be finite and > 0, got " +
            std::to_string(field.spacing));
    if (!isFinite(field.origin))
        throw std::invalid_argument("dual_contouring: the field origin must be finite");
    if (field.samples.x < 0 || field.samples.y < 0 || field.samples.z < 0)
        throw std::invalid_argument("dual_contouring: negative sample count");
    const std::size_t expected = std::size_t(field.samples.x) * field.samples.y * field.samples.z;
    if (field.values.size() != expected)
        throw std::invalid_argument("dual_contouring: the field has " +
                                    std::to_string(field.values.size()) + " values for " +
                                    std::to_string(expected) + " samples");
    if (!std::isfinite(input.isoValue))
        throw std::invalid_argument("dual_contouring: the iso-value must be finite, got " +
                                    std::to_string(input.isoValue));
    if (input.materials != nullptr && input.materials->size() != expected)
        throw std::invalid_argument("dual_contouring: " + std::to_string(input.materials->size()) +
                                    " materials for " + std::to_string(expected) + " samples");
    if (input.hermite != nullptr && input.hermite->samples != field.samples)
        throw std::invalid_argument("dual_contouring: the Hermite data refers to another grid");
}

//! Pass 1 (after the sign bits): the crossed edges, numbered in scan order.
void buildEdgeTable(const Grid& grid, EdgeTable& table)
{
    const SignRows& rows = table.rows;
    const int ny = grid.size(1);
    const int nz = grid.size(2);
    const std::size_t words = rows.words();
    std::vector<std::uint64_t> layerCount(nz + 1, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, nz), [&](const tbb::blocked_range<int>& range) {
        for (int z = range.begin(); z != range.end(); ++z)
            layerCount[z + 1] = rows.countCrossedEdges(z);
    });
    for (int z = 0; z < nz; ++z)
        layerCount[z + 1] += layerCount[z];
    const std::uint64_t edgeCount = layerCount[nz];
    if (edgeCount >= kNone)
        throw std::length_error("dual_contouring: " + std::to_string(edgeCount) +
                                " crossed edges exceed 32-bit indices");
    table.edges.resize(edgeCount);
    table.wordBase.resize(std::size_t(nz) * std::size_t(ny) * words);
    tbb::parallel_for(tbb::blocked_range<int>(0, nz), [&](const tbb::blocked_range<int>& range) {
        for (int z = range.begin(); z != range.end(); ++z) {
            std::uint32_t next = std::uint32_t(layerCount[z]);
            for (int y = 0; y < ny; ++y)
                for (std::size_t w = 0; w < words; ++w) {
                    table.wordBase[(std::size_t(z) * ny + y) * words + w] = next;
                    const SignRows::Crossings c = rows.getCrossings(y, z, w);
                    for (std::uint64_t any = c.any(); any != 0; any &= any - 1) {
                        const int bit = std::countr_zero(any);
                        const std::size_t sample = grid.index({int(64 * w) + bit, y, z});
                        for (int axis = 0; axis < 3; ++axis)
                            if ((c.axis[axis] >> bit) & 1u)
                                table.edges[next++] = std::uint64_t(sample) * 3u + std::uint64_t(axis);
                    }
                }
        }
    });
}

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
        missing = false;
        if (mUseHermite) {
            const plugin::HermiteEdge* edge = mInput.hermite->find(s, axis);
            if (edge != nullptr && std::isfinite(edge->t)) {
                Crossing c;
                c.point = glm::dvec3(s) + std::clamp(edge->t, 0.0, 1.0) * axisVector(axis);
                c.normal = normalizeOrZero(edge->normal);
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
        c.point = glm::dvec3(s) + t * axisVector(axis);
        if (mUseExactGradient) {
            // Outward normal: the field grows outward. Uniform scaling keeps directions, so the
            // world gradient's direction is the grid-unit normal.
            c.normal = normalizeOrZero(mInput.exactGradient(mGrid.toWorld(c.point)));
        } else {
            glm::ivec3 s1 = s;
            ++s1[axis];
            c.normal =
                normalizeOrZero((1.0 - t) * mGrid.sampleGradient(s) + t * mGrid.sampleGradient(s1));
        }
        return c;
    }

private:
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

const std::array<CellEdgeOffset, 12>& getCellEdgeOffsets()
{
    static const std::array<CellEdgeOffset, 12> edges = [] {
        std::array<CellEdgeOffset, 12> e{};
        int k = 0;
        for (int axis = 0; axis < 3; ++axis) {
            const int b = (axis + 1) % 3;
            const int c = (axis + 2) % 3;
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i) {
                    glm::ivec3 o(0);
                    o[b] = i;
                    o[c] = j;
                    e[k++] = {o, axis};
                }
        }
        return e;
    }();
    return edges;
}

//! Whether the crossed edge (sample, axis) has all four cells around it (gives a quad).
bool isInteriorEdge(const Grid& grid, const glm::ivec3& s, int axis)
{
    const int b = (axis + 1) % 3;
    const int c = (axis + 2) % 3;
    return s[b] >= 1 && s[b] + 1 < grid.size(b) && s[c] >= 1 && s[c] + 1 < grid.size(c);
}

//! The four cells around edge (sample, axis), counter-clockwise seen from +axis.
std::array<glm::ivec3, 4> getCellsAroundEdge(const glm::ivec3& s, int axis)
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
int getTableEdge(const glm::ivec3& offset, int axis)
{
    const int u = axis == 0 ? 1 : 0;
    const int v = axis == 2 ? 1 : 2;
    return axis * 4 + offset[u] + 2 * offset[v];
}

//! Per DC cell edge (getCellEdgeOffsets order), its table edge id.
const std::array<int, 12>& getTableEdges()
{
    static const std::array<int, 12> ids = [] {
        std::array<int, 12> e{};
        for (int k = 0; k < 12; ++k)
            e[k] = getTableEdge(getCellEdgeOffsets()[k].offset, getCellEdgeOffsets()[k].axis);
        return e;
    }();
    return ids;
}

//! A table edge mask converted to a DC cell edge mask.
std::uint16_t toCellEdgeMask(unsigned tableMask)
{
    std::uint16_t mask = 0;
    for (int k = 0; k < 12; ++k) {
        if ((tableMask >> getTableEdges()[k]) & 1u)
            mask |= std::uint16_t(1u << k);
    }
    return mask;
}

//! What the vertex passes need to know about each cell.
struct CellCase {
    std::uint16_t entry = 0;  //!< index into the case table (per_component)
    std::uint8_t cube = 0;    //!< bit c set when corner c is inside
    std::uint8_t joined = 0;  //!< ambiguous faces whose inside corners are joined across them
    std::uint8_t paired = 0;  //!< faces that this cell's and the neighbour's patch both cross twice
    std::uint8_t patches = 0; //!< patch vertices of the cell (0 when it has no sign change)
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
    std::vector<std::uint32_t> vertexOfCell; //!< per active cell: its first vertex
    std::vector<glm::ivec3> cell;            //!< per vertex
    std::vector<std::uint16_t> edges; //!< per vertex: its cell edges (getCellEdgeOffsets bits)
    std::vector<std::uint8_t> onFace; //!< per vertex: 1 for a face vertex (see numberCells)
    std::vector<glm::dvec3> local;    //!< per vertex, position relative to its cell, cells
    std::vector<glm::dvec3> normal;   //!< per vertex, unit
    std::vector<QefSystem> qef;       //!< per vertex, kept for the relaxation only

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

//! Pass 2: the case of every cell and its vertices, numbered in cell scan order.
//!
//! per_cell: one vertex per cell with a sign change, on all its crossed edges [Ju et al. 2002].
//! per_component: one vertex per surface patch of the cell, the patches being the loops of the
//! marching cubes case table under the asymptotic decider (framework/isosurface), as in Nielson's
//! Dual Marching Cubes [G. M. Nielson, "Dual Marching Cubes", IEEE Visualization 2004] and the
//! finest-level vertex clustering of Manifold Dual Contouring [S. Schaefer, T. Ju, J. Warren,
//! "Manifold Dual Contouring", IEEE TVCG 2007]. Face decisions depend on the face's values only,
//! so the two cells on a face split its crossed edges into the same segments. Where both cells'
//! patches cross a shared ambiguous face twice (a tunnel through the face), one vertex per patch
//! would join the two patches by a mesh edge that four quads use; instead each of the face's two
//! segments gets a vertex of its own on the face, owned by the lower cell and numbered after its
//! patch vertices, and the quads around the segment's edges pass through it (pentagons).
void numberCells(const Grid& grid, const EdgeTable& table, const ExtractionOptions& options,
                 CellVertices& vertices)
{
    const tables::CaseTable& caseTable = tables::CaseTable::getInstance();
    const bool perComponent = options.vertices == VertexMode::PerComponent;
    const glm::ivec3 cells(grid.cells(0), grid.cells(1), grid.cells(2));
    const SignRows& rows = table.rows;
    const std::size_t words = rows.words();
    vertices.words = words;
    vertices.rowsPerLayer = cells.y;
    vertices.active.resize(std::size_t(cells.z) * std::size_t(cells.y) * words);
    vertices.activeBase.resize(vertices.active.size());

    // Active cells, counted per cell layer.
    std::vector<std::uint64_t> layerActive(cells.z + 1, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, cells.z), [&](const tbb::blocked_range<int>& r) {
        for (int z = r.begin(); z != r.end(); ++z) {
            std::uint64_t count = 0;
            for (int y = 0; y < cells.y; ++y)
                for (std::size_t w = 0; w < words; ++w) {
                    const std::uint64_t bits = rows.getActiveCells(y, z, w);
                    vertices.active[(std::size_t(z) * cells.y + y) * words + w] = bits;
                    count += std::uint64_t(std::popcount(bits));
                }
            layerActive[z + 1] = count;
        }
    });
    for (int z = 0; z < cells.z; ++z)
        layerActive[z + 1] += layerActive[z];
    const std::uint64_t activeCount = layerActive[cells.z];
    if (activeCount >= kNone)
        throw std::length_error("dual_contouring: " + std::to_string(activeCount) +
                                " cells with a sign change exceed 32-bit indices");
    vertices.activeCell.resize(activeCount);
    vertices.cases.resize(activeCount);
    vertices.vertexOfCell.resize(activeCount);

    // Cases and patches.
    tbb::parallel_for(tbb::blocked_range<int>(0, cells.z), [&](const tbb::blocked_range<int>& r) {
        std::array<std::size_t, 8> corner{};
        for (int k = 0; k < 8; ++k)
            corner[k] = grid.index({k & 1, (k >> 1) & 1, (k >> 2) & 1});
        for (int z = r.begin(); z != r.end(); ++z) {
            std::uint32_t next = std::uint32_t(layerActive[z]);
            for (int y = 0; y < cells.y; ++y)
                for (std::size_t w = 0; w < words; ++w) {
                    const std::size_t k = (std::size_t(z) * cells.y + y) * words + w;
                    vertices.activeBase[k] = next;
                    for (std::uint64_t bits = vertices.active[k]; bits != 0; bits &= bits - 1) {
                        const int x = int(64 * w) + std::countr_zero(bits);
                        vertices.activeCell[next] = glm::ivec3(x, y, z);
                        CellCase& c = vertices.cases[next++];
                        const unsigned cube = rows.getCube(x, y, z);
                        c.cube = std::uint8_t(cube);
                        if (!perComponent) {
                            c.patches = 1;
                            continue;
                        }
                        const std::size_t base = grid.index({x, y, z});
                        std::array<double, 8> values;
                        for (int j = 0; j < 8; ++j)
                            values[j] = grid.relative(base + corner[j]);
                        c.joined = std::uint8_t(tables::decideJoinedFaces(
                            cube, values, tables::AmbiguityRule::Asymptotic));
                        const std::size_t entry = caseTable.entryIndex(cube, c.joined);
                        c.entry = std::uint16_t(entry);
                        c.patches = std::uint8_t(caseTable.entry(entry).loopCount);
                    }
                }
        }
    });

    // Faces that the patches on both sides cross twice, and the vertex count per cell layer.
    std::vector<std::uint64_t> layerCount(cells.z + 1, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, cells.z), [&](const tbb::blocked_range<int>& r) {
        for (int z = r.begin(); z != r.end(); ++z) {
            std::uint64_t count = 0;
            for (std::uint64_t i = layerActive[z]; i != layerActive[z + 1]; ++i) {
                CellCase& c = vertices.cases[i];
                count += c.patches;
                if (!perComponent)
                    continue;
                const unsigned doubled = caseTable.entry(c.entry).doubledFaces;
                for (int f = 0; f < tables::kFaceCount; ++f) {
                    if (((doubled >> f) & 1u) == 0)
                        continue;
                    glm::ivec3 other = vertices.activeCell[i];
                    other[f / 2] += (f & 1) ? 1 : -1;
                    if (other[f / 2] < 0 || other[f / 2] >= cells[f / 2])
                        continue;
                    const CellCase& n = vertices.getCase(other);
                    if ((caseTable.entry(n.entry).doubledFaces >> tables::getOppositeFace(f)) & 1u)
                        c.paired |= std::uint8_t(1u << f);
                }
                count += 2 * std::popcount(unsigned(c.paired & kHighFaces));
            }
            layerCount[z + 1] = count;
        }
    });
    for (int z = 0; z < cells.z; ++z)
        layerCount[z + 1] += layerCount[z];
    const std::uint64_t total = layerCount[cells.z];
    if (total >= kNone)
        throw std::length_error("dual_contouring: " + std::to_string(total) +
                                " vertices exceed 32-bit indices");
    vertices.cell.resize(total);
    vertices.edges.resize(total);
    vertices.onFace.assign(total, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, cells.z), [&](const tbb::blocked_range<int>& r) {
        for (int z = r.begin(); z != r.end(); ++z) {
            std::uint32_t next = std::uint32_t(layerCount[z]);
            for (std::uint64_t i = layerActive[z]; i != layerActive[z + 1]; ++i) {
                const CellCase& c = vertices.cases[i];
                const glm::ivec3 cell = vertices.activeCell[i];
                vertices.vertexOfCell[i] = next;
                if (!perComponent) {
                    vertices.cell[next] = cell;
                    vertices.edges[next++] = 0xfff;
                    continue;
                }
                const tables::CellTriangulation& entry = caseTable.entry(c.entry);
                for (int l = 0; l < entry.loopCount; ++l) {
                    vertices.cell[next] = cell;
                    vertices.edges[next++] = toCellEdgeMask(entry.loops[l]);
                }
                for (int f = 1; f < tables::kFaceCount; f += 2) {
                    if (((c.paired >> f) & 1u) == 0)
                        continue;
                    const bool joined = ((c.joined >> f) & 1u) != 0;
                    for (int segment = 0; segment < 2; ++segment) {
                        unsigned mask = 0;
                        for (const int e : tables::getCellFaces()[f].edges) {
                            if (tables::findFaceSegment(c.cube, f, joined, e) == segment)
                                mask |= 1u << e;
                        }
                        vertices.cell[next] = cell;
                        vertices.edges[next] = toCellEdgeMask(mask);
                        vertices.onFace[next++] = 1;
                    }
                }
            }
        }
    });
}

//! The vertex that the quads around the crossed grid edge (sample s, axis) use in `cell`.
std::uint32_t findEdgeVertex(const Grid& grid, const CellVertices& vertices,
                             const ExtractionOptions& options, const glm::ivec3& cell,
                             const glm::ivec3& s, int axis)
{
    const std::uint32_t k = vertices.findActive(cell);
    if (k == kNone)
        return kNone;
    const std::uint32_t first = vertices.vertexOfCell[k];
    if (options.vertices == VertexMode::PerCell)
        return first;
    const auto& entry = tables::CaseTable::getInstance().entry(vertices.cases[k].entry);
    return first + std::uint32_t(entry.edgeLoop[getTableEdge(s - cell, axis)]);
}

//! The face vertex between `cell` and its neighbour `other` (one step along one axis) for the
//! segment holding the crossed grid edge (sample s, axis), or kNone when that face has none.
std::uint32_t findFaceVertex(const Grid& grid, const CellVertices& vertices, glm::ivec3 cell,
                             glm::ivec3 other, const glm::ivec3& s, int axis)
{
    int normalAxis = 0;
    while (cell[normalAxis] == other[normalAxis])
        ++normalAxis;
    if (other[normalAxis] < cell[normalAxis])
        std::swap(cell, other);
    const std::uint32_t k = vertices.findActive(cell);
    if (k == kNone)
        return kNone;
    const CellCase& c = vertices.cases[k];
    const int face = 2 * normalAxis + 1;
    if (((c.paired >> face) & 1u) == 0)
        return kNone;
    const int segment = tables::findFaceSegment(c.cube, face, ((c.joined >> face) & 1u) != 0,
                                                getTableEdge(s - cell, axis));
    const unsigned before = unsigned(c.paired & kHighFaces) & ((1u << face) - 1u);
    return vertices.vertexOfCell[k] + c.patches + 2u * std::popcount(before) +
           std::uint32_t(segment);
}

bool isInsideBox(const glm::dvec3& p)
{
    for (int axis = 0; axis < 3; ++axis) {
        if (!(p[axis] >= -kOutsideTolerance && p[axis] <= 1.0 + kOutsideTolerance))
            return false;
    }
    return true;
}

//! Pass 3: one QEF vertex per cell or patch [Ju et al. 2002, sec. 2.2], from the crossings of its
//! own edges only, in the cell's frame (its lowest sample at the origin, the box [0, 1]^3). A face
//! vertex is the midpoint of its segment's two crossings, which lies on the face.
void placeVertices(const Grid& grid, const EdgeTable& table, const ExtractionOptions& options,
                   bool keepQef, CellVertices& vertices, ExtractionStats& stats)
{
    const std::size_t count = vertices.cell.size();
    vertices.local.assign(count, glm::dvec3(0.0));
    vertices.normal.assign(count, glm::dvec3(0.0));
    if (keepQef)
        vertices.qef.assign(count, QefSystem{});
    std::vector<std::uint8_t> rank(count, 0);
    std::vector<std::uint8_t> left(count, 0);
    std::vector<std::uint8_t> skipped(count, 0);
    std::vector<std::uint8_t> noPlanes(count, 0);
    const auto& cellEdges = getCellEdgeOffsets();

    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, count),
        [&](const tbb::blocked_range<std::size_t>& range) {
            std::array<glm::dvec3, 12> points;
            std::array<glm::dvec3, 12> normals;
            for (std::size_t v = range.begin(); v != range.end(); ++v) {
                const glm::ivec3 cell = vertices.cell[v];
                int n = 0;
                glm::dvec3 normalSum(0.0);
                for (int k = 0; k < 12; ++k) {
                    if (((vertices.edges[v] >> k) & 1u) == 0)
                        continue;
                    const CellEdgeOffset& e = cellEdges[k];
                    const std::uint32_t id = table.find(cell + e.offset, e.axis);
                    if (id == kNone)
                        continue;
                    const Crossing& c = table.crossings[id];
                    points[n] = c.point - glm::dvec3(cell);
                    normals[n] = c.normal;
                    normalSum += c.normal;
                    ++n;
                }
                if (vertices.onFace[v]) {
                    glm::dvec3 mid(0.0);
                    for (int i = 0; i < n; ++i)
                        mid += points[i];
                    vertices.local[v] = mid / double(std::max(n, 1));
                    glm::dvec3 normal = normalizeOrZero(normalSum);
                    vertices.normal[v] =
                        normal == glm::dvec3(0.0) ? glm::dvec3(0.0, 0.0, 1.0) : normal;
                    continue;
                }
                int skippedHere = 0;
                const QefSystem qef = buildQef(std::span(points.data(), n),
                                               std::span(normals.data(), n), &skippedHere);
                skipped[v] = std::uint8_t(skippedHere);
                QefSolution solution;
                if (options.solver == QefSolver::Svd) {
                    solution = solveQefSvd(qef, options.svdThreshold);
                } else {
                    const glm::dvec3 start = options.schmitzStart == SchmitzStart::MassPoint
                                                 ? qef.massPoint
                                                 : glm::dvec3(0.5);
                    solution =
                        solveQefSchmitz(qef, start, options.schmitzIterations, options.schmitzStep);
                }
                glm::dvec3 p = solution.position;
                if (qef.planeCount == 0) {
                    noPlanes[v] = 1;
                    p = qef.massPoint;
                }
                if (!isFinite(p))
                    p = qef.massPoint;
                if (!isInsideBox(p)) {
                    left[v] = 1;
                    switch (options.outsidePolicy) {
                    case OutsidePolicy::Clamp:
                        p = glm::clamp(p, glm::dvec3(0.0), glm::dvec3(1.0));
                        break;
                    case OutsidePolicy::MassPoint:
                        p = qef.massPoint;
                        break;
                    case OutsidePolicy::Keep:
                        break;
                    }
                }
                vertices.local[v] = p;
                rank[v] = std::uint8_t(solution.rank);
                if (keepQef)
                    vertices.qef[v] = qef;
                if (options.computeNormals) {
                    glm::dvec3 normal = normalizeOrZero(normalSum);
                    if (normal == glm::dvec3(0.0)) {
                        // No usable crossing normal: the sampled field's gradient over the cell.
                        glm::dvec3 gradient(0.0);
                        for (int k = 0; k < 8; ++k)
                            gradient += grid.sampleGradient(
                                cell + glm::ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1));
                        normal = normalizeOrZero(gradient);
                    }
                    if (normal == glm::dvec3(0.0))
                        normal = glm::dvec3(0.0, 0.0, 1.0);
                    vertices.normal[v] = normal;
                }
            }
        });
    for (std::size_t v = 0; v < count; ++v) {
        if (vertices.onFace[v])
            continue;
        ++stats.rank[std::min<int>(rank[v], 3)];
        stats.leftCell += left[v];
        stats.skippedNormals += skipped[v];
        stats.cellsWithoutPlanes += noPlanes[v];
    }
}

//! Elastic relaxation of the vertices on material boundaries, as The Tomorrow Children does it
//! (seed 000_3da000e866ebc485.txt, "Polygonization / Dual Contouring": every quad takes the
//! material of the edge it crosses, which gives blocky transitions, so "whenever a DC vertex is
//! involved in DC quads of different materials, we relax/average it with DC vertices around (in
//! an elastic mesh fashion), we make sure they don't move outside their DC cube").
class MaterialRelaxation {
public:
    MaterialRelaxation(const Grid& grid, const EdgeTable& table,
                       const std::vector<std::uint32_t>& materials,
                       const ExtractionOptions& options, const CrossingSource& source,
                       const plugin::IsosurfaceInput& input, CellVertices& vertices)
        : mGrid(grid), mTable(table), mMaterials(materials), mOptions(options), mSource(source),
          mInput(input), mVertices(vertices)
    {
    }

    //! Finds the boundary vertices and their boundary neighbours; returns their count.
    std::size_t findBoundary()
    {
        const std::size_t count = mVertices.cell.size();
        mBoundary.assign(count, 0);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t v = range.begin(); v != range.end(); ++v)
                                  mBoundary[v] = !mVertices.onFace[v] && hasMixedQuads(v);
                          });
        mNeighbourStart.assign(count + 1, 0);
        std::vector<std::uint32_t> found(kMaxNeighbours * count);
        std::vector<std::uint8_t> foundCount(count, 0);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count),
                          [&](const tbb::blocked_range<std::size_t>& range) {
                              for (std::size_t v = range.begin(); v != range.end(); ++v) {
                                  if (mBoundary[v])
                                      foundCount[v] = std::uint8_t(
                                          findBoundaryNeighbours(v, &found[kMaxNeighbours * v]));
                              }
                          });
        for (std::size_t v = 0; v < count; ++v)
            mNeighbourStart[v + 1] = mNeighbourStart[v] + foundCount[v];
        mNeighbours.resize(mNeighbourStart[count]);
        for (std::size_t v = 0; v < count; ++v)
            std::copy_n(found.begin() + kMaxNeighbours * v, foundCount[v],
                        mNeighbours.begin() + mNeighbourStart[v]);
        std::size_t boundary = 0;
        for (std::uint8_t b : mBoundary)
            boundary += b;
        return boundary;
    }

    //! Runs the iterations (Jacobi order, so the result does not depend on the thread count);
    //! returns the largest displacement of a vertex, cells.
    double relax(int iterations)
    {
        const std::size_t count = mVertices.cell.size();
        const std::vector<glm::dvec3> initial = mVertices.local;
        std::vector<glm::dvec3> next = mVertices.local;
        for (int it = 0; it < iterations; ++it) {
            tbb::parallel_for(
                tbb::blocked_range<std::size_t>(0, count),
                [&](const tbb::blocked_range<std::size_t>& range) {
                    for (std::size_t v = range.begin(); v != range.end(); ++v) {
                        const std::uint32_t first = mNeighbourStart[v];
                        const std::uint32_t last = mNeighbourStart[v + 1];
                        if (!mBoundary[v] || first == last) {
                            next[v] = mVertices.local[v];
                            continue;
                        }
                        // Laplacian step toward the mean of the boundary neighbours, in the
                        // vertex's cell frame.
                        const glm::ivec3 cell = mVertices.cell[v];
                        glm::dvec3 mean(0.0);
                        for (std::uint32_t k = first; k < last; ++k) {
                            const std::uint32_t u = mNeighbours[k];
                            mean += mVertices.local[u] + glm::dvec3(mVertices.cell[u] - cell);
                        }
                        mean /= double(last - first);
                        // "we make sure they don't move outside their DC cube": a step whose
                        // projection leaves the cell is halved (up to kMaxStepHalvings times), else
                        // the vertex stays, so relaxed vertices are on the surface and in their
                        // cell.
                        const glm::dvec3 p = mVertices.local[v];
                        double weight = mOptions.materialRelaxationWeight;
                        next[v] = p;
                        for (int k = 0; k <= kMaxStepHalvings; ++k, weight *= 0.5) {
                            const glm::dvec3 target = project(v, p + weight * (mean - p));
                            if (isFinite(target) && isInsideBox(target)) {
                                next[v] = target;
                                break;
                            }
                        }
                    }
                });
            mVertices.local.swap(next);
        }
        double shift = 0.0;
        for (std::size_t v = 0; v < count; ++v)
            shift = std::max(shift, glm::length(mVertices.local[v] - initial[v]));
        return shift;
    }

private:
    //! Material of the quad around a crossed edge: the material of its inside sample.
    std::uint32_t getEdgeMaterial(const glm::ivec3& s, int axis) const
    {
        const std::size_t sample = mGrid.index(s);
        const bool lowInside = mTable.isInside(s);
        return mMaterials[lowInside ? sample : sample + mGrid.stride(axis)];
    }

    //! Whether the quads of the vertex's crossed interior edges carry more than one material.
    bool hasMixedQuads(std::size_t v) const
    {
        bool any = false;
        std::uint32_t material = 0;
        for (int k = 0; k < 12; ++k) {
            if (((mVertices.edges[v] >> k) & 1u) == 0)
                continue;
            const CellEdgeOffset& e = getCellEdgeOffsets()[k];
            const glm::ivec3 s = mVertices.cell[v] + e.offset;
            if (mTable.find(s, e.axis) == kNone || !isInteriorEdge(mGrid, s, e.axis))
                continue;
            const std::uint32_t m = getEdgeMaterial(s, e.axis);
            if (any && m != material)
                return true;
            any = true;
            material = m;
        }
        return false;
    }

    //! Boundary vertices joined to v by a quad side: for each face of v's cell, the vertices of
    //! the neighbour cell that the quads around v's crossed interior edges on that face use
    //! (faces with face vertices join v to those instead, which are not relaxed).
    int findBoundaryNeighbours(std::size_t v, std::uint32_t* out) const
    {
        const glm::ivec3 cell = mVertices.cell[v];
        int n = 0;
        for (int axis = 0; axis < 3; ++axis) {
            for (int side = -1; side <= 1; side += 2) {
                glm::ivec3 other = cell;
                other[axis] += side;
                if (other[axis] < 0 || other[axis] >= mGrid.cells(axis))
                    continue;
                for (int k = 0; k < 12; ++k) {
                    const CellEdgeOffset& e = getCellEdgeOffsets()[k];
                    if (((mVertices.edges[v] >> k) & 1u) == 0 || e.axis == axis ||
                        e.offset[axis] != (side > 0 ? 1 : 0))
                        continue;
                    const glm::ivec3 s = cell + e.offset;
                    if (mTable.find(s, e.axis) == kNone ||
                        !isInteriorEdge(mGrid, s, e.axis) ||
                        findFaceVertex(mGrid, mVertices, cell, other, s, e.axis) != kNone)
                        continue;
                    const std::uint32_t u =
                        findEdgeVertex(mGrid, mVertices, mOptions, other, s, e.axis);
                    if (u == kNone || !mBoundary[u] || std::find(out, out + n, u) != out + n)
                        continue;
                    out[n++] = u;
                }
            }
        }
        return n;
    }

    //! Back onto the surface: Newton steps on the exact field when there is one, else the QEF
    //! minimiser nearest to the point (moves only along the cell's constrained directions).
    glm::dvec3 project(std::size_t v, glm::dvec3 p) const
    {
        const glm::dvec3 cell(mVertices.cell[v]);
        if (mSource.hasExactProjection()) {
            for (int k = 0; k < kProjectionSteps; ++k) {
                const glm::dvec3 world = mGrid.toWorld(cell + p);
                const double f = mInput.exactValue(world) - mGrid.iso();
                const glm::dvec3 g = mInput.exactGradient(world);
                const double g2 = glm::dot(g, g);
                if (!std::isfinite(f) || !std::isfinite(g2) || !(g2 > 0.0))
                    break;
                p -= (f / g2) * g / mGrid.spacing();
                if (std::abs(f) <= 1e-12 * mGrid.spacing())
                    break;
            }
            return p;
        }
        return solveQefNear(mVertices.qef[v], p, mOptions.svdThreshold).position;
    }

    const Grid& mGrid;
    const EdgeTable& mTable;
    const std::vector<std::uint32_t>& mMaterials;
    const ExtractionOptions& mOptions;
    const CrossingSource& mSource;
    const plugin::IsosurfaceInput& mInput;
    CellVertices& mVertices;
    std::vector<std::uint8_t> mBoundary;
    std::vector<std::uint32_t> mNeighbourStart;
    std::vector<std::uint32_t> mNeighbours;
};

//! Splits quad (v0, v1, v2, v3) into two triangles. Rule: the diagonal whose two triangles'
//! unit normals agree best (largest dot product), which never folds a planar non-convex quad and
//! follows the crease of a bent one; a tie (|difference| <= 1e-12, e.g. planar convex quads)
//! takes the diagonal through the quad's smallest vertex index, which does not depend on where
//! the quad's cycle starts. Returns true for the diagonal v1-v3.
bool chooseDiagonal13(const std::array<std::uint32_t, 4>& q, const std::array<glm::dvec3, 4>& p)
{
    const auto normal = [&](int a, int b, int c) {
        return normalizeOrZero(glm::cross(p[b] - p[a], p[c] - p[a]));
    };
    const double agree02 = glm::dot(normal(0, 1, 2), normal(0, 2, 3));
    const double agree13 = glm::dot(normal(0, 1, 3), normal(1, 2, 3));
    if (std::abs(agree02 - agree13) > 1e-12)
        return agree13 > agree02;
    const int smallest = int(std::min_element(q.begin(), q.end()) - q.begin());
    return smallest % 2 == 1;
}

} // namespace

void extractDualContour(const plugin::IsosurfaceInput& input, const ExtractionOptions& options,
                        TriangleMesh& out, ExtractionStats& stats)
{
    validate(input);
    stats = ExtractionStats{};
    const plugin::SampledField& field = *input.field;
    const Grid grid(field, input.isoValue);
    const CrossingSource source(grid, input, options);
    stats.source = source.source();
    if (field.samples.x < 2 || field.samples.y < 2 || field.samples.z < 2) {
        out.clear();
        return;
    }

    std::size_t firstNan = SignRows::kNoNan;
    EdgeTable table(SignRows(field, input.isoValue, firstNan));
    if (firstNan != SignRows::kNoNan) {
        const glm::ivec3 s = grid.sampleOf(firstNan);
        throw std::invalid_argument("dual_contouring: NaN sample at (" + std::to_string(s.x) +
                                    ", " + std::to_string(s.y) + ", " + std::to_string(s.z) +
                                    ")");
    }
    buildEdgeTable(grid, table);
    const std::size_t edgeCount = table.edges.size();
    stats.crossedEdges = edgeCount;

    // Hermite data [Ju et al. 2002, sec. 2]: one crossing and normal per crossed edge.
    table.crossings.resize(edgeCount);
    std::atomic<std::size_t> missing{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, edgeCount),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          std::size_t missingHere = 0;
                          for (std::size_t k = range.begin(); k != range.end(); ++k) {
                              const std::size_t sample = std::size_t(table.edges[k] / 3u);
                              const int axis = int(table.edges[k] % 3u);
                              bool edgeMissing = false;
                              table.crossings[k] =
                                  source.compute(grid.sampleOf(sample), axis, edgeMissing);
                              missingHere += edgeMissing;
                          }
                          missing += missingHere;
                      });
    stats.hermiteMissing = missing.load();

    CellVertices vertices;
    numberCells(grid, table, options, vertices);
    const bool relaxing = input.materials != nullptr && options.materialRelaxationIterations > 0;
    placeVertices(grid, table, options, relaxing && !source.hasExactProjection(), vertices, stats);
    stats.vertices = vertices.cell.size();
    for (const CellCase& c : vertices.cases) {
        stats.cells += c.patches > 0;
        stats.multiVertexCells += c.patches > 1;
        stats.patchVertices += c.patches;
    }
    stats.faceVertices = stats.vertices - stats.patchVertices;

    if (input.materials != nullptr) {
        MaterialRelaxation relaxation(grid, table, *input.materials, options, source, input,
                                      vertices);
        stats.boundaryVertices = relaxation.findBoundary();
        if (relaxing)
            stats.maxRelaxationShift = relaxation.relax(options.materialRelaxationIterations);
    }

    // One quad per crossed edge with four cells around it [Ju et al. 2002, sec. 2.1], wound
    // counter-clockwise seen from the outside: when the edge's low end is inside the outward
    // normal points along +axis, and the cells come counter-clockwise seen from +axis.
    // A quad side between two cells whose patches both cross their shared face twice passes
    // through the face vertex of the edge's segment (see numberCells); such polygons are fanned
    // around their first face vertex.
    // Edges are cut into fixed chunks, each writing its triangles to a list of its own; the lists
    // are concatenated in chunk order, so the triangle order is the edge order whatever the
    // thread count.
    constexpr std::size_t kChunk = 8192;
    struct ChunkOutput {
        std::vector<std::uint32_t> indices;
        std::size_t quads = 0;
        std::size_t flipped = 0;
    };
    std::vector<ChunkOutput> chunks((edgeCount + kChunk - 1) / kChunk);
    tbb::parallel_for(std::size_t(0), chunks.size(), [&](std::size_t chunk) {
        ChunkOutput& result = chunks[chunk];
        result.indices.reserve(6 * kChunk);
        const std::size_t end = std::min(edgeCount, (chunk + 1) * kChunk);
        for (std::size_t k = chunk * kChunk; k != end; ++k) {
            const std::size_t sample = std::size_t(table.edges[k] / 3u);
            const int axis = int(table.edges[k] % 3u);
            const glm::ivec3 s = grid.sampleOf(sample);
            if (!isInteriorEdge(grid, s, axis))
                continue;
            const std::array<glm::ivec3, 4> cells = getCellsAroundEdge(s, axis);
            const bool lowInside = table.isInside(s);
            std::array<glm::ivec3, 4> around;
            std::array<std::uint32_t, 4> q;
            std::array<glm::dvec3, 4> p;
            for (int c = 0; c < 4; ++c) {
                around[c] = cells[lowInside ? c : (4 - c) % 4];
                q[c] = findEdgeVertex(grid, vertices, options, around[c], s, axis);
                p[c] = glm::dvec3(around[c] - s) + vertices.local[q[c]];
            }
            ++result.quads;
            std::array<std::uint32_t, 8> polygon;
            int size = 0;
            int firstFace = -1;
            for (int c = 0; c < 4; ++c) {
                polygon[size++] = q[c];
                if (options.vertices == VertexMode::PerCell)
                    continue;
                const std::uint32_t f =
                    findFaceVertex(grid, vertices, around[c], around[(c + 1) % 4], s, axis);
                if (f == kNone)
                    continue;
                if (firstFace < 0)
                    firstFace = size;
                polygon[size++] = f;
            }
            auto& out = result.indices;
            if (firstFace >= 0) {
                for (int i = 1; i + 1 < size; ++i)
                    out.insert(out.end(), {polygon[firstFace], polygon[(firstFace + i) % size],
                                           polygon[(firstFace + i + 1) % size]});
            } else if (chooseDiagonal13(q, p)) {
                ++result.flipped;
                out.insert(out.end(), {q[0], q[1], q[3], q[1], q[2], q[3]});
            } else {
                out.insert(out.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
            }
        }
    });

    // Nothing below throws std::invalid_argument, so the mesh is built in `out` itself, reusing
    // its storage from the last call (as the vtk_flying_edges wrapper does).
    out.clear();
    const std::size_t vertexCount = vertices.cell.size();
    out.positions.resize(vertexCount);
    if (options.computeNormals)
        out.normals.resize(vertexCount);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertexCount),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t v = range.begin(); v != range.end(); ++v) {
                              out.positions[v] = glm::vec3(grid.toWorld(
                                  glm::dvec3(vertices.cell[v]) + vertices.local[v]));
                              if (options.computeNormals)
                                  out.normals[v] = glm::vec3(vertices.normal[v]);
                          }
                      });
    std::vector<std::size_t> firstIndex(chunks.size() + 1, 0);
    for (std::size_t c = 0; c < chunks.size(); ++c) {
        firstIndex[c + 1] = firstIndex[c] + chunks[c].indices.size();
        stats.quads += chunks[c].quads;
        stats.flippedSplits += chunks[c].flipped;
    }
    out.indices.resize(firstIndex.back());
    tbb::parallel_for(std::size_t(0), chunks.size(), [&](std::size_t c) {
        std::copy(chunks[c].indices.begin(), chunks[c].indices.end(),
                  out.indices.begin() + std::ptrdiff_t(firstIndex[c]));
    });
}

} // namespace rtlab::isosurface::dc
