#include "isosurface/case_table.h"

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <bit>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace rtlab::isosurface::tables {
namespace {

//! The two axes other than `axis`, in increasing order: they span the faces normal to `axis` and
//! enumerate the four edges parallel to it.
std::array<int, 2> getOtherAxes(int axis)
{
    return axis == 0 ? std::array{1, 2} : axis == 1 ? std::array{0, 2} : std::array{0, 1};
}

std::array<CellEdge, kEdgeCount> buildEdges()
{
    std::array<CellEdge, kEdgeCount> edges{};
    for (int axis = 0; axis < 3; ++axis) {
        const auto [u, v] = getOtherAxes(axis);
        for (int k = 0; k < 4; ++k) {
            const int start = ((k & 1) << u) | (((k >> 1) & 1) << v);
            edges[axis * 4 + k] = {axis, start, start | (1 << axis)};
        }
    }
    return edges;
}

int findEdge(const std::array<CellEdge, kEdgeCount>& edges, int cornerA, int cornerB)
{
    for (int e = 0; e < kEdgeCount; ++e) {
        if ((edges[e].start == cornerA && edges[e].end == cornerB) ||
            (edges[e].start == cornerB && edges[e].end == cornerA))
            return e;
    }
    throw std::logic_error("isosurface tables: corners " + std::to_string(cornerA) + " and " +
                           std::to_string(cornerB) + " share no cell edge");
}

std::array<CellFace, kFaceCount> buildFaces()
{
    const auto& edges = getCellEdges();
    std::array<CellFace, kFaceCount> faces{};
    for (int axis = 0; axis < 3; ++axis) {
        const auto [u, v] = getOtherAxes(axis);
        for (int side = 0; side < 2; ++side) {
            CellFace& face = faces[axis * 2 + side];
            face.axis = axis;
            face.side = side;
            // (u, v) = (0,0), (1,0), (1,1), (0,1): a cycle around the face.
            constexpr int kCycleU[4] = {0, 1, 1, 0};
            constexpr int kCycleV[4] = {0, 0, 1, 1};
            for (int k = 0; k < 4; ++k)
                face.corners[k] = (side << axis) | (kCycleU[k] << u) | (kCycleV[k] << v);
            for (int k = 0; k < 4; ++k)
                face.edges[k] = findEdge(edges, face.corners[k], face.corners[(k + 1) % 4]);
        }
    }
    return faces;
}

bool isInside(unsigned cube, int corner)
{
    return (cube >> corner) & 1u;
}

glm::dvec3 getCornerPosition(int corner)
{
    return {getCornerBit(corner, 0), getCornerBit(corner, 1), getCornerBit(corner, 2)};
}

glm::dvec3 computeEdgeMidpoint(int edge)
{
    const CellEdge& e = getCellEdges()[edge];
    return 0.5 * (getCornerPosition(e.start) + getCornerPosition(e.end));
}

//! Orients the face segment between crossed edges p and q so that, seen from outside the cell,
//! the face's inside corners lie on its right. Then every crossed edge starts one segment on one
//! of its two faces and ends one on the other, the segments chain into loops, and a loop's
//! right-hand normal points from the inside corners to the outside ones: the induced boundary
//! orientation of the surface patch whose normal points toward increasing field.
std::pair<int, int> orientSegment(unsigned cube, const CellFace& face, int p, int q)
{
    const CellEdge& edgeP = getCellEdges()[p];
    const int insideCorner = isInside(cube, edgeP.start) ? edgeP.start : edgeP.end;
    glm::dvec3 normal(0.0);
    normal[face.axis] = face.side == 1 ? 1.0 : -1.0;
    const glm::dvec3 pointP = computeEdgeMidpoint(p);
    const glm::dvec3 direction = computeEdgeMidpoint(q) - pointP;
    const double side =
        glm::dot(glm::cross(direction, getCornerPosition(insideCorner) - pointP), normal);
    // The inside corner of edge p is never on the line through p and q (q is on another edge).
    return side < 0.0 ? std::pair{p, q} : std::pair{q, p};
}

void appendTriangle(CellTriangulation& cell, int a, int b, int c)
{
    if (cell.triangleCount == kMaxCellTriangles)
        throw std::logic_error("isosurface tables: more than 12 triangles in a cell");
    const int t = cell.triangleCount++;
    cell.vertices[3 * t + 0] = static_cast<std::uint8_t>(a);
    cell.vertices[3 * t + 1] = static_cast<std::uint8_t>(b);
    cell.vertices[3 * t + 2] = static_cast<std::uint8_t>(c);
}

//! Triangulates one loop (its edge ids in loop order, smallest first) into `cell`; see
//! triangulateCell. `forbidden[e]` is the mask of edges that may not be joined to e by a diagonal.
void triangulateLoop(const std::vector<int>& loop,
                     const std::array<std::uint16_t, kEdgeCount>& forbidden,
                     CellTriangulation& cell)
{
    const int n = int(loop.size());
    // Work in one canonical direction (second vertex smaller than the last) so that a loop and
    // its reverse (the complementary case) get the same triangles, wound the other way.
    const bool reversed = loop[1] > loop[n - 1];
    std::vector<int> seq(loop);
    if (reversed)
        std::reverse(seq.begin() + 1, seq.end());

    const auto isSide = [&](int i, int j) { return j - i == 1 || (i == 0 && j == n - 1); };
    const auto isAllowed = [&](int i, int j) {
        return isSide(i, j) || ((forbidden[seq[i]] >> seq[j]) & 1u) == 0;
    };
    const auto weight = [&](int i, int j) {
        return isSide(i, j)
                   ? 0.0
                   : glm::length(computeEdgeMidpoint(seq[i]) - computeEdgeMidpoint(seq[j]));
    };
    // Minimum-weight triangulation of the polygon seq[i..j] with its chord (i, j) as base.
    constexpr double kNone = std::numeric_limits<double>::infinity();
    std::vector<double> cost(std::size_t(n * n), 0.0);
    std::vector<int> apex(std::size_t(n * n), -1);
    const auto at = [n](int i, int j) { return std::size_t(i * n + j); };
    for (int length = 2; length < n; ++length) {
        for (int i = 0; i + length < n; ++i) {
            const int j = i + length;
            double best = kNone;
            for (int k = i + 1; k < j; ++k) {
                if (!isAllowed(i, k) || !isAllowed(k, j))
                    continue;
                const double c = cost[at(i, k)] + cost[at(k, j)] + weight(i, k) + weight(k, j);
                if (c < best) {
                    best = c;
                    apex[at(i, j)] = k;
                }
            }
            cost[at(i, j)] = best;
        }
    }

    if (cost[at(0, n - 1)] < kNone) {
        // Triangles (i, k, j) with i < k < j follow the direction of seq.
        std::vector<std::pair<int, int>> pending{{0, n - 1}};
        while (!pending.empty()) {
            const auto [i, j] = pending.back();
            pending.pop_back();
            if (j - i < 2)
                continue;
            const int k = apex[at(i, j)];
            if (reversed)
                appendTriangle(cell, seq[j], seq[k], seq[i]);
            else
                appendTriangle(cell, seq[i], seq[k], seq[j]);
            pending.push_back({k, j});
            pending.push_back({i, k});
        }
        return;
    }

    // No admissible triangulation on the edge vertices: fan around a vertex inside the cell.
    if (cell.extraCount == kMaxCellExtras)
        throw std::logic_error("isosurface tables: too many interior vertices in a cell");
    const int extra = cell.extraCount++;
    std::uint16_t mask = 0;
    for (const int e : loop)
        mask |= std::uint16_t(1u << e);
    cell.extraLoops[extra] = mask;
    for (int i = 0; i < n; ++i)
        appendTriangle(cell, kExtraVertex + extra, loop[i], loop[(i + 1) % n]);
}

} // namespace

const std::array<CellEdge, kEdgeCount>& getCellEdges()
{
    static const std::array<CellEdge, kEdgeCount> edges = buildEdges();
    return edges;
}

const std::array<CellFace, kFaceCount>& getCellFaces()
{
    static const std::array<CellFace, kFaceCount> faces = buildFaces();
    return faces;
}

bool isFaceAmbiguous(unsigned cube, int face)
{
    const auto& corners = getCellFaces()[face].corners;
    const bool in0 = isInside(cube, corners[0]);
    return in0 == isInside(cube, corners[2]) && in0 != isInside(cube, corners[1]) &&
           in0 != isInside(cube, corners[3]);
}

int findFaceSegment(unsigned cube, int face, bool joined, int edge)
{
    if (!isFaceAmbiguous(cube, face))
        return -1;
    const CellFace& f = getCellFaces()[face];
    int segment = 0;
    for (int k = 0; k < 4; ++k) {
        // Same cut as triangulateCell: joined faces cut off their outside corners.
        if (isInside(cube, f.corners[k]) == joined)
            continue;
        if (f.edges[(k + 3) % 4] == edge || f.edges[k] == edge)
            return segment;
        ++segment;
    }
    return -1;
}

unsigned decideJoinedFaces(unsigned cube, const std::array<double, kCornerCount>& values,
                           AmbiguityRule rule)
{
    unsigned joined = 0;
    for (int f = 0; f < kFaceCount; ++f) {
        if (!isFaceAmbiguous(cube, f) || rule == AmbiguityRule::SeparateInside)
            continue;
        if (rule == AmbiguityRule::JoinInside) {
            joined |= 1u << f;
            continue;
        }
        const auto& corners = getCellFaces()[f].corners;
        double v[4];
        for (int k = 0; k < 4; ++k)
            v[k] = values[corners[k]];
        const bool firstInside = isInside(cube, corners[0]);
        const double insideProduct = firstInside ? v[0] * v[2] : v[1] * v[3];
        const double outsideProduct = firstInside ? v[1] * v[3] : v[0] * v[2];
        // [Nielson & Hamann 1991] asymptotic decider: the bilinear interpolant on the face has
        // its saddle value (ac - bd) / (a + c - b - d) (a, c diagonal). With a, c the inside
        // pair the denominator is negative, so the saddle is inside, and the inside corners
        // connected through it, exactly when ac > bd. A saddle exactly on the iso-value is
        // outside, as samples on it are. Both cells sharing the face compute the same two
        // products from the same four values, so they always agree: the mesh stays closed.
        if (insideProduct > outsideProduct)
            joined |= 1u << f;
    }
    return joined;
}

CellTriangulation triangulateCell(unsigned cube, unsigned joinedFaces)
{
    // 1. Per face, segments between the crossed edges, as a successor map over cell edges; and
    //    the pairs of edges of an ambiguous face that no segment joins.
    std::array<int, kEdgeCount> next;
    next.fill(-1);
    std::array<std::uint16_t, kEdgeCount> forbidden{};
    const auto addSegment = [&](const CellFace& face, int p, int q) {
        const auto [from, to] = orientSegment(cube, face, p, q);
        if (next[from] != -1)
            throw std::logic_error("isosurface tables: case " + std::to_string(cube) + ": edge " +
                                   std::to_string(from) + " starts two segments");
        next[from] = to;
    };
    for (int f = 0; f < kFaceCount; ++f) {
        const CellFace& face = getCellFaces()[f];
        std::array<bool, 4> inside{};
        for (int k = 0; k < 4; ++k)
            inside[k] = isInside(cube, face.corners[k]);
        if (isFaceAmbiguous(cube, f)) {
            // Four crossed edges; each segment cuts one corner off the face. Cutting off the
            // outside corners leaves the inside diagonal connected across the face; cutting off
            // the inside corners separates it.
            for (int a : face.edges)
                for (int b : face.edges)
                    forbidden[a] |= std::uint16_t(a != b ? 1u << b : 0u);
            const bool cutInside = ((joinedFaces >> f) & 1u) == 0;
            for (int k = 0; k < 4; ++k) {
                if (inside[k] != cutInside)
                    continue;
                const int p = face.edges[(k + 3) % 4];
                const int q = face.edges[k];
                forbidden[p] &= std::uint16_t(~(1u << q));
                forbidden[q] &= std::uint16_t(~(1u << p));
                addSegment(face, p, q);
            }
            continue;
        }
        // Zero or two crossed edges: at most one segment.
        int crossed[2];
        int count = 0;
        for (int k = 0; k < 4; ++k) {
            if (inside[k] != inside[(k + 1) % 4])
                crossed[count++] = face.edges[k];
        }
        if (count == 2)
            addSegment(face, crossed[0], crossed[1]);
    }
    int crossedCount = 0;
    for (const CellEdge& edge : getCellEdges())
        crossedCount += isInside(cube, edge.start) != isInside(cube, edge.end);

    // 2. Chain the segments into loops, each starting at its smallest edge id, and triangulate
    //    each loop. [Lorensen & Cline 1987]: the surface in a cell is a set of polygons with
    //    vertices on the crossed edges, triangulated once per case.
    CellTriangulation result;
    result.edgeLoop.fill(-1);
    std::array<bool, kEdgeCount> visited{};
    int chained = 0;
    for (int start = 0; start < kEdgeCount; ++start) {
        if (next[start] == -1 || visited[start])
            continue;
        std::vector<int> loop;
        for (int e = start; !visited[e]; e = next[e]) {
            if (next[e] == -1)
                throw std::logic_error("isosurface tables: case " + std::to_string(cube) +
                                       ": open chain of segments");
            visited[e] = true;
            loop.push_back(e);
        }
        if (next[loop.back()] != start || loop.size() < 3)
            throw std::logic_error("isosurface tables: case " + std::to_string(cube) +
                                   ": segments do not close into a loop");
        triangulateLoop(loop, forbidden, result);
        chained += int(loop.size());
        if (result.loopCount == kMaxCellLoops)
            throw std::logic_error("isosurface tables: case " + std::to_string(cube) +
                                   ": more than four loops");
        std::uint16_t mask = 0;
        for (const int e : loop)
            mask |= std::uint16_t(1u << e);
        result.loops[result.loopCount++] = mask;
    }
    if (chained != crossedCount)
        throw std::logic_error("isosurface tables: case " + std::to_string(cube) +
                               ": not every crossed edge is on a loop");

    // 3. Patches: which loop each crossed edge is on, and the ambiguous faces whose two segments
    //    one loop holds.
    for (int l = 0; l < result.loopCount; ++l) {
        for (int e = 0; e < kEdgeCount; ++e) {
            if ((result.loops[l] >> e) & 1u)
                result.edgeLoop[e] = std::int8_t(l);
        }
        for (int f = 0; f < kFaceCount; ++f) {
            unsigned faceMask = 0;
            for (const int e : getCellFaces()[f].edges)
                faceMask |= 1u << e;
            if (isFaceAmbiguous(cube, f) && (result.loops[l] & faceMask) == faceMask)
                result.doubledFaces |= std::uint8_t(1u << f);
        }
    }
    return result;
}

unsigned CaseTable::packDecisions(unsigned ambiguous, unsigned joinedFaces)
{
    unsigned decisions = 0;
    int bit = 0;
    for (int f = 0; f < kFaceCount; ++f) {
        if ((ambiguous >> f) & 1u)
            decisions |= ((joinedFaces >> f) & 1u) << bit++;
    }
    return decisions;
}

const CaseTable& CaseTable::getInstance()
{
    static const CaseTable table;
    return table;
}

CaseTable::CaseTable()
{
    for (unsigned cube = 0; cube < 256; ++cube) {
        unsigned ambiguous = 0;
        for (int f = 0; f < kFaceCount; ++f) {
            if (isFaceAmbiguous(cube, f))
                ambiguous |= 1u << f;
        }
        mAmbiguousFaces[cube] = static_cast<std::uint8_t>(ambiguous);
        mFirstEntry[cube] = static_cast<std::uint16_t>(mEntries.size());
        const unsigned combinations = 1u << std::popcount(ambiguous);
        for (unsigned decisions = 0; decisions < combinations; ++decisions) {
            // Spread the compact decision bits onto the ambiguous faces, in ascending face order.
            unsigned joined = 0;
            int bit = 0;
            for (int f = 0; f < kFaceCount; ++f) {
                if ((ambiguous >> f) & 1u)
                    joined |= ((decisions >> bit++) & 1u) << f;
            }
            mEntries.push_back(triangulateCell(cube, joined));
        }
    }
}

} // namespace rtlab::isosurface::tables
