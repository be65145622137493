#include "passes.h"

#include "qef.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace rtlab::isosurface::dc::detail {

//! Pass 3: one QEF vertex per cell or patch [Ju et al. 2002, sec. 2.2], from the crossings of its
//! own edges only, in the cell's frame (its lowest sample at the origin, the box [0, 1]^3). A face
//! vertex is the midpoint of its segment's two crossings, which lies on the face.
void placeVertices(const Grid& grid, const EdgeTable& table, const ExtractionOptions& options,
                   bool keepQef, CellVertices& vertices, ExtractionStats& stats)
{
    const std::size_t count = vertices.cell.size();
    vertices.local.resize(count); // every entry is written below
    if (options.computeNormals)
        vertices.normal.resize(count); // likewise
    else
        vertices.normal.assign(count, glm::dvec3(0.0));
    if (keepQef)
        vertices.qef.assign(count, QefSystem{});
    // Every entry of placement is written below (a face vertex's is not read).
    vertices.placement.resize(count);
    const auto& cellEdges = getCellEdgeOffsets();

    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, count),
        [&](const tbb::blocked_range<std::size_t>& range) {
            std::array<glm::dvec3, 12> points;
            std::array<glm::dvec3, 12> normals;
            // The cell's edges start in 4 sample rows and at most 2 words of each: those words
            // are fetched once per cell (the vertices of a cell follow each other).
            glm::ivec3 cached(-1);
            std::array<EdgeTable::Word, 8> words;
            unsigned fetched = 0;
            for (std::size_t v = range.begin(); v != range.end(); ++v) {
                const glm::ivec3 cell = vertices.cell[v];
                if (cell != cached) {
                    cached = cell;
                    fetched = 0;
                }
                int n = 0;
                glm::dvec3 normalSum(0.0);
                // The set bits only (a loop over all 12 mispredicts at every other edge).
                for (unsigned bits = vertices.edges[v]; bits != 0; bits &= bits - 1) {
                    const CellEdgeOffset& e = cellEdges[std::size_t(std::countr_zero(bits))];
                    const int sx = cell.x + e.offset.x;
                    const unsigned slot = unsigned(e.offset.y + 2 * e.offset.z) * 2u +
                                          unsigned((sx >> 6) - (cell.x >> 6));
                    if (((fetched >> slot) & 1u) == 0) {
                        words[slot] = table.getWord(cell.y + e.offset.y, cell.z + e.offset.z,
                                                    std::size_t(sx) >> 6);
                        fetched |= 1u << slot;
                    }
                    const std::uint32_t id = EdgeTable::findIn(words[slot], sx & 63, e.axis);
                    if (id == kNone)
                        continue;
                    const Crossing& c = table.crossings[id];
                    points[n] = glm::dvec3(e.offset); // in the cell's frame
                    points[n][e.axis] += c.t;
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
                std::array<std::uint8_t, 4>& placed = vertices.placement[v];
                placed = {0, 0, std::uint8_t(skippedHere), 0};
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
                    placed[3] = 1;
                    p = qef.massPoint;
                }
                if (!isFinite(p))
                    p = qef.massPoint;
                if (!isInsideBox(p)) {
                    placed[1] = 1;
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
                placed[0] = std::uint8_t(solution.rank);
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
        const std::array<std::uint8_t, 4>& placed = vertices.placement[v];
        ++stats.rank[std::min<int>(placed[0], 3)];
        stats.leftCell += placed[1];
        stats.skippedNormals += placed[2];
        stats.cellsWithoutPlanes += placed[3];
    }
}

} // namespace rtlab::isosurface::dc::detail
