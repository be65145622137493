// The isosurface family in experiments: sample an analytic shape on a grid, extract a mesh with
// the run's technique, and measure it against the exact distance field.

#include "experiment/runner.h"

#include "core/error.h"
#include "metrics/mesh_metrics.h"
#include "metrics/timing.h"
#include "plugin/isosurface.h"
#include "scene/sdf_shapes.h"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>

namespace rtlab::experiment {

namespace {

//! Samples `shape` on grid^3 points covering its bounds (a cube, so cells are cubes).
plugin::SampledField sampleShape(const scene::AnalyticShape& shape, int grid)
{
    plugin::SampledField field;
    const glm::dvec3 extent = shape.boundsMax - shape.boundsMin;
    const double side = std::max({extent.x, extent.y, extent.z});
    const glm::dvec3 center = 0.5 * (shape.boundsMin + shape.boundsMax);
    field.samples = glm::ivec3(grid);
    field.spacing = side / double(grid - 1);
    field.origin = center - glm::dvec3(0.5 * side);
    field.values.resize(std::size_t(grid) * grid * grid);
    tbb::parallel_for(0, grid, [&](int z) {
        for (int y = 0; y < grid; ++y)
            for (int x = 0; x < grid; ++x)
                field.values[field.index(x, y, z)] = float(shape.distance(field.position(x, y, z)));
    });
    return field;
}

} // namespace

std::vector<ResultRow> runIsosurfaceFamily(const RunConfig& run, const std::string& family,
                                           DriverContext& context, const ResultRow& common)
{
    const plugin::Registry& registry = context.registry();
    const std::string& runDirectory = context.runDirectory();
    ResultRow row = common;
    const scene::AnalyticShape* shape = scene::findAnalyticShape(run.scene);
    if (!shape)
        throw Error("scene '" + run.scene + "' is not an analytic shape the isosurface family can use");
    const TechniqueChoice& choice = run.techniques.at(family);
    const plugin::TechniqueEntry* entry = registry.findTechnique(family, choice.technique);
    auto technique = entry->create(choice.params);
    auto* mesher = dynamic_cast<plugin::IsosurfaceTechnique*>(technique.get());
    if (!mesher)
        throw Error("technique '" + choice.technique + "' does not implement the isosurface interface");
    const config::ParamSet effective = technique->effectiveParams();
    for (const auto& [name, value] : effective.values())
        row.set("param." + name, config::formatValue(value));

    // Pass 1: sample the field (framework work, shared by every technique).
    plugin::SampledField field;
    const auto sampleReport = metrics::measure({.warmup = 0, .repeats = 1}, [&] {
        field = sampleShape(*shape, run.grid);
        return metrics::GpuPassTimes{};
    });
    addTimingColumns(row, "sample_field", sampleReport);

    // Pass 2: the technique.
    plugin::IsosurfaceInput input;
    input.field = &field;
    input.exactValue = [shape](const glm::dvec3& p) { return shape->distance(p); };
    input.exactGradient = [shape](const glm::dvec3& p) { return shape->gradient(p); };
    TriangleMesh mesh;
    const auto report = metrics::measure(run.timing, [&] {
        mesher->extract(input, mesh);
        return metrics::GpuPassTimes{};
    });
    addTimingColumns(row, "extract", report);
    PassLog passes;
    passes.add("sample_field");
    passes.add("extract");
    passes.write(row);

    // Metrics against the exact distance field.
    const auto deviation =
        metrics::measureSurfaceDeviation(mesh, [shape](const glm::dvec3& p) { return shape->distance(p); });
    const auto topology = metrics::analyzeTopology(mesh);
    const double trueVolume = shape->volume();
    row.set("cell_size", field.spacing)
        .set("vertices", std::int64_t(topology.vertices))
        .set("triangles", std::int64_t(topology.triangles))
        .set("max_deviation", deviation.maxAbs)
        .set("mean_deviation", deviation.meanAbs)
        .set("rms_deviation", deviation.rms)
        .set("max_deviation_cells", deviation.maxAbs / field.spacing)
        .set("volume_rel_error", (metrics::computeEnclosedVolume(mesh) - trueVolume) / trueVolume)
        .set("boundary_edges", std::int64_t(topology.boundaryEdges))
        .set("non_manifold_edges", std::int64_t(topology.nonManifoldEdges))
        .set("inconsistent_edges", std::int64_t(topology.inconsistentEdges))
        .set("degenerate_triangles", std::int64_t(topology.degenerateTriangles))
        .set("euler_characteristic", std::int64_t(topology.eulerCharacteristic))
        .set("watertight", topology.watertight());
    const std::string meshPath = runDirectory + "/mesh.obj";
    writeObj(mesh, meshPath);
    row.set("mesh_file", meshPath);
    return {row};
}

} // namespace rtlab::experiment
