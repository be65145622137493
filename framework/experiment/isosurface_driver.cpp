// The isosurface family in experiments. A run's scene is an analytic shape (sphere, box, torus)
// or an SDF model of a procedural scene ("csg_gallery/rotated_cube", "tomorrow_town/landscape").
// The run is one frame graph (pipeline/frame_graph.h):
//   evaluate_field   the model's field on the grid: for SDF models the hierarchical evaluator
//                    (sdf/evaluator.h: culling rate, samples per second, Hermite data), for
//                    analytic shapes the exact distance at every sample
//   extract          the technique (timed: median and IQR of the run's repeats)
//   surface_samples  points on the exact zero set (only when the Chamfer metric is asked for)
//   metric.*         one pass per metric the run asks for
//   export           mesh.obj, mesh.ply, mesh.vtp, and the field as field.vti (grids <= 128^3)
// Distances to the exact surface use |f| of the model's field at mesh points: exact for the
// analytic shapes and for single-primitive models, a lower bound where CSG makes f a bound
// (subtraction, intersection, soft blends); the row says which (`exact_distance`). The other half
// of the Chamfer distance (exact surface points to the mesh) is exact in every case.

#include "experiment/runner.h"

#include "core/error.h"
#include "core/strings.h"
#include "meshio/meshio.h"
#include "metrics/mesh_metrics.h"
#include "metrics/timing.h"
#include "pipeline/frame_graph.h"
#include "plugin/isosurface.h"
#include "scene/procedural.h"
#include "scene/sdf_shapes.h"
#include "sdf/evaluator.h"

#include <glm/gtc/quaternion.hpp>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <optional>

namespace rtlab::experiment {

namespace {

//! What a run meshes: the field, its exact version and what is known about its surface.
struct Subject {
    std::string name;
    const scene::AnalyticShape* shape = nullptr;
    std::optional<scene::SdfModel> model;
    std::function<double(const glm::dvec3&)> distance;
    std::function<glm::dvec3(const glm::dvec3&)> gradient;
    glm::dvec3 boundsMin{0.0}, boundsMax{0.0};
    bool exactDistance = true;
    std::optional<double> volume;
    std::optional<std::vector<metrics::FeatureSegment>> features; //!< empty optional = unknown
};

// CSG edits whose result is an exact distance on its own: one additive primitive (not the
// ellipsoid, whose value is a bound).
bool isExactDistance(const scene::SdfModel& model)
{
    return model.edits.size() == 1 && model.edits[0].op == scene::CsgOp::Add &&
           model.edits[0].shape != scene::CsgShape::Ellipsoid;
}

Subject resolveSubject(const std::string& name)
{
    Subject s;
    s.name = name;
    if (const scene::AnalyticShape* shape = scene::findAnalyticShape(name)) {
        s.shape = shape;
        s.distance = [shape](const glm::dvec3& p) { return shape->distance(p); };
        s.gradient = [shape](const glm::dvec3& p) { return shape->gradient(p); };
        s.boundsMin = shape->boundsMin;
        s.boundsMax = shape->boundsMax;
        s.volume = shape->volume();
        std::vector<metrics::FeatureSegment> features;
        if (shape->kind == scene::ShapeKind::Box)
            features = metrics::makeBoxFeatureEdges(shape->center, shape->size);
        s.features = features; // sphere and torus: smooth, no features
        return s;
    }
    const auto slash = name.find('/');
    if (slash == std::string::npos)
        throw Error(
            "scene '" + name + "' is neither an analytic shape (" +
            joinList(scene::analyticShapeNames()) +
            ") nor an SDF model named <procedural scene>/<model> (e.g. csg_gallery/rotated_cube)");
    const scene::Scene parent = scene::makeProceduralScene(name.substr(0, slash));
    const std::string modelName = name.substr(slash + 1);
    for (const auto& m : parent.sdfModels)
        if (m.name == modelName)
            s.model = m;
    if (!s.model)
        throw Error("scene '" + name.substr(0, slash) + "' has no SDF model '" + modelName + "'");
    const sdf::ExactFunctions exact = sdf::makeExactFunctions(*s.model);
    s.distance = exact.value;
    s.gradient = exact.gradient;
    s.boundsMin = s.model->boundsMin;
    s.boundsMax = s.model->boundsMax;
    s.exactDistance = isExactDistance(*s.model);
    if (s.model->featuresKnown) {
        std::vector<metrics::FeatureSegment> features;
        for (const auto& [a, b] : s.model->featureEdges)
            features.push_back({a, b});
        s.features = features;
    }
    return s;
}

//! Samples an analytic shape on grid^3 points covering its bounds (a cube, so cells are cubes).
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

constexpr std::size_t kSurfacePoints = 50000; // exact surface points for the Chamfer distance
constexpr std::size_t kMeshSamples = 50000;   // area-uniform mesh samples for it
constexpr std::size_t kMaxVtiSamples = 129u * 129u * 129u; // fields above this are not exported

} // namespace

std::vector<ResultRow> runIsosurfaceFamily(const RunConfig& run, const std::string& family,
                                           DriverContext& context, const ResultRow& common)
{
    const plugin::Registry& registry = context.registry();
    const std::string& runDirectory = context.runDirectory();
    ResultRow row = common;
    const Subject subject = resolveSubject(run.scene);
    const TechniqueChoice& choice = run.techniques.at(family);
    const plugin::TechniqueEntry* entry = registry.findTechnique(family, choice.technique);
    auto technique = entry->create(choice.params);
    auto* mesher = dynamic_cast<plugin::IsosurfaceTechnique*>(technique.get());
    if (!mesher)
        throw Error("technique '" + choice.technique +
                    "' does not implement the isosurface interface");
    const config::ParamSet effective = technique->effectiveParams();
    for (const auto& [name, value] : effective.values())
        row.set("param." + name, config::formatValue(value));
    row.set("exact_distance", subject.exactDistance);

    plugin::SampledField field;
    std::optional<sdf::EvaluationResult> evaluated;
    TriangleMesh mesh;
    std::vector<glm::dvec3> surfacePoints;

    pipeline::FrameGraph graph;
    graph.addExternal("model");
    graph.addExternal("feature_curves", subject.features.has_value(),
                      "model '" + subject.name + "' declares no sharp feature curves");
    graph.addPass({.name = "evaluate_field", .reads = {"model"}, .writes = {"field"}}, [&] {
        const auto report = metrics::measure({.warmup = 0, .repeats = 1}, [&] {
            if (subject.model) {
                // The Dreams-style evaluator: pruned edit lists per 4x4x4 cell, a narrow band of
                // exact values, Hermite data for dual contouring (sdf/evaluator.h).
                evaluated = sdf::evaluateModel(
                    *subject.model, sdf::makeModelGrid(*subject.model, run.grid), sdf::kAllFrames,
                    {.computeHermite = true, .computeMaterials = true});
                field = evaluated->field;
            } else {
                field = sampleShape(*subject.shape, run.grid);
            }
            return metrics::GpuPassTimes{};
        });
        addTimingColumns(row, "evaluate_field", report);
        if (evaluated) {
            const sdf::EvaluationStats& st = evaluated->stats;
            row.set("evaluator.culling_rate", st.getCullingRate())
                .set("evaluator.samples_per_second", st.getSamplesPerSecond())
                .set("evaluator.samples_in_band", std::int64_t(st.samplesInBand))
                .set("evaluator.field_evaluations", std::int64_t(st.getFieldEvaluations()))
                .set("evaluator.brute_force_evaluations", std::int64_t(st.bruteForceEvaluations))
                .set("evaluator.hermite_edges", std::int64_t(st.hermiteEdges))
                .set("evaluator.field_ms", 1e3 * st.fieldSeconds)
                .set("evaluator.hermite_ms", 1e3 * st.hermiteSeconds);
        }
        return pipeline::PassOutcome{};
    });
    graph.addPass({.name = "extract", .reads = {"field"}, .writes = {"mesh"}}, [&] {
        plugin::IsosurfaceInput input;
        input.field = &field;
        input.exactValue = subject.distance;
        input.exactGradient = subject.gradient;
        if (evaluated) {
            input.hermite = &evaluated->hermite;
            input.materials = &evaluated->materials;
        }
        const auto report = metrics::measure(run.timing, [&] {
            mesher->extract(input, mesh);
            return metrics::GpuPassTimes{};
        });
        addTimingColumns(row, "extract", report);
        const double cells =
            double(field.samples.x - 1) * double(field.samples.y - 1) * double(field.samples.z - 1);
        row.set("extract.mcells_per_s", cells / (report.cpuMs.median * 1e3));
        for (const auto& [name, value] : technique->counters())
            row.set("counter." + name, value);
        return pipeline::PassOutcome{};
    });
    graph.addPass({.name = "surface_samples", .reads = {"model"}, .writes = {"surface_points"}},
                  [&] {
                      surfacePoints = metrics::sampleSdfSurface(subject.distance, subject.gradient,
                                                                subject.boundsMin,
                                                                subject.boundsMax, kSurfacePoints);
                      return pipeline::PassOutcome{};
                  });
    auto metricPass = [&](const std::string& name, std::vector<std::string> reads, auto&& compute) {
        graph.addPass(
            {.name = "metric." + name, .reads = std::move(reads), .writes = {"metric." + name}},
            [&, compute] {
                compute();
                return pipeline::PassOutcome{};
            });
    };
    metricPass("deviation", {"mesh", "model"}, [&] {
        const auto deviation = metrics::measureSurfaceDeviation(mesh, subject.distance);
        row.set("max_deviation", deviation.maxAbs)
            .set("mean_deviation", deviation.meanAbs)
            .set("rms_deviation", deviation.rms)
            .set("max_deviation_cells", deviation.maxAbs / field.spacing);
        if (subject.volume)
            row.set("volume_rel_error",
                    (metrics::computeEnclosedVolume(mesh) - *subject.volume) / *subject.volume);
    });
    metricPass("topology", {"mesh"}, [&] {
        const auto topology = metrics::analyzeTopology(mesh);
        row.set("boundary_edges", std::int64_t(topology.boundaryEdges))
            .set("non_manifold_edges", std::int64_t(topology.nonManifoldEdges))
            .set("inconsistent_edges", std::int64_t(topology.inconsistentEdges))
            .set("degenerate_triangles", std::int64_t(topology.degenerateTriangles))
            .set("euler_characteristic", std::int64_t(topology.eulerCharacteristic))
            .set("watertight", topology.watertight());
    });
    metricPass("chamfer", {"mesh", "surface_points"}, [&] {
        const auto d =
            metrics::measureMeshDistance(mesh, subject.distance, surfacePoints,
                                         {.meshSamples = kMeshSamples, .cellSize = field.spacing});
        row.set("chamfer.mean", d.chamferMean)
            .set("chamfer.rms", d.chamferRms)
            .set("hausdorff", d.hausdorff)
            .set("chamfer.mean_cells", d.chamferMeanCells)
            .set("hausdorff_cells", d.hausdorffCells);
    });
    metricPass("sharp_features", {"mesh", "feature_curves"}, [&] {
        // Tolerance of edge-F1: a tenth of a cell. Relative to the cell so that grids compare; a
        // tenth separates meshers that cut sharp edges (marching cubes misses them by a fraction
        // of a cell, ~0.2 on the gallery's cubes) from those that place vertices on them.
        const double tolerance = 0.1 * field.spacing;
        const auto score = metrics::measureSharpFeatures(
            mesh, *subject.features, {.minCreaseDeg = 30.0, .tolerance = tolerance});
        row.set("edge.f1_tolerance", tolerance);
        row.set("edge.chamfer", score.edgeChamfer)
            .set("edge.chamfer_cells", score.edgeChamfer / field.spacing)
            .set("edge.f1", score.f1)
            .set("edge.precision", score.precision)
            .set("edge.recall", score.recall);
    });
    metricPass("triangle_quality", {"mesh"}, [&] {
        const auto h = metrics::computeTriangleAngleHistogram(mesh, 18, 10.0);
        row.set("angle.min_deg", h.minAngleDeg).set("angle.sliver_fraction", h.sliverFraction);
        std::string bins;
        for (std::size_t i = 0; i < h.counts.size(); ++i)
            bins += (i ? " " : "") + std::to_string(h.counts[i]);
        row.set("angle.histogram_10deg", bins);
    });
    metricPass("self_intersections", {"mesh"}, [&] {
        row.set("self_intersections", std::int64_t(metrics::findSelfIntersections(mesh).pairs));
    });
    graph.addPass({.name = "export", .reads = {"mesh", "field"}, .writes = {"exports"}}, [&] {
        for (const char* extension : {"obj", "ply", "vtp"})
            meshio::writeMesh(mesh, runDirectory + "/mesh." + extension);
        row.set("mesh_file", runDirectory + "/mesh.obj");
        if (field.values.size() <= kMaxVtiSamples) {
            meshio::writeFieldVti(field, runDirectory + "/field.vti");
            row.set("field_file", runDirectory + "/field.vti");
        }
        return pipeline::PassOutcome{};
    });

    std::vector<std::string> outputs = {"exports"};
    for (const auto& m : registry.findFamily(family)->metrics)
        if (run.wantsMetric(m.name))
            outputs.push_back("metric." + m.name);
    const auto records = graph.execute(scene::FeatureSet{}, outputs);
    PassLog passes;
    for (const auto& r : records)
        r.ran ? passes.add(r.name) : passes.skip(r.name, r.reason);
    passes.write(row);
    row.set("cell_size", field.spacing)
        .set("vertices", std::int64_t(mesh.positions.size()))
        .set("triangles", std::int64_t(mesh.indices.size() / 3));
    return {row};
}

} // namespace rtlab::experiment
