#pragma once
// Internal helpers of the mesh metrics: hashing, closest points, vertex merging, and a BVH over
// arbitrary primitives (Embree user geometry behind an opaque pointer).

#include "core/mesh.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace rtlab::metrics::detail {

//! Uniform [0, 1) from a counter-based hash (SplitMix64 finaliser) of (seed, index, stream).
double hashToUnit(std::uint64_t seed, std::uint64_t index, std::uint64_t stream);

//! Closest point to p on triangle abc (Ericson, Real-Time Collision Detection, 5.1.5); falls
//! back to the closest point on the three edges when the triangle has no area.
glm::dvec3 findClosestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a,
                                      const glm::dvec3& b, const glm::dvec3& c);
//! Closest point to p on segment ab.
glm::dvec3 findClosestPointOnSegment(const glm::dvec3& p, const glm::dvec3& a,
                                     const glm::dvec3& b);

//! Throws rtlab::Error, naming `what`, when the index count is not a multiple of 3, an index is
//! out of range or a position is not finite.
void checkMesh(const TriangleMesh& mesh, const char* what);

//! For each vertex, the smallest index of a vertex with the same position (+0 and -0 equal).
std::vector<std::uint32_t> mergeVerticesByPosition(const TriangleMesh& mesh);

//! The three corners of triangle t in double precision.
inline void loadTriangle(const TriangleMesh& mesh, std::size_t t, glm::dvec3 out[3])
{
    for (int k = 0; k < 3; ++k)
        out[k] = glm::dvec3(mesh.positions[mesh.indices[3 * t + k]]);
}

//! Do triangles p and q intersect (touching included)? Separating-axis test in double over the
//! 2 normals, 9 edge-edge cross products and 6 in-plane edge normals.
bool testTrianglesIntersect(const glm::dvec3 p[3], const glm::dvec3 q[3]);

//! Axis-aligned box, world units.
struct Box {
    glm::dvec3 lo{0.0};
    glm::dvec3 hi{0.0};
};

//! A bounding volume hierarchy over primitives known only by their boxes, built by Embree.
//! Queries may run concurrently from several threads.
class PrimitiveBvh {
public:
    explicit PrimitiveBvh(const std::vector<Box>& boxes);
    ~PrimitiveBvh();
    PrimitiveBvh(const PrimitiveBvh&) = delete;
    PrimitiveBvh& operator=(const PrimitiveBvh&) = delete;

    //! Distance from p to primitive `index` (world units, >= 0).
    using DistanceFunction = std::function<double(std::uint32_t index, const glm::dvec3& p)>;

    //! The smallest distance(i, p) over all primitives (+infinity when there are none); the
    //! index of that primitive goes to *nearest when given.
    double findNearestDistance(const glm::dvec3& p, const DistanceFunction& distance,
                               std::uint32_t* nearest = nullptr) const;

    //! All pairs (i, j), i < j, whose boxes may overlap (a superset of the overlapping pairs),
    //! sorted and unique.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> findOverlappingPairs() const;

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

} // namespace rtlab::metrics::detail
