#include "passes.h"

#include "isosurface/case_table.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <stdexcept>
#include <string>

namespace rtlab::isosurface::dc::detail {

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

namespace {

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

constexpr std::size_t kMaxLoops = tables::kMaxCellLoops;

//! What numberCells reads of a case-table entry, packed small (the entries themselves hold
//! triangles and loops, a few cache lines each): edgeLoop at 2 bits per table edge
//! (CellCase::edgeLoops), the loop count and the doubled faces.
struct CompactEntry {
    std::uint32_t edgeLoops = 0;
    std::uint8_t loopCount = 0;
    std::uint8_t doubledFaces = 0;
};

const std::vector<CompactEntry>& getCompactEntries()
{
    static const std::vector<CompactEntry> compact = [] {
        static_assert(tables::kMaxCellLoops <= 4 && tables::kEdgeCount <= 16);
        const tables::CaseTable& table = tables::CaseTable::getInstance();
        std::vector<CompactEntry> c(table.entryCount());
        for (std::size_t e = 0; e < table.entryCount(); ++e) {
            const tables::CellTriangulation& entry = table.entry(e);
            for (int edge = 0; edge < tables::kEdgeCount; ++edge)
                if (const int loop = entry.edgeLoop[std::size_t(edge)]; loop >= 0)
                    c[e].edgeLoops |= std::uint32_t(loop) << (2 * edge);
            c[e].loopCount = std::uint8_t(entry.loopCount);
            c[e].doubledFaces = std::uint8_t(entry.doubledFaces);
        }
        return c;
    }();
    return compact;
}

//! Per case-table entry and loop, the loop's DC cell edge mask (kMaxLoops slots per entry).
const std::vector<std::uint16_t>& getLoopEdgeMasks()
{
    static const std::vector<std::uint16_t> masks = [] {
        const tables::CaseTable& table = tables::CaseTable::getInstance();
        std::vector<std::uint16_t> m(table.entryCount() * kMaxLoops, 0);
        for (std::size_t e = 0; e < table.entryCount(); ++e) {
            const tables::CellTriangulation& entry = table.entry(e);
            for (int l = 0; l < entry.loopCount; ++l)
                m[e * kMaxLoops + std::size_t(l)] = toCellEdgeMask(entry.loops[l]);
        }
        return m;
    }();
    return masks;
}

} // namespace

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

    // Cases and patches.
    const std::vector<CompactEntry>& compact = getCompactEntries();
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
                        c = CellCase{}; // the array may hold the last call's cases
                        const unsigned cube = rows.getCube(x, y, z);
                        c.cube = std::uint8_t(cube);
                        if (!perComponent) {
                            c.patches = 1;
                            continue;
                        }
                        // Most cells have no ambiguous face, and then nothing to decide.
                        if (caseTable.ambiguousFaces(cube) != 0) {
                            const std::size_t base = grid.index({x, y, z});
                            std::array<double, 8> values;
                            for (int j = 0; j < 8; ++j)
                                values[j] = grid.relative(base + corner[j]);
                            c.joined = std::uint8_t(tables::decideJoinedFaces(
                                cube, values, tables::AmbiguityRule::Asymptotic));
                        }
                        const std::size_t entry = caseTable.entryIndex(cube, c.joined);
                        c.entry = std::uint16_t(entry);
                        c.patches = compact[entry].loopCount;
                        c.edgeLoops = compact[entry].edgeLoops;
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
                const unsigned doubled = compact[c.entry].doubledFaces;
                for (int f = 0; f < tables::kFaceCount; ++f) {
                    if (((doubled >> f) & 1u) == 0)
                        continue;
                    glm::ivec3 other = vertices.activeCell[i];
                    other[f / 2] += (f & 1) ? 1 : -1;
                    if (other[f / 2] < 0 || other[f / 2] >= cells[f / 2])
                        continue;
                    const CellCase& n = vertices.getCase(other);
                    if ((compact[n.entry].doubledFaces >> tables::getOppositeFace(f)) & 1u)
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
    const std::vector<std::uint16_t>& loopEdgeMasks = getLoopEdgeMasks();
    vertices.onFace.assign(total, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, cells.z), [&](const tbb::blocked_range<int>& r) {
        for (int z = r.begin(); z != r.end(); ++z) {
            std::uint32_t next = std::uint32_t(layerCount[z]);
            for (std::uint64_t i = layerActive[z]; i != layerActive[z + 1]; ++i) {
                CellCase& c = vertices.cases[i];
                const glm::ivec3 cell = vertices.activeCell[i];
                c.firstVertex = next;
                if (!perComponent) {
                    vertices.cell[next] = cell;
                    vertices.edges[next++] = 0xfff;
                    continue;
                }
                const std::uint16_t* loopMasks = &loopEdgeMasks[std::size_t(c.entry) * kMaxLoops];
                for (int l = 0; l < c.patches; ++l) {
                    vertices.cell[next] = cell;
                    vertices.edges[next++] = loopMasks[l];
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
    return c.firstVertex + c.patches + 2u * std::popcount(before) + std::uint32_t(segment);
}

} // namespace rtlab::isosurface::dc::detail
