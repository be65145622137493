// Deterministic point sampling of meshes (area-uniform) and of SDF zero sets (band projection).

#include "metrics/mesh_metrics.h"

#include "metrics/mesh_metrics_detail.h"

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace rtlab::metrics {

std::vector<MeshSample> sampleMeshSurface(const TriangleMesh& mesh, std::size_t count,
                                          std::uint64_t seed)
{
    const std::size_t triangles = mesh.triangleCount();
    std::vector<double> cumulative(triangles);
    double total = 0;
    for (std::size_t t = 0; t < triangles; ++t) {
        glm::dvec3 v[3];
        detail::loadTriangle(mesh, t, v);
        const double area = 0.5 * glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
        total += std::isfinite(area) ? area : 0.0;
        cumulative[t] = total;
    }
    std::vector<MeshSample> samples;
    if (count == 0 || !(total > 0))
        return samples;
    samples.resize(count);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const double u = (double(i) + detail::hashToUnit(seed, i, 0)) / double(count);
            const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), u * total);
            // upper_bound skips zero-area triangles (their cumulative value repeats).
            const std::size_t t = std::min<std::size_t>(it - cumulative.begin(), triangles - 1);
            const double s = std::sqrt(detail::hashToUnit(seed, i, 1));
            const double r = detail::hashToUnit(seed, i, 2);
            const glm::dvec3 w(1.0 - s, s * (1.0 - r), s * r);
            glm::dvec3 v[3];
            detail::loadTriangle(mesh, t, v);
            samples[i] = {w.x * v[0] + w.y * v[1] + w.z * v[2], w, std::uint32_t(t)};
        }
    });
    return samples;
}

std::vector<glm::dvec3> sampleSdfSurface(const ScalarField& sdf, const VectorField& gradient,
                                         const glm::dvec3& boundsMin, const glm::dvec3& boundsMax,
                                         std::size_t count, std::uint64_t seed,
                                         const SdfSurfaceSampling& options)
{
    const glm::dvec3 extent = boundsMax - boundsMin;
    const double diagonal = glm::length(extent);
    const double band = options.band > 0 ? options.band : 0.01 * diagonal;
    const double tolerance = options.tolerance > 0 ? options.tolerance : 1e-12 * diagonal;
    const std::size_t maxCandidates =
        options.maxCandidates > 0 ? options.maxCandidates : 4000 * std::max<std::size_t>(count, 1);

    auto project = [&](std::size_t index) -> std::optional<glm::dvec3> {
        glm::dvec3 p = boundsMin + extent * glm::dvec3(detail::hashToUnit(seed, index, 0),
                                                       detail::hashToUnit(seed, index, 1),
                                                       detail::hashToUnit(seed, index, 2));
        double f = sdf(p);
        if (!(std::abs(f) <= band))
            return std::nullopt;
        for (int k = 0; k < options.newtonIterations && !(std::abs(f) <= tolerance); ++k) {
            const glm::dvec3 g = gradient(p);
            const double gg = glm::dot(g, g);
            if (!(gg > 0) || !std::isfinite(gg))
                return std::nullopt;
            p -= (f / gg) * g;
            f = sdf(p);
        }
        if (!(std::abs(f) <= tolerance))
            return std::nullopt;
        return p;
    };

    // Candidates in fixed blocks, accepted in index order: the result does not depend on threads.
    std::vector<glm::dvec3> points;
    points.reserve(count);
    const std::size_t block = std::max<std::size_t>(std::size_t(1) << 14, 4 * count);
    std::vector<std::optional<glm::dvec3>> results;
    for (std::size_t start = 0; start < maxCandidates && points.size() < count; start += block) {
        const std::size_t end = std::min(maxCandidates, start + block);
        results.assign(end - start, std::nullopt);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(start, end), [&](const auto& range) {
            for (std::size_t i = range.begin(); i != range.end(); ++i)
                results[i - start] = project(i);
        });
        for (const auto& r : results)
            if (r && points.size() < count)
                points.push_back(*r);
    }
    return points;
}

} // namespace rtlab::metrics
