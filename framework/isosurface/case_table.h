#pragma once
// Cell geometry and the marching cubes case table, generated at first use from the corner signs.
// Shared by the isosurface techniques: marching_cubes triangulates the table's loops, and
// dual_contouring gives each loop (surface patch of a cell) its own vertex.
//
// Conventions shared by the table and the extractor:
//   corner c  : offset (c & 1, (c >> 1) & 1, (c >> 2) & 1) from the cell's lowest sample
//   edge e    : axis e / 4; its start corner has the two other axes' bits from e % 4
//   face f    : axis f / 2, side f % 2 (0 = low, 1 = high); corners listed in cyclic order
//   cube index: bit c set when corner c is inside (value < iso)

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rtlab::isosurface::tables {

inline constexpr int kCornerCount = 8;
inline constexpr int kEdgeCount = 12;
inline constexpr int kFaceCount = 6;
//! Loops that need a vertex inside the cell (see triangulateCell); at most one per cell occurs,
//! four is the bound from loops of >= 3 of the 12 edges.
inline constexpr int kMaxCellExtras = 4;
//! A loop of L edges gives L - 2 triangles, or L around an interior vertex; loops share no edge.
inline constexpr int kMaxCellTriangles = 12;
//! Loops (surface patches) of a cell: four separated corners give the most.
inline constexpr int kMaxCellLoops = 4;
//! Vertex ids in a CellTriangulation: 0..11 are cell edges, kExtraVertex + j the j-th interior
//! vertex of the cell.
inline constexpr int kExtraVertex = kEdgeCount;

struct CellEdge {
    int axis;  //!< 0 = x, 1 = y, 2 = z
    int start; //!< corner with the lower coordinate along the axis
    int end;   //!< start | (1 << axis)
};

struct CellFace {
    int axis;                   //!< axis of the face normal
    int side;                   //!< 0: low face (normal -axis), 1: high face (normal +axis)
    std::array<int, 4> corners; //!< cyclic order around the face
    std::array<int, 4> edges;   //!< edges[k] joins corners[k] and corners[(k + 1) % 4]
};

const std::array<CellEdge, kEdgeCount>& getCellEdges();
const std::array<CellFace, kFaceCount>& getCellFaces();

//! Offset of a corner along an axis, 0 or 1.
constexpr int getCornerBit(int corner, int axis)
{
    return (corner >> axis) & 1;
}

//! A face is ambiguous when its inside corners are diagonal (two inside, two outside, alternating).
bool isFaceAmbiguous(unsigned cube, int face);

//! The face across which a cell's neighbour sees face `face`: same axis, other side.
constexpr int getOppositeFace(int face)
{
    return face ^ 1;
}

enum class AmbiguityRule {
    Asymptotic,     //!< per face, the bilinear interpolant's saddle value decides
    SeparateInside, //!< inside corners of an ambiguous face are never connected across it
    JoinInside,     //!< inside corners of an ambiguous face are always connected across it
};

//! The ambiguous faces of `cube` whose inside corners are connected across the face (bit f set),
//! decided by `rule` from the corner values relative to the iso-value (`values[c]` < 0 exactly
//! when corner c is inside). The decision on a face depends on that face's four values alone, so
//! both cells sharing it decide the same.
unsigned decideJoinedFaces(unsigned cube, const std::array<double, kCornerCount>& values,
                           AmbiguityRule rule);

//! Which of the two segments of ambiguous face `face` holds cell edge `edge` (0 or 1; -1 when the
//! edge is not on the face or the face is not ambiguous), with the face's inside corners joined
//! across it when `joined` is set. Segments cut one corner each off the face (the outside
//! corners when joined, else the inside ones) and are numbered in the face's corner order.
int findFaceSegment(unsigned cube, int face, bool joined, int edge);

//! The triangles of one cell, counter-clockwise seen from the outside (positive) side. Vertices
//! are the crossed edges (one vertex per edge) and, for loops that cannot be triangulated on their
//! edge vertices alone, one interior vertex per such loop, placed at the loop's centroid.
//!
//! The loops themselves are kept too: each is one surface patch of the cell, the polygon whose
//! vertices are its crossed edges.
struct CellTriangulation {
    int triangleCount = 0;
    int extraCount = 0;                                     //!< interior vertices
    std::array<std::uint16_t, kMaxCellExtras> extraLoops{}; //!< cell edge mask of each one's loop
    std::array<std::uint8_t, 3 * kMaxCellTriangles> vertices{}; //!< three per triangle
    int loopCount = 0;
    //! Cell edge mask of each loop, ordered by the loop's smallest edge id.
    std::array<std::uint16_t, kMaxCellLoops> loops{};
    //! Per cell edge, the loop it lies on; -1 for edges that are not crossed.
    std::array<std::int8_t, kEdgeCount> edgeLoop{};
    //! Bit f set when face f is ambiguous and one loop holds both of its segments (all four of
    //! its edges): the patch crosses the face twice.
    std::uint8_t doubledFaces = 0;
};

//! Builds the triangulation of a cell from its inside corners (`cube`) and, for each face f whose
//! bit is set in `joinedFaces`, the decision that the face's inside corners are connected across
//! it (only meaningful on ambiguous faces; ignored elsewhere).
//!
//! Per face, segments join the crossed edges; they chain into loops. A loop is triangulated with
//! the least total diagonal length (measured between edge midpoints) among the triangulations
//! with no diagonal between two edges of one face that no segment joins: such a diagonal lies in
//! the face, and the cell on the other side may use it too, which would put four triangles on one
//! mesh edge. Loops with no such triangulation (only mixed decisions on ambiguous faces produce
//! them) are fanned around an interior vertex instead.
CellTriangulation triangulateCell(unsigned cube, unsigned joinedFaces);

//! Every (cube index, ambiguous face decision) combination, generated once by triangulateCell.
class CaseTable {
public:
    //! The table, built on first use (thread-safe static initialisation).
    static const CaseTable& getInstance();

    //! Bit f set when face f of `cube` is ambiguous.
    unsigned ambiguousFaces(unsigned cube) const { return mAmbiguousFaces[cube]; }
    //! `decisions` bit k: the k-th ambiguous face of `cube` (ascending face id) joins its inside
    //! corners. Bits above the number of ambiguous faces must be zero.
    const CellTriangulation& find(unsigned cube, unsigned decisions) const
    {
        return mEntries[mFirstEntry[cube] + decisions];
    }
    //! The entry of `cube` whose ambiguous faces are joined exactly where `joinedFaces` (a face
    //! mask, as triangulateCell takes it) has a bit; bits of other faces are ignored.
    const CellTriangulation& findJoined(unsigned cube, unsigned joinedFaces) const
    {
        return mEntries[entryIndex(cube, joinedFaces)];
    }
    //! Position of findJoined(cube, joinedFaces) among all entries (see entry()).
    std::size_t entryIndex(unsigned cube, unsigned joinedFaces) const
    {
        return mFirstEntry[cube] + packDecisions(ambiguousFaces(cube), joinedFaces);
    }
    const CellTriangulation& entry(std::size_t index) const { return mEntries[index]; }
    std::size_t entryCount() const { return mEntries.size(); }

    //! The compact decision bits of find() from a face mask: bit k is the bit of the k-th face
    //! set in `ambiguous`.
    static unsigned packDecisions(unsigned ambiguous, unsigned joinedFaces);

private:
    CaseTable();

    std::array<std::uint8_t, 256> mAmbiguousFaces{};
    std::array<std::uint16_t, 256> mFirstEntry{};
    std::vector<CellTriangulation> mEntries;
};

} // namespace rtlab::isosurface::tables
