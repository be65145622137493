// Two-sided mesh <-> SDF zero-set distances and the normal angle error.

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
#include <string>

namespace rtlab::metrics {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDegreesPerRadian = 57.29577951308232;

//! Max, mean and RMS of the values, summed in order (deterministic).
OneSidedDistance summarise(const std::vector<double>& values)
{
    OneSidedDistance d;
    d.samples = values.size();
    if (values.empty())
        return d;
    double sum = 0, sumSq = 0;
    for (const double v : values) {
        d.max = std::max(d.max, v);
        sum += v;
        sumSq += v * v;
    }
    d.mean = sum / double(values.size());
    d.rms = std::sqrt(sumSq / double(values.size()));
    return d;
}

OneSidedDistance makeInfinite(std::size_t samples)
{
    return {kInf, kInf, kInf, samples};
}

template <class Work>
void runParallel(std::size_t count, const Work& work)
{
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count), [&](const auto& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i)
            work(i);
    });
}

//! Angle in degrees between two non-zero vectors, by atan2 (accurate near 0 and 180).
double measureAngleDeg(const glm::dvec3& a, const glm::dvec3& b)
{
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * kDegreesPerRadian;
}

bool isFiniteNonZero(const glm::dvec3& v)
{
    const double n = glm::dot(v, v);
    return n > 0 && std::isfinite(n);
}

} // namespace

MeshDistance measureMeshDistance(const TriangleMesh& mesh, const ScalarField& sdf,
                                 const std::vector<glm::dvec3>& surfacePoints,
                                 const MeshDistanceOptions& options)
{
    detail::checkMesh(mesh, "mesh distance");
    if (surfacePoints.empty())
        throw Error("metrics: mesh distance: no surface points were given");
    if (options.meshSamples == 0)
        throw Error("metrics: mesh distance: meshSamples must be positive");

    MeshDistance result;
    const auto samples = sampleMeshSurface(mesh, options.meshSamples, options.seed);
    if (samples.empty()) {
        result.meshToSurface = makeInfinite(0);
        result.surfaceToMesh = makeInfinite(surfacePoints.size());
    } else {
        std::vector<double> toSurface(samples.size());
        runParallel(samples.size(),
                    [&](std::size_t i) { toSurface[i] = std::abs(sdf(samples[i].position)); });
        result.meshToSurface = summarise(toSurface);

        std::vector<detail::Box> boxes(mesh.triangleCount());
        for (std::size_t t = 0; t < boxes.size(); ++t) {
            glm::dvec3 v[3];
            detail::loadTriangle(mesh, t, v);
            boxes[t] = {glm::min(v[0], glm::min(v[1], v[2])), glm::max(v[0], glm::max(v[1], v[2]))};
        }
        const detail::PrimitiveBvh bvh(boxes);
        const detail::PrimitiveBvh::DistanceFunction distance = [&](std::uint32_t t,
                                                                    const glm::dvec3& p) {
            glm::dvec3 v[3];
            detail::loadTriangle(mesh, t, v);
            return glm::length(p - detail::findClosestPointOnTriangle(p, v[0], v[1], v[2]));
        };
        std::vector<double> toMesh(surfacePoints.size());
        runParallel(surfacePoints.size(), [&](std::size_t i) {
            toMesh[i] = bvh.findNearestDistance(surfacePoints[i], distance);
        });
        result.surfaceToMesh = summarise(toMesh);
    }

    const OneSidedDistance& a = result.meshToSurface;
    const OneSidedDistance& b = result.surfaceToMesh;
    result.hausdorff = std::max(a.max, b.max);
    result.chamferMean = 0.5 * (a.mean + b.mean);
    result.chamferRms = std::sqrt(0.5 * (a.rms * a.rms + b.rms * b.rms));
    result.cellSize = options.cellSize;
    const bool hasCell = options.cellSize > 0;
    result.hausdorffCells = hasCell ? result.hausdorff / options.cellSize : kNaN;
    result.chamferMeanCells = hasCell ? result.chamferMean / options.cellSize : kNaN;
    result.chamferRmsCells = hasCell ? result.chamferRms / options.cellSize : kNaN;
    return result;
}

NormalError measureNormalError(const TriangleMesh& mesh, const VectorField& gradient,
                               const NormalErrorOptions& options)
{
    detail::checkMesh(mesh, "normal error");
    const bool interpolated = options.source == MeshNormalSource::Interpolated;
    if (interpolated && mesh.normals.size() != mesh.positions.size())
        throw Error("metrics: normal error: interpolated normals need one normal per position, "
                    "but the mesh has " + std::to_string(mesh.normals.size()) + " normals for " +
                    std::to_string(mesh.positions.size()) + " positions");

    const auto samples = sampleMeshSurface(mesh, options.samples, options.seed);
    std::vector<double> angles(samples.size(), kNaN);
    runParallel(samples.size(), [&](std::size_t i) {
        const MeshSample& s = samples[i];
        glm::dvec3 normal;
        if (interpolated) {
            normal = glm::dvec3(0.0);
            for (int k = 0; k < 3; ++k)
                normal +=
                    s.barycentric[k] * glm::dvec3(mesh.normals[mesh.indices[3 * s.triangle + k]]);
        } else {
            glm::dvec3 v[3];
            detail::loadTriangle(mesh, s.triangle, v);
            normal = glm::cross(v[1] - v[0], v[2] - v[0]);
        }
        const glm::dvec3 g = gradient(s.position);
        if (isFiniteNonZero(normal) && isFiniteNonZero(g))
            angles[i] = measureAngleDeg(normal, g);
    });

    NormalError e;
    double sum = 0, sumSq = 0;
    for (const double a : angles) {
        if (std::isnan(a)) {
            ++e.skipped;
            continue;
        }
        ++e.samples;
        e.maxDeg = std::max(e.maxDeg, a);
        sum += a;
        sumSq += a * a;
    }
    if (e.samples == 0)
        return {kNaN, kNaN, kNaN, 0, e.skipped};
    e.meanDeg = sum / double(e.samples);
    e.rmsDeg = std::sqrt(sumSq / double(e.samples));
    return e;
}

} // namespace rtlab::metrics
