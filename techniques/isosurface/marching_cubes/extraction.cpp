#include "extraction.h"

#include "case_table.h"
#include "isosurface/sign_rows.h"

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace rtlab::isosurface::mc {
namespace {

//! Read-only view of the field shared by both passes.
class Grid {
public:
    Grid(const plugin::SampledField& field, double isoValue)
        : mField(field), mIso(isoValue),
          mSize(field.samples), mStride{1, std::size_t(field.samples.x),
                                        std::size_t(field.samples.x) * field.samples.y}
    {
    }

    int size(int axis) const { return mSize[axis]; }
    std::size_t stride(int axis) const { return mStride[axis]; }
    std::size_t index(int x, int y, int z) const { return mField.index(x, y, z); }
    std::size_t layerSize() const { return mStride[2]; }
    //! Value relative to the iso-value. Its sign is exact: a double difference is zero only when
    //! the operands are equal, so f < iso exactly when relative(f) < 0.
    double relative(std::size_t i) const { return double(mField.values[i]) - mIso; }
    const plugin::SampledField& field() const { return mField; }

private:
    const plugin::SampledField& mField;
    double mIso;
    glm::ivec3 mSize;
    std::size_t mStride[3];
};

//! Vertex index of every crossed edge starting in one sample layer, per axis, indexed y * nx + x.
//! Entries of edges that are not crossed are stale; the case table never asks for them.
struct LayerVertices {
    std::unique_ptr<std::uint32_t[]> edge[3]; // left uninitialised: only crossed edges are read

    explicit LayerVertices(std::size_t layerSize)
    {
        for (auto& e : edge)
            e = std::make_unique_for_overwrite<std::uint32_t[]>(layerSize);
    }
};

//! Field gradient at a sample, in field units per sample step: central differences inside the
//! grid, one-sided on its boundary.
glm::dvec3 computeGradient(const Grid& grid, int x, int y, int z)
{
    const std::size_t i = grid.index(x, y, z);
    if (x > 0 && y > 0 && z > 0 && x + 1 < grid.size(0) && y + 1 < grid.size(1) &&
        z + 1 < grid.size(2)) {
        // Inside the grid (nearly every vertex): the same differences without the per-axis tests.
        const std::size_t sy = grid.stride(1);
        const std::size_t sz = grid.stride(2);
        return {0.5 * (grid.relative(i + 1) - grid.relative(i - 1)),
                0.5 * (grid.relative(i + sy) - grid.relative(i - sy)),
                0.5 * (grid.relative(i + sz) - grid.relative(i - sz))};
    }
    const int coord[3] = {x, y, z};
    glm::dvec3 gradient(0.0);
    for (int axis = 0; axis < 3; ++axis) {
        const std::size_t step = grid.stride(axis);
        const int c = coord[axis];
        const int n = grid.size(axis);
        if (c > 0 && c + 1 < n)
            gradient[axis] = 0.5 * (grid.relative(i + step) - grid.relative(i - step));
        else if (c == 0)
            gradient[axis] = grid.relative(i + step) - grid.relative(i);
        else
            gradient[axis] = grid.relative(i) - grid.relative(i - step);
    }
    return gradient;
}

//! A vertex before it is stored: world position and unit normal, in double.
struct Vertex {
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0};
};

//! What one slab produces besides the edge vertices it writes in place.
struct SlabOutput {
    //! Three per triangle. Edge vertices carry their final index; interior vertices carry
    //! kInteriorFlag | their index in `interior`, fixed up once every slab's count is known.
    std::vector<std::uint32_t> triangles;
    std::vector<Vertex> interior;
};

constexpr std::uint32_t kInteriorFlag = 0x80000000u;

class Mesher {
public:
    Mesher(const Grid& grid, const ExtractionOptions& options, const SignRows& rows,
           const std::vector<std::uint64_t>& layerOffset, TriangleMesh& mesh)
        : mGrid(grid), mOptions(options), mRows(rows), mLayerOffset(layerOffset), mMesh(mesh),
          mTable(CaseTable::getInstance())
    {
        for (int c = 0; c < kCornerCount; ++c)
            mCornerOffset[c] =
                grid.index(getCornerBit(c, 0), getCornerBit(c, 1), getCornerBit(c, 2));
    }

    //! Meshes cell layers [z0, z1): writes the edge vertices of the sample layers it owns and
    //! appends its triangles, in cell scan order, to `out`. `lower` and `upper` are scratch of
    //! layerSize() entries per axis; their contents on entry do not matter.
    void meshSlab(int z0, int z1, LayerVertices& lower, LayerVertices& upper,
                  SlabOutput& out) const
    {
        const int lastLayer = mGrid.size(2) - 1;
        // A slab owns the vertices of sample layers z0 .. z1 - 1 (and the top layer if it is the
        // last slab). It numbers layer z1 too, for its top cells, but the next slab writes it.
        // A closed surface has about two triangles per edge vertex: reserve that many indices.
        out.triangles.reserve(6 * (mLayerOffset[z1 + 1] - mLayerOffset[z0]));
        numberLayer(z0, lower, true);
        for (int z = z0; z < z1; ++z) {
            numberLayer(z + 1, upper, z + 1 < z1 || z + 1 == lastLayer);
            meshCellLayer(z, lower, upper, out);
            std::swap(lower, upper);
        }
    }

private:
    void numberLayer(int z, LayerVertices& layer, bool writeVertices) const
    {
        std::uint64_t next = mLayerOffset[z];
        const std::size_t nx = std::size_t(mGrid.size(0));
        mRows.visitCrossedEdges(z, [&](int x, int y, int axis) {
            const auto index = static_cast<std::uint32_t>(next++);
            layer.edge[axis][std::size_t(y) * nx + x] = index;
            if (!writeVertices)
                return;
            const Vertex vertex = computeEdgeVertex(x, y, z, axis);
            mMesh.positions[index] = glm::vec3(vertex.position);
            if (mOptions.computeNormals)
                mMesh.normals[index] = glm::vec3(vertex.normal);
        });
        assert(next == mLayerOffset[z + 1]);
    }

    //! The vertex on the crossed edge from sample (x, y, z) along `axis`. A pure function of the
    //! samples, so a cell can recompute a vertex that another slab writes.
    Vertex computeEdgeVertex(int x, int y, int z, int axis) const
    {
        const std::size_t a = mGrid.index(x, y, z);
        const std::size_t b = a + mGrid.stride(axis);
        const double valueA = mGrid.relative(a);
        const double valueB = mGrid.relative(b);
        const bool insideA = valueA < 0.0;

        double s = 0.5; // parameter from sample a toward sample b
        if (mOptions.placement == VertexPlacement::Linear) {
            // [Lorensen & Cline 1987] the crossing of the linear interpolant along the edge.
            // t runs from the inside end (< 0) to the outside end (>= 0); t = 1 exactly when the
            // outside end is exactly on the iso-value, so the vertex lands on that sample.
            const double in = insideA ? valueA : valueB;
            const double out = insideA ? valueB : valueA;
            double t;
            if (std::isinf(in) && std::isinf(out))
                t = 0.5;
            else if (std::isinf(in))
                t = 1.0; // the limit of in / (in - out) as in -> -inf
            else if (std::isinf(out))
                t = 0.0; // the limit as out -> +inf
            else
                t = std::clamp(in / (in - out), 0.0, 1.0);
            s = insideA ? t : 1.0 - t;
        }
        // Grid coordinates are integers plus s, so a vertex at s = 0 or 1 is exactly the sample.
        glm::dvec3 coord(x, y, z);
        coord[axis] += s;
        const plugin::SampledField& field = mGrid.field();
        Vertex vertex;
        vertex.position = field.origin + field.spacing * coord;
        if (!mOptions.computeNormals)
            return vertex;
        const glm::dvec3 gradient =
            (1.0 - s) * computeGradient(mGrid, x, y, z) +
            s * computeGradient(mGrid, x + (axis == 0), y + (axis == 1), z + (axis == 2));
        const double length = glm::length(gradient);
        if (std::isfinite(length) && length > 0.0) {
            vertex.normal = gradient / length;
        } else {
            // Flat or non-finite neighbourhood: the field increases from the inside end of the
            // edge to the outside end, so that direction is outward.
            vertex.normal[axis] = insideA ? 1.0 : -1.0;
        }
        return vertex;
    }

    //! The interior vertex of a loop in cell (x, y, z): the centroid of the loop's edge vertices,
    //! with their mean normal (or, where that cancels, the normal of the loop's fan).
    Vertex computeInteriorVertex(int x, int y, int z, const CellTriangulation& cell,
                                 int extra) const
    {
        const auto& edges = getCellEdges();
        Vertex loopVertices[kEdgeCount];
        int count = 0;
        Vertex vertex;
        for (int e = 0; e < kEdgeCount; ++e) {
            if (((cell.extraLoops[extra] >> e) & 1u) == 0)
                continue;
            const CellEdge& edge = edges[e];
            loopVertices[e] =
                computeEdgeVertex(x + getCornerBit(edge.start, 0), y + getCornerBit(edge.start, 1),
                                  z + getCornerBit(edge.start, 2), edge.axis);
            vertex.position += loopVertices[e].position;
            vertex.normal += loopVertices[e].normal;
            ++count;
        }
        vertex.position /= double(count);
        if (!mOptions.computeNormals)
            return vertex;
        double length = glm::length(vertex.normal);
        if (!(length > 1e-12)) {
            vertex.normal = glm::dvec3(0.0);
            for (int t = 0; t < cell.triangleCount; ++t) {
                if (cell.vertices[3 * t] != kExtraVertex + extra)
                    continue; // the fan's triangles start at the interior vertex
                const glm::dvec3 b = loopVertices[cell.vertices[3 * t + 1]].position;
                const glm::dvec3 c = loopVertices[cell.vertices[3 * t + 2]].position;
                vertex.normal += glm::cross(b - vertex.position, c - vertex.position);
            }
            length = glm::length(vertex.normal);
        }
        if (length > 0.0 && std::isfinite(length)) {
            vertex.normal /= length;
        } else {
            // Degenerate loop (all its vertices on one point): any loop vertex's normal is unit.
            const int first = std::countr_zero(unsigned(cell.extraLoops[extra]));
            vertex.normal = loopVertices[first].normal;
        }
        return vertex;
    }

    //! Compact decision bits for the ambiguous faces of a cell (see CaseTable::find).
    unsigned decideFaces(unsigned cube, std::size_t base) const
    {
        const unsigned ambiguous = mTable.ambiguousFaces(cube);
        if (ambiguous == 0)
            return 0;
        std::array<double, kCornerCount> values;
        for (int c = 0; c < kCornerCount; ++c)
            values[c] = mGrid.relative(base + mCornerOffset[c]);
        return CaseTable::packDecisions(ambiguous,
                                        decideJoinedFaces(cube, values, mOptions.ambiguity));
    }

    void meshCellLayer(int z, const LayerVertices& lower, const LayerVertices& upper,
                       SlabOutput& out) const
    {
        for (int y = 0; y + 1 < mGrid.size(1); ++y)
            for (std::size_t w = 0; w < mRows.words(); ++w)
                for (std::uint64_t bits = mRows.getActiveCells(y, z, w); bits != 0;
                     bits &= bits - 1) {
                    const int x = int(64 * w) + std::countr_zero(bits);
                    // [Lorensen & Cline 1987] the case index from the signs of the eight corners.
                    meshCell(x, y, z, mRows.getCube(x, y, z), lower, upper, out);
                }
    }

    void meshCell(int x, int y, int z, unsigned cube, const LayerVertices& lower,
                  const LayerVertices& upper, SlabOutput& out) const
    {
        const int nx = mGrid.size(0);
        const auto& edges = getCellEdges();
        const std::size_t base = mGrid.index(x, y, z);
        const CellTriangulation& cell = mTable.find(cube, decideFaces(cube, base));
        std::uint32_t interior[kMaxCellExtras];
        for (int j = 0; j < cell.extraCount; ++j) {
            interior[j] = kInteriorFlag | std::uint32_t(out.interior.size());
            out.interior.push_back(computeInteriorVertex(x, y, z, cell, j));
        }
        for (int k = 0; k < 3 * cell.triangleCount; ++k) {
            const int id = cell.vertices[k];
            if (id >= kExtraVertex) {
                out.triangles.push_back(interior[id - kExtraVertex]);
                continue;
            }
            const CellEdge& edge = edges[id];
            const LayerVertices& layer = getCornerBit(edge.start, 2) ? upper : lower;
            const std::size_t column = std::size_t(y + getCornerBit(edge.start, 1)) * nx +
                                       std::size_t(x + getCornerBit(edge.start, 0));
            out.triangles.push_back(layer.edge[edge.axis][column]);
        }
    }

    const Grid& mGrid;
    const ExtractionOptions& mOptions;
    const SignRows& mRows;
    const std::vector<std::uint64_t>& mLayerOffset;
    TriangleMesh& mMesh;
    const CaseTable& mTable;
    std::size_t mCornerOffset[kCornerCount];
};

void validateField(const plugin::SampledField& field)
{
    if (!(std::isfinite(field.spacing) && field.spacing > 0.0))
        throw std::invalid_argument(
            "marching_cubes: the field spacing must be finite and > 0, got " +
            std::to_string(field.spacing));
    if (!(std::isfinite(field.origin.x) && std::isfinite(field.origin.y) &&
          std::isfinite(field.origin.z)))
        throw std::invalid_argument("marching_cubes: the field origin must be finite");
    const std::size_t expected =
        std::size_t(field.samples.x) * std::size_t(field.samples.y) * std::size_t(field.samples.z);
    if (field.values.size() != expected)
        throw std::invalid_argument(
            "marching_cubes: the field has " + std::to_string(field.values.size()) +
            " values for " + std::to_string(field.samples.x) + " x " +
            std::to_string(field.samples.y) + " x " + std::to_string(field.samples.z) + " samples");
}

} // namespace

void extractIsosurface(const plugin::SampledField& field, double isoValue,
                       const ExtractionOptions& options, TriangleMesh& out)
{
    if (!std::isfinite(isoValue))
        throw std::invalid_argument("marching_cubes: the iso-value must be finite, got " +
                                    std::to_string(isoValue));
    if (field.samples.x < 2 || field.samples.y < 2 || field.samples.z < 2) {
        out.clear(); // no cell, no surface
        return;
    }
    validateField(field);

    const Grid grid(field, isoValue);
    const int nz = grid.size(2);
    const int grain = std::max(options.grain, 1);

    // Pass 1, per sample layer: the inside bits of every row (framework/isosurface/sign_rows.h:
    // the grid walk follows Flying Edges [Schroeder, Maynard & Geveci 2015], touching only the
    // rows and cells the surface crosses) and the NaN check.
    std::size_t firstNan = SignRows::kNoNan;
    const SignRows rows(field, isoValue, firstNan);
    if (firstNan != SignRows::kNoNan) {
        const std::size_t nx = std::size_t(grid.size(0));
        const std::size_t ny = std::size_t(grid.size(1));
        throw std::invalid_argument("marching_cubes: NaN sample at (" +
                                    std::to_string(firstNan % nx) + ", " +
                                    std::to_string(firstNan / nx % ny) + ", " +
                                    std::to_string(firstNan / (nx * ny)) +
                                    "); the field must be NaN-free");
    }

    // Pass 2, per sample layer: the number of crossed edges whose vertex the layer owns. The
    // prefix sum over layers numbers the vertices in scan order, so the numbering does not depend
    // on how the work is split.
    std::vector<std::uint64_t> layerOffset(std::size_t(nz) + 1, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, nz), [&](const tbb::blocked_range<int>& range) {
        for (int z = range.begin(); z != range.end(); ++z)
            layerOffset[std::size_t(z) + 1] = rows.countCrossedEdges(z);
    });
    for (int z = 0; z < nz; ++z)
        layerOffset[std::size_t(z) + 1] += layerOffset[z];
    const std::uint64_t edgeVertexCount = layerOffset.back();
    if (edgeVertexCount >= kInteriorFlag)
        throw std::length_error("marching_cubes: " + std::to_string(edgeVertexCount) +
                                " edge vertices do not fit 31-bit indices");

    // Pass 3, per slab of `grain` cell layers: edge vertices of the owned layers, written in
    // place, and the slab's triangles and interior vertices, concatenated afterwards in slab
    // order, i.e. in cell scan order whatever the grain or thread count. Only the crossed edges
    // and the cells with mixed corners are visited.
    // Nothing below throws std::invalid_argument, so the mesh is built in `out` itself, reusing
    // its storage from the last call (as the vtk_flying_edges wrapper does).
    TriangleMesh& mesh = out;
    mesh.clear();
    mesh.positions.resize(edgeVertexCount);
    if (options.computeNormals)
        mesh.normals.resize(edgeVertexCount);
    const int cellLayers = nz - 1;
    const int slabCount = (cellLayers + grain - 1) / grain;
    std::vector<SlabOutput> slabs(static_cast<std::size_t>(slabCount));
    const Mesher mesher(grid, options, rows, layerOffset, mesh);
    // Each worker keeps its two layers of vertex indices from slab to slab.
    tbb::enumerable_thread_specific<std::pair<LayerVertices, LayerVertices>> layers(
        [&] { return std::pair(LayerVertices(grid.layerSize()), LayerVertices(grid.layerSize())); });
    tbb::parallel_for(
        tbb::blocked_range<int>(0, slabCount, 1),
        [&](const tbb::blocked_range<int>& range) {
            auto& [lower, upper] = layers.local();
            for (int s = range.begin(); s != range.end(); ++s) {
                const int z0 = s * grain;
                mesher.meshSlab(z0, std::min(z0 + grain, cellLayers), lower, upper, slabs[s]);
            }
        },
        tbb::simple_partitioner());

    // Interior vertices follow the edge vertices, in slab order.
    std::uint64_t vertexCount = edgeVertexCount;
    std::size_t indexCount = 0;
    for (const SlabOutput& slab : slabs) {
        vertexCount += slab.interior.size();
        indexCount += slab.triangles.size();
    }
    if (vertexCount > std::numeric_limits<std::uint32_t>::max()) {
        out.clear();
        throw std::length_error("marching_cubes: " + std::to_string(vertexCount) +
                                " vertices do not fit 32-bit indices");
    }
    std::vector<std::size_t> firstIndex(slabs.size() + 1, 0);
    std::vector<std::uint32_t> firstInterior(slabs.size() + 1, std::uint32_t(edgeVertexCount));
    for (std::size_t s = 0; s < slabs.size(); ++s) {
        firstIndex[s + 1] = firstIndex[s] + slabs[s].triangles.size();
        firstInterior[s + 1] = firstInterior[s] + std::uint32_t(slabs[s].interior.size());
    }
    mesh.indices.resize(indexCount);
    mesh.positions.resize(vertexCount);
    if (options.computeNormals)
        mesh.normals.resize(vertexCount);
    tbb::parallel_for(std::size_t(0), slabs.size(), [&](std::size_t s) {
        const SlabOutput& slab = slabs[s];
        std::uint32_t* indices = mesh.indices.data() + firstIndex[s];
        if (slab.interior.empty()) { // the common case: nothing to fix up
            std::copy(slab.triangles.begin(), slab.triangles.end(), indices);
            return;
        }
        for (const std::uint32_t index : slab.triangles)
            *indices++ = (index & kInteriorFlag) != 0
                             ? firstInterior[s] + (index & ~kInteriorFlag)
                             : index;
        for (std::size_t j = 0; j < slab.interior.size(); ++j) {
            mesh.positions[firstInterior[s] + j] = glm::vec3(slab.interior[j].position);
            if (options.computeNormals)
                mesh.normals[firstInterior[s] + j] = glm::vec3(slab.interior[j].normal);
        }
    });
}

} // namespace rtlab::isosurface::mc
