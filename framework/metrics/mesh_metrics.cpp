#include "metrics/mesh_metrics.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <unordered_map>

namespace rtlab::metrics {

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

} // namespace rtlab::metrics
