// Self-intersections: Embree's BVH collision for candidate pairs, a separating-axis test for each.

#include "metrics/mesh_metrics.h"

#include "metrics/mesh_metrics_detail.h"

#include <glm/common.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

namespace rtlab::metrics {

SelfIntersections findSelfIntersections(const TriangleMesh& mesh)
{
    detail::checkMesh(mesh, "self-intersections");
    const auto canonical = detail::mergeVerticesByPosition(mesh);
    const std::size_t triangles = mesh.triangleCount();
    auto corner = [&](std::size_t t, int k) { return canonical[mesh.indices[3 * t + k]]; };

    // Triangles with a repeated (merged) vertex stay in the BVH, so that primitive ids are
    // triangle indices, but take part in no pair.
    std::vector<detail::Box> boxes(triangles);
    std::vector<char> valid(triangles, 0);
    for (std::size_t t = 0; t < triangles; ++t) {
        glm::dvec3 v[3];
        detail::loadTriangle(mesh, t, v);
        boxes[t] = {glm::min(v[0], glm::min(v[1], v[2])), glm::max(v[0], glm::max(v[1], v[2]))};
        valid[t] = corner(t, 0) != corner(t, 1) && corner(t, 1) != corner(t, 2) &&
                   corner(t, 0) != corner(t, 2);
    }
    const detail::PrimitiveBvh bvh(boxes);
    const auto candidates = bvh.findOverlappingPairs();

    auto testPair = [&](std::uint32_t s, std::uint32_t t) {
        if (!valid[s] || !valid[t])
            return false;
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k)
                if (corner(s, j) == corner(t, k))
                    return false;  // neighbours: sharing a vertex or an edge
        glm::dvec3 p[3], q[3];
        detail::loadTriangle(mesh, s, p);
        detail::loadTriangle(mesh, t, q);
        return detail::testTrianglesIntersect(p, q);
    };
    std::vector<char> hit(candidates.size(), 0);
    const tbb::blocked_range<std::size_t> all(0, candidates.size());
    tbb::parallel_for(all, [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i)
            hit[i] = testPair(candidates[i].first, candidates[i].second);
    });

    SelfIntersections result;
    result.candidatePairs = candidates.size();
    std::vector<char> flagged(triangles, 0);
    for (std::size_t i = 0; i < candidates.size(); ++i)
        if (hit[i]) {
            ++result.pairs;
            flagged[candidates[i].first] = flagged[candidates[i].second] = 1;
        }
    for (std::size_t t = 0; t < triangles; ++t)
        if (flagged[t])
            result.triangles.push_back(std::uint32_t(t));
    return result;
}

} // namespace rtlab::metrics
