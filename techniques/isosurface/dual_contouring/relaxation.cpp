#include "passes.h"

#include "qef.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace rtlab::isosurface::dc::detail {

namespace {

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
                    const std::uint32_t u = findEdgeVertex(mVertices, other, s, e.axis);
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

} // namespace

void relaxMaterialBoundaries(const Grid& grid, const EdgeTable& table,
                             const std::vector<std::uint32_t>& materials,
                             const ExtractionOptions& options, const CrossingSource& source,
                             const plugin::IsosurfaceInput& input, bool relax,
                             CellVertices& vertices, ExtractionStats& stats)
{
    MaterialRelaxation relaxation(grid, table, materials, options, source, input, vertices);
    stats.boundaryVertices = relaxation.findBoundary();
    if (relax)
        stats.maxRelaxationShift = relaxation.relax(options.materialRelaxationIterations);
}

} // namespace rtlab::isosurface::dc::detail
