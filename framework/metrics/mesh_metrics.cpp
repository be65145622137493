#include "metrics/mesh_metrics.h"

#include "metrics/mesh_metrics_detail.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <vector>

namespace rtlab::metrics {

namespace {

constexpr double kDegreesPerRadian = 57.29577951308232;
//! Angles this close below a bin edge count above it (see TriangleAngleHistogram).
constexpr double kBinEdgeSnapDeg = 1e-3;

//! Vertices whose incident triangles (with three distinct indices) form two or more fans.
std::size_t countNonManifoldVertices(const TriangleMesh& mesh)
{
    // Incident triangles of every vertex, compressed row storage.
    const std::size_t n = mesh.positions.size();
    std::vector<std::size_t> start(n + 1, 0);
    auto distinct = [&](std::size_t f) {
        const auto* v = &mesh.indices[f];
        return v[0] != v[1] && v[1] != v[2] && v[0] != v[2];
    };
    for (std::size_t f = 0; f + 2 < mesh.indices.size(); f += 3)
        if (distinct(f))
            for (int k = 0; k < 3; ++k)
                ++start[mesh.indices[f + k] + 1];
    std::partial_sum(start.begin(), start.end(), start.begin());
    std::vector<std::size_t> incident(start[n]);
    std::vector<std::size_t> fill(start.begin(), start.end() - 1);
    for (std::size_t f = 0; f + 2 < mesh.indices.size(); f += 3)
        if (distinct(f))
            for (int k = 0; k < 3; ++k)
                incident[fill[mesh.indices[f + k]]++] = f;

    // Around vertex v each triangle (v, a, b) links a and b; the fans are the connected groups of
    // these link vertices (union-find over the link vertices, numbered locally).
    std::size_t count = 0;
    std::vector<std::uint32_t> link;
    std::vector<std::uint32_t> parent;
    auto find = [&](std::uint32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    };
    for (std::size_t v = 0; v < n; ++v) {
        if (start[v + 1] - start[v] < 2)
            continue;
        link.clear();
        for (std::size_t i = start[v]; i < start[v + 1]; ++i)
            for (int k = 0; k < 3; ++k)
                if (mesh.indices[incident[i] + k] != v)
                    link.push_back(mesh.indices[incident[i] + k]);
        std::vector<std::uint32_t> ids(link);
        std::sort(ids.begin(), ids.end());
        ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
        parent.resize(ids.size());
        std::iota(parent.begin(), parent.end(), 0u);
        auto local = [&](std::uint32_t w) {
            return std::uint32_t(std::lower_bound(ids.begin(), ids.end(), w) - ids.begin());
        };
        std::size_t groups = ids.size();
        for (std::size_t i = 0; i + 1 < link.size(); i += 2) {
            const std::uint32_t a = find(local(link[i])), b = find(local(link[i + 1]));
            if (a != b) {
                parent[a] = b;
                --groups;
            }
        }
        if (groups > 1)
            ++count;
    }
    return count;
}

} // namespace

MeshTopology analyzeTopology(const TriangleMesh& mesh)
{
    MeshTopology t;
    t.vertices = mesh.vertexCount();
    t.triangles = mesh.triangleCount();
    // Key an undirected edge by (min, max); count uses and the uses in the (min -> max) direction.
    struct EdgeUse {
        int count = 0;
        int forward = 0;
    };
    std::unordered_map<std::uint64_t, EdgeUse> edges;
    edges.reserve(mesh.indices.size());
    for (std::size_t f = 0; f + 2 < mesh.indices.size(); f += 3) {
        const std::uint32_t v[3] = {mesh.indices[f], mesh.indices[f + 1], mesh.indices[f + 2]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
            ++t.degenerateTriangles;
        } else {
            const glm::vec3 n = glm::cross(mesh.positions[v[1]] - mesh.positions[v[0]],
                                           mesh.positions[v[2]] - mesh.positions[v[0]]);
            if (glm::dot(n, n) == 0.0f)
                ++t.degenerateTriangles;
        }
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = v[e], b = v[(e + 1) % 3];
            const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            auto& use = edges[key];
            ++use.count;
            if (a < b)
                ++use.forward;
        }
    }
    t.edges = edges.size();
    for (const auto& [key, use] : edges) {
        if (use.count == 1)
            ++t.boundaryEdges;
        else if (use.count > 2)
            ++t.nonManifoldEdges;
        else if (use.forward != 1)
            ++t.inconsistentEdges;
    }
    t.nonManifoldVertices = countNonManifoldVertices(mesh);
    t.eulerCharacteristic = (long long)t.vertices - (long long)t.edges + (long long)t.triangles;
    return t;
}

SurfaceDeviation measureSurfaceDeviation(const TriangleMesh& mesh,
                                         const std::function<double(const glm::dvec3&)>& sdf)
{
    SurfaceDeviation d;
    double sum = 0, sumSq = 0;
    auto add = [&](const glm::dvec3& p) {
        const double e = std::abs(sdf(p));
        d.maxAbs = std::max(d.maxAbs, e);
        sum += e;
        sumSq += e * e;
        ++d.samples;
    };
    for (const auto& p : mesh.positions)
        add(glm::dvec3(p));
    for (std::size_t f = 0; f + 2 < mesh.indices.size(); f += 3)
        add((glm::dvec3(mesh.positions[mesh.indices[f]]) + glm::dvec3(mesh.positions[mesh.indices[f + 1]]) +
             glm::dvec3(mesh.positions[mesh.indices[f + 2]])) / 3.0);
    if (d.samples) {
        d.meanAbs = sum / double(d.samples);
        d.rms = std::sqrt(sumSq / double(d.samples));
    }
    return d;
}

double computeEnclosedVolume(const TriangleMesh& mesh)
{
    double volume = 0;
    for (std::size_t f = 0; f + 2 < mesh.indices.size(); f += 3) {
        const glm::dvec3 a(mesh.positions[mesh.indices[f]]);
        const glm::dvec3 b(mesh.positions[mesh.indices[f + 1]]);
        const glm::dvec3 c(mesh.positions[mesh.indices[f + 2]]);
        volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    return volume;
}

TriangleAngleHistogram computeTriangleAngleHistogram(const TriangleMesh& mesh, int bins,
                                                     double sliverDeg)
{
    detail::checkMesh(mesh, "triangle angles");
    TriangleAngleHistogram h;
    bins = std::max(bins, 1);
    h.counts.assign(std::size_t(bins), 0);
    h.binWidthDeg = 180.0 / double(bins);
    h.sliverDeg = sliverDeg;
    h.minAngleDeg = std::numeric_limits<double>::infinity();
    h.maxAngleDeg = -std::numeric_limits<double>::infinity();
    for (std::size_t f = 0; f + 2 < mesh.indices.size(); f += 3) {
        const std::uint32_t* v = &mesh.indices[f];
        const glm::dvec3 p[3] = {glm::dvec3(mesh.positions[v[0]]), glm::dvec3(mesh.positions[v[1]]),
                                 glm::dvec3(mesh.positions[v[2]])};
        const double area2 = glm::length(glm::cross(p[1] - p[0], p[2] - p[0]));
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2] || !(area2 > 0)) {
            ++h.degenerateTriangles;
            continue;
        }
        for (int k = 0; k < 3; ++k) {
            const glm::dvec3 a = p[(k + 1) % 3] - p[k], b = p[(k + 2) % 3] - p[k];
            const double angle =
                std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * kDegreesPerRadian;
            const double snapped = angle + kBinEdgeSnapDeg;
            const auto bin = std::min<std::size_t>(std::size_t(snapped / h.binWidthDeg),
                                                   std::size_t(bins - 1));
            ++h.counts[bin];
            ++h.angles;
            h.slivers += snapped < sliverDeg ? 1 : 0;
            h.minAngleDeg = std::min(h.minAngleDeg, angle);
            h.maxAngleDeg = std::max(h.maxAngleDeg, angle);
        }
    }
    if (h.angles == 0) {
        h.minAngleDeg = h.maxAngleDeg = h.sliverFraction = std::numeric_limits<double>::quiet_NaN();
    } else {
        h.sliverFraction = double(h.slivers) / double(h.angles);
    }
    return h;
}

} // namespace rtlab::metrics
