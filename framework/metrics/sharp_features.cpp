// Sharp features: crease edges of a mesh, box feature curves, edge-Chamfer and edge-F1.

#include "metrics/mesh_metrics.h"

#include "core/error.h"
#include "metrics/mesh_metrics_detail.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::metrics {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kRadiansPerDegree = 0.017453292519943295;

//! Midpoints of ceil(length / spacing) equal pieces of each segment.
std::vector<glm::dvec3> sampleSegments(const std::vector<FeatureSegment>& segments,
                                       double spacing)
{
    std::vector<glm::dvec3> samples;
    for (const FeatureSegment& s : segments) {
        const double length = glm::length(s.b - s.a);
        const auto pieces = std::max<std::size_t>(1, std::size_t(std::ceil(length / spacing)));
        for (std::size_t k = 0; k < pieces; ++k)
            samples.push_back(s.a + (s.b - s.a) * ((double(k) + 0.5) / double(pieces)));
    }
    return samples;
}

double sumLengths(const std::vector<FeatureSegment>& segments)
{
    double total = 0;
    for (const FeatureSegment& s : segments)
        total += glm::length(s.b - s.a);
    return total;
}

//! Distance of every sample to the nearest segment (+infinity when there are none).
std::vector<double> measureDistances(const std::vector<glm::dvec3>& samples,
                                     const std::vector<FeatureSegment>& segments)
{
    std::vector<detail::Box> boxes(segments.size());
    for (std::size_t i = 0; i < segments.size(); ++i)
        boxes[i] = {glm::min(segments[i].a, segments[i].b), glm::max(segments[i].a, segments[i].b)};
    const detail::PrimitiveBvh bvh(boxes);
    const detail::PrimitiveBvh::DistanceFunction distance = [&](std::uint32_t i,
                                                                const glm::dvec3& p) {
        return glm::length(p - detail::findClosestPointOnSegment(p, segments[i].a, segments[i].b));
    };
    std::vector<double> out(samples.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, samples.size()), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i)
            out[i] = bvh.findNearestDistance(samples[i], distance);
    });
    return out;
}

struct SideScore {
    double mean = 0;        // mean distance; 0 for an empty side
    double meanSquare = 0;  // mean squared distance
    double within = 1;      // fraction within the tolerance; 1 for an empty side
};

SideScore scoreSide(const std::vector<double>& distances, double tolerance)
{
    SideScore s;
    if (distances.empty())
        return s;
    double sum = 0, sumSq = 0;
    std::size_t within = 0;
    for (const double d : distances) {
        sum += d;
        sumSq += d * d;
        within += d <= tolerance ? 1 : 0;
    }
    s.mean = sum / double(distances.size());
    s.meanSquare = sumSq / double(distances.size());
    s.within = double(within) / double(distances.size());
    return s;
}

} // namespace

std::vector<FeatureSegment> makeBoxFeatureEdges(const glm::dvec3& center,
                                                const glm::dvec3& halfExtent,
                                                const glm::dmat3& rotation)
{
    auto corner = [&](int x, int y, int z) {
        return center + rotation * (halfExtent * glm::dvec3(x ? 1 : -1, y ? 1 : -1, z ? 1 : -1));
    };
    std::vector<FeatureSegment> edges;
    for (int axis = 0; axis < 3; ++axis)
        for (int u = 0; u < 2; ++u)
            for (int v = 0; v < 2; ++v) {
                int lo[3], hi[3];
                lo[axis] = 0;
                hi[axis] = 1;
                lo[(axis + 1) % 3] = hi[(axis + 1) % 3] = u;
                lo[(axis + 2) % 3] = hi[(axis + 2) % 3] = v;
                edges.push_back({corner(lo[0], lo[1], lo[2]), corner(hi[0], hi[1], hi[2])});
            }
    return edges;
}

std::vector<FeatureSegment> extractSharpEdges(const TriangleMesh& mesh, double minCreaseDeg)
{
    detail::checkMesh(mesh, "sharp edges");
    const auto canonical = detail::mergeVerticesByPosition(mesh);
    // One entry per triangle side, keyed by its undirected edge; sorting groups the sides of an
    // edge together (and orders the result deterministically).
    struct Side {
        std::uint64_t key;       // (min << 32) | max of the merged vertex indices
        std::uint32_t triangle;
        bool forward;            // traversed min -> max
        bool operator<(const Side& o) const
        {
            return key != o.key ? key < o.key : triangle < o.triangle;
        }
    };
    std::vector<Side> sides;
    sides.reserve(mesh.indices.size());
    std::vector<glm::dvec3> normals(mesh.triangleCount());
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
        const std::uint32_t v[3] = {canonical[mesh.indices[3 * t]],
                                    canonical[mesh.indices[3 * t + 1]],
                                    canonical[mesh.indices[3 * t + 2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2])
            continue;  // collapsed by merging: not part of the surface
        glm::dvec3 p[3];
        detail::loadTriangle(mesh, t, p);
        normals[t] = glm::cross(p[1] - p[0], p[2] - p[0]);
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = std::min(v[e], v[(e + 1) % 3]);
            const std::uint32_t b = std::max(v[e], v[(e + 1) % 3]);
            sides.push_back({(std::uint64_t(a) << 32) | b, std::uint32_t(t), v[e] == a});
        }
    }
    std::sort(sides.begin(), sides.end());

    const double cosLimit = std::cos(minCreaseDeg * kRadiansPerDegree);
    std::vector<FeatureSegment> out;
    for (std::size_t i = 0, j = 0; i < sides.size(); i = j) {
        while (j < sides.size() && sides[j].key == sides[i].key)
            ++j;
        bool isSharp = j - i > 2;
        if (j - i == 2) {
            const glm::dvec3 n0 = normals[sides[i].triangle];
            // Consistent neighbours traverse the edge in opposite directions.
            const double sign = sides[i].forward != sides[i + 1].forward ? 1.0 : -1.0;
            const glm::dvec3 n1 = sign * normals[sides[i + 1].triangle];
            const double l0 = glm::length(n0), l1 = glm::length(n1);
            if (l0 > 0 && l1 > 0)
                isSharp = glm::dot(n0, n1) / (l0 * l1) < cosLimit;
        }
        if (isSharp)
            out.push_back({glm::dvec3(mesh.positions[sides[i].key >> 32]),
                           glm::dvec3(mesh.positions[sides[i].key & 0xFFFFFFFFu])});
    }
    return out;
}

SharpFeatureScore measureSharpFeatures(const TriangleMesh& mesh,
                                       const std::vector<FeatureSegment>& features,
                                       const SharpFeatureOptions& options)
{
    if (!(options.tolerance > 0))
        throw Error("metrics: sharp features: the tolerance must be positive");
    const double spacing = options.sampleSpacing > 0 ? options.sampleSpacing
                                                     : 0.25 * options.tolerance;
    const auto meshEdges = extractSharpEdges(mesh, options.minCreaseDeg);
    const auto meshSamples = sampleSegments(meshEdges, spacing);
    const auto featureSamples = sampleSegments(features, spacing);

    SharpFeatureScore score;
    score.meshEdges = meshEdges.size();
    score.meshEdgeLength = sumLengths(meshEdges);
    score.featureLength = sumLengths(features);
    score.meshSamples = meshSamples.size();
    score.featureSamples = featureSamples.size();

    const SideScore m = scoreSide(measureDistances(meshSamples, features), options.tolerance);
    const SideScore f = scoreSide(measureDistances(featureSamples, meshEdges), options.tolerance);
    score.meshToFeature = m.mean;
    score.featureToMesh = f.mean;
    score.edgeChamfer = 0.5 * (m.mean + f.mean);
    score.edgeChamferSquared = m.meanSquare + f.meanSquare;
    score.precision = m.within;
    score.recall = f.within;
    const double sum = score.precision + score.recall;
    score.f1 = sum > 0 ? 2 * score.precision * score.recall / sum : 0.0;
    return score;
}

} // namespace rtlab::metrics
