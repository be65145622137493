#pragma once
// The state an SdfMesher keeps between updates, shared by its two halves: sdf_mesher.cpp (the
// grid, the vertex and quad rules, the full meshing) and sdf_mesher_update.cpp (the incremental
// update). Private to the scene module.

#include "scene/sdf_mesher.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace rtlab::scene {

namespace sdf_mesher_detail {

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
inline constexpr int kNotMeshed = INT_MIN;

inline constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                      {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
inline constexpr int kEdge[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                     {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

inline void growBox(glm::dvec3& lo, glm::dvec3& hi, const glm::vec3& p)
{
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
}

} // namespace sdf_mesher_detail

// A private header of the mesher's two sources: its constants are theirs.
using namespace sdf_mesher_detail;

struct SdfMesher::State {
    const SdfModel* model = nullptr;
    SdfMeshOptions options;
    glm::ivec3 cells{0};
    glm::ivec3 samples{0};
    glm::dvec3 origin{0.0};
    double spacing = 0.0;
    int meshedFrame = kNotMeshed;
    std::vector<double> raw;     // the field at each sample
    std::vector<double> values;  // the same, the padding shell pushed outside
    std::vector<std::uint32_t> cellVertex;  // vertex of each cell, kNone when not crossed
    std::vector<std::uint32_t> vertexCell;  // cell of each vertex
    std::vector<std::uint32_t> edgeQuad;    // quad (triangles 2q, 2q + 1) of each grid edge
    std::vector<std::uint32_t> quadEdge;    // edge of each quad
    SdfMesh mesh;

    // Scratch of the incremental update, kept between calls: fresh memory costs its first
    // touch, which on a dig's few percent of the grid would cost more than the meshing. A cell,
    // edge or vertex is marked in this update when its stamp equals `stamp`.
    struct Quad {
        std::uint32_t slot = kNone;
        std::array<std::uint32_t, 6> indices{};
        std::array<std::uint32_t, 2> materials{};
    };
    std::uint32_t stamp = 0;
    std::vector<std::uint32_t> cellStamp, edgeStamp, vertexStamp;
    std::vector<std::vector<std::uint32_t>> changedBySlice;
    std::vector<std::uint32_t> dirtyCells;
    std::vector<std::size_t> edges;
    std::vector<Quad> before, after;
    std::vector<glm::vec3> newPosition;
    std::vector<std::uint8_t> crossed;

    std::size_t sampleIndex(int x, int y, int z) const
    {
        return (std::size_t(z) * samples.y + y) * samples.x + x;
    }
    std::size_t cellIndex(int x, int y, int z) const
    {
        return (std::size_t(z) * cells.y + y) * cells.x + x;
    }
    glm::ivec3 cellCoords(std::size_t c) const
    {
        return {int(c % std::size_t(cells.x)), int((c / std::size_t(cells.x)) % std::size_t(cells.y)),
                int(c / (std::size_t(cells.x) * std::size_t(cells.y)))};
    }
    // Edge along `axis` from sample p0 to p0 + e_axis.
    std::size_t edgeIndex(int axis, const glm::ivec3& p0) const
    {
        return std::size_t(axis) * samples.x * samples.y * samples.z + sampleIndex(p0.x, p0.y, p0.z);
    }
    glm::dvec3 position(int x, int y, int z) const { return origin + spacing * glm::dvec3(x, y, z); }
    bool isPadding(int x, int y, int z) const
    {
        return x == 0 || y == 0 || z == 0 || x == samples.x - 1 || y == samples.y - 1 ||
               z == samples.z - 1;
    }
    // The padding shell is outside by construction: closed surfaces stay closed even when the
    // model touches its bounds.
    double padded(double v, int x, int y, int z) const
    {
        return isPadding(x, y, z) ? std::max(v, spacing * 0.5) : v;
    }

    // One vertex per crossed cell, at the mean of its edge crossings, then Newton-projected.
    bool computeVertex(int x, int y, int z, int frame, glm::vec3& out) const
    {
        double v[8];
        int inside = 0;
        for (int c = 0; c < 8; ++c) {
            v[c] = values[sampleIndex(x + kCorner[c][0], y + kCorner[c][1], z + kCorner[c][2])];
            inside += v[c] < 0.0;
        }
        if (inside == 0 || inside == 8)
            return false;
        glm::dvec3 sum(0.0);
        int crossings = 0;
        for (const auto& e : kEdge) {
            const double a = v[e[0]], b = v[e[1]];
            if ((a < 0.0) == (b < 0.0))
                continue;
            const double t = a / (a - b);
            const glm::dvec3 pa(kCorner[e[0]][0], kCorner[e[0]][1], kCorner[e[0]][2]);
            const glm::dvec3 pb(kCorner[e[1]][0], kCorner[e[1]][1], kCorner[e[1]][2]);
            sum += pa + t * (pb - pa);
            ++crossings;
        }
        const glm::dvec3 cellMin = position(x, y, z);
        glm::dvec3 p = cellMin + spacing * (sum / double(crossings));
        // Newton steps on the field, kept within half a cell of the cell so that sharp features
        // cannot pull vertices across their neighbours (which would fold the mesh); the surface
        // may leave the cell's own box between two crossings.
        const glm::dvec3 lo = cellMin - glm::dvec3(0.5 * spacing);
        const glm::dvec3 hi = cellMin + glm::dvec3(1.5 * spacing);
        for (int s = 0; s < options.projectionSteps; ++s) {
            const double f = model->evaluate(p, frame);
            if (!std::isfinite(f))
                break;
            p = glm::clamp(p - f * model->evaluateGradient(p, frame), lo, hi);
        }
        out = glm::vec3(p);
        return true;
    }

    // One quad per crossed grid edge, between the four cells around it, wound counter-clockwise
    // seen from outside: for an edge along axis a with u = a+1, v = a+2 (cyclic), the cells in
    // the order (u-,v-), (u+,v-), (u+,v+), (u-,v+) are counter-clockwise seen from +a.
    bool computeQuad(int axis, const glm::ivec3& p0, std::uint32_t tri[6]) const
    {
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;
        glm::ivec3 p1 = p0;
        p1[axis] += 1;
        if (p1[axis] >= samples[axis] || p0[u] == 0 || p0[w] == 0 || p0[u] >= cells[u] ||
            p0[w] >= cells[w])
            return false;
        const bool in0 = values[sampleIndex(p0.x, p0.y, p0.z)] < 0.0;
        const bool in1 = values[sampleIndex(p1.x, p1.y, p1.z)] < 0.0;
        if (in0 == in1)
            return false;
        std::uint32_t q[4];
        const int du[4] = {-1, 0, 0, -1}, dw[4] = {-1, -1, 0, 0};
        for (int k = 0; k < 4; ++k) {
            glm::ivec3 c = p0;
            c[u] += du[k];
            c[w] += dw[k];
            q[k] = cellVertex[cellIndex(c.x, c.y, c.z)];
            if (q[k] == kNone)
                return false;
        }
        if (!in0) // the surface faces -axis: reverse the winding
            std::swap(q[1], q[3]);
        const auto& positions = mesh.mesh.positions;
        // Split along the shorter diagonal: fewer slivers.
        const float d02 = glm::distance(positions[q[0]], positions[q[2]]);
        const float d13 = glm::distance(positions[q[1]], positions[q[3]]);
        const std::uint32_t split02[6] = {q[0], q[1], q[2], q[0], q[2], q[3]};
        const std::uint32_t split13[6] = {q[0], q[1], q[3], q[1], q[2], q[3]};
        std::copy_n(d02 <= d13 ? split02 : split13, 6, tri);
        return true;
    }

    // The material at the triangle's centroid.
    std::uint32_t computeMaterial(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                                  int frame) const
    {
        return model->evaluateMaterial((glm::dvec3(a) + glm::dvec3(b) + glm::dvec3(c)) / 3.0, frame);
    }

    void meshAll(int frame);
    // Folds `added` (edits after every applied one) into the grid and re-meshes what they
    // touched; `reach` is each added edit's findEditReach box.
    void meshIncrementally(int frame, const std::vector<const CsgEdit*>& added,
                           const std::vector<std::pair<glm::dvec3, glm::dvec3>>& reach,
                           SdfMeshChange& change);
};


} // namespace rtlab::scene
