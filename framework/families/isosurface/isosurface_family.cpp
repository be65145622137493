// The isosurface family. A run's scene is an analytic shape (sphere, box, torus)
// or an SDF model of a procedural scene ("csg_gallery/rotated_cube", "tomorrow_town/landscape").
// Its run is one frame of its own graph (pipeline/frame_graph.h; no screen-space frame start):
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

#include "core/error.h"
#include "core/strings.h"
#include "experiment/family.h"
#include "experiment/runner.h"
#include "meshio/meshio.h"
#include "metrics/mesh_metrics.h"
#include "pipeline/frame_graph.h"
#include "families/isosurface/isosurface.h"
#include "families/isosurface/stress_cases.h"
#include "scene/procedural.h"
#include "scene/sdf_shapes.h"
#include "sdf/evaluator.h"

#include <glm/gtc/quaternion.hpp>
#include <tbb/parallel_for.h>

#include <cmath>
#include <functional>
#include <optional>

namespace rtlab::families {

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

class IsosurfaceRun final : public experiment::FamilyRun {
public:
    explicit IsosurfaceRun(experiment::RunSetup& setup)
        : mRun(setup.run), mContext(setup.context), mFamily(setup.family.name),
          mParamPrefix(setup.paramPrefix), mSubject(resolveSubject(setup.run.scene))
    {
        mTechnique = experiment::createTechnique<plugin::IsosurfaceTechnique>(
            mRun, mContext.registry(), mFamily);
        addPasses(setup);
    }

    void describe(experiment::ResultRow& row) const override
    {
        experiment::addParamColumns(row, *mTechnique, mParamPrefix);
        row.set("exact_distance", mSubject.exactDistance);
    }

    void beginFrame(int, experiment::ResultRow& row) override { mRow = &row; }

    void endFrame(int, const std::vector<pipeline::PassRecord>& records,
                  experiment::ResultRow& row) override
    {
        for (const auto& r : records)
            if (r.name == "extract" && r.ran && r.time) {
                const double cells = double(mField.samples.x - 1) * double(mField.samples.y - 1) *
                                     double(mField.samples.z - 1);
                row.set("extract.mcells_per_s", cells / (r.time->cpuMs.median * 1e3));
            }
        row.set("cell_size", mField.spacing)
            .set("vertices", std::int64_t(mMesh.positions.size()))
            .set("triangles", std::int64_t(mMesh.indices.size() / 3));
        mRow = nullptr;
    }

private:
    void addPasses(experiment::RunSetup& setup)
    {
        pipeline::FrameGraph& graph = setup.graph;
        const Subject& subject = mSubject;
        const int grid = mRun.grid;
        const auto model = graph.addExternal<Subject>(
            "model", pipeline::ResourceType::value("sdf model"), &mSubject);
        graph.addExternal("feature_curves", subject.features.has_value(),
                          "model '" + subject.name + "' declares no sharp feature curves");
        // The field and mesh stay in the run (the row's cell size and counts read them after the
        // frame); the graph's resources are tokens that order the passes.
        graph.addPass(
            {.name = "evaluate_field",
             .reads = {model},
             .writes = {"field"},
             // One timed call, as the study's columns always had it (first use, no warm-up).
             .timing = pipeline::PassTiming::Repeated,
             .timingOptions = metrics::TimingOptions{.warmup = 0, .repeats = 1}},
            [this, grid] {
                if (mSubject.model) {
                    // The Dreams-style evaluator: pruned edit lists per 4x4x4 cell, a narrow band
                    // of exact values, Hermite data for dual contouring (sdf/evaluator.h).
                    mEvaluated = sdf::evaluateModel(
                        *mSubject.model, sdf::makeModelGrid(*mSubject.model, grid), sdf::kAllFrames,
                        {.computeHermite = true, .computeMaterials = true});
                    mField = mEvaluated->field;
                    const sdf::EvaluationStats& st = mEvaluated->stats;
                    mRow->set("evaluator.culling_rate", st.getCullingRate())
                        .set("evaluator.ideal_culling_rate", st.getIdealCullingRate())
                        .set("evaluator.samples_per_second", st.getSamplesPerSecond())
                        .set("evaluator.samples_in_band", std::int64_t(st.samplesInBand))
                        .set("evaluator.field_evaluations", std::int64_t(st.getFieldEvaluations()))
                        .set("evaluator.brute_force_evaluations",
                             std::int64_t(st.bruteForceEvaluations))
                        .set("evaluator.hermite_edges", std::int64_t(st.hermiteEdges))
                        .set("evaluator.field_ms", 1e3 * st.fieldSeconds)
                        .set("evaluator.hermite_ms", 1e3 * st.hermiteSeconds);
                } else {
                    mField = sampleShape(*mSubject.shape, grid);
                }
                return pipeline::PassOutcome{};
            });
        graph.addPass({.name = "extract",
                       .reads = {"field"},
                       .writes = {"mesh"},
                       .timing = pipeline::PassTiming::Repeated},
                      [this] {
                          plugin::IsosurfaceInput input;
                          input.field = &mField;
                          input.exactValue = mSubject.distance;
                          input.exactGradient = mSubject.gradient;
                          if (mEvaluated) {
                              input.hermite = &mEvaluated->hermite;
                              input.materials = &mEvaluated->materials;
                          }
                          mTechnique->extract(input, mMesh);
                          for (const auto& [name, value] : mTechnique->counters())
                              mRow->set("counter." + name, value);
                          return pipeline::PassOutcome{};
                      });
        graph.addPass({.name = "surface_samples",
                       .reads = {model},
                       .writes = {"surface_points"},
                       .measurement = true},
                      [this] {
                          mSurfacePoints = metrics::sampleSdfSurface(
                              mSubject.distance, mSubject.gradient, mSubject.boundsMin,
                              mSubject.boundsMax, kSurfacePoints);
                          return pipeline::PassOutcome{};
                      });
        auto metricPass = [&](const std::string& name, std::vector<pipeline::ResourceRef> reads,
                              std::function<void()> compute) {
            graph.addPass({.name = "metric." + name,
                           .reads = std::move(reads),
                           .writes = {"metric." + name},
                           .measurement = true},
                          [compute] {
                              compute();
                              return pipeline::PassOutcome{};
                          });
        };
        metricPass("deviation", {"mesh", model}, [this] {
            const auto deviation = metrics::measureSurfaceDeviation(mMesh, mSubject.distance);
            mRow->set("max_deviation", deviation.maxAbs)
                .set("mean_deviation", deviation.meanAbs)
                .set("rms_deviation", deviation.rms)
                .set("max_deviation_cells", deviation.maxAbs / mField.spacing);
            if (mSubject.volume)
                mRow->set("volume_rel_error",
                          (metrics::computeEnclosedVolume(mMesh) - *mSubject.volume) /
                              *mSubject.volume);
        });
        metricPass("topology", {"mesh"}, [this] {
            const auto topology = metrics::analyzeTopology(mMesh);
            mRow->set("boundary_edges", std::int64_t(topology.boundaryEdges))
                .set("non_manifold_edges", std::int64_t(topology.nonManifoldEdges))
                .set("inconsistent_edges", std::int64_t(topology.inconsistentEdges))
                .set("degenerate_triangles", std::int64_t(topology.degenerateTriangles))
                .set("euler_characteristic", std::int64_t(topology.eulerCharacteristic))
                .set("watertight", topology.watertight());
        });
        metricPass("chamfer", {"mesh", "surface_points"}, [this] {
            const auto d = metrics::measureMeshDistance(
                mMesh, mSubject.distance, mSurfacePoints,
                {.meshSamples = kMeshSamples, .cellSize = mField.spacing});
            mRow->set("chamfer.mean", d.chamferMean)
                .set("chamfer.rms", d.chamferRms)
                .set("hausdorff", d.hausdorff)
                .set("chamfer.mean_cells", d.chamferMeanCells)
                .set("hausdorff_cells", d.hausdorffCells);
        });
        metricPass("sharp_features", {"mesh", "feature_curves"}, [this] {
            // Tolerance of edge-F1: a tenth of a cell. Relative to the cell so that grids compare;
            // a tenth separates meshers that cut sharp edges (marching cubes misses them by a
            // fraction of a cell, ~0.2 on the gallery's cubes) from those that place vertices on
            // them.
            const double tolerance = 0.1 * mField.spacing;
            const auto score = metrics::measureSharpFeatures(
                mMesh, *mSubject.features, {.minCreaseDeg = 30.0, .tolerance = tolerance});
            mRow->set("edge.f1_tolerance", tolerance);
            // A shape without sharp features (a sphere) has no edge-Chamfer or edge-F1 to speak of:
            // the score against no curves is vacuous (0 and 1), so the row leaves them empty and
            // the report says so instead of drawing a chart of zeros.
            const bool none = mSubject.features->empty();
            const double nan = std::nan("");
            mRow->set("edge.feature_segments", std::int64_t(mSubject.features->size()));
            mRow->set("edge.chamfer", none ? nan : score.edgeChamfer)
                .set("edge.chamfer_cells", none ? nan : score.edgeChamfer / mField.spacing)
                .set("edge.f1", none ? nan : score.f1)
                .set("edge.precision", score.precision)
                .set("edge.recall", score.recall);
        });
        metricPass("triangle_quality", {"mesh"}, [this] {
            const auto h = metrics::computeTriangleAngleHistogram(mMesh, 18, 10.0);
            mRow->set("angle.min_deg", h.minAngleDeg)
                .set("angle.sliver_fraction", h.sliverFraction);
            std::string bins;
            for (std::size_t i = 0; i < h.counts.size(); ++i)
                bins += (i ? " " : "") + std::to_string(h.counts[i]);
            mRow->set("angle.histogram_10deg", bins);
        });
        metricPass("self_intersections", {"mesh"}, [this] {
            mRow->set("self_intersections",
                      std::int64_t(metrics::findSelfIntersections(mMesh).pairs));
        });
        graph.addPass({.name = "export",
                       .reads = {"mesh", "field"},
                       .writes = {"exports"},
                       .measurement = true},
                      [this] {
                          const std::string& runDirectory = mContext.runDirectory();
                          for (const char* extension : {"obj", "ply", "vtp"})
                              meshio::writeMesh(mMesh, runDirectory + "/mesh." + extension);
                          mRow->set("mesh_file", runDirectory + "/mesh.obj");
                          if (mField.values.size() <= kMaxVtiSamples) {
                              meshio::writeFieldVti(mField, runDirectory + "/field.vti");
                              mRow->set("field_file", runDirectory + "/field.vti");
                          }
                          return pipeline::PassOutcome{};
                      });

        setup.outputs.push_back("exports");
        for (const auto& m : setup.family.metrics)
            if (mRun.wantsMetric(m.name))
                setup.outputs.push_back("metric." + m.name);
    }

    const experiment::RunConfig& mRun;
    experiment::DriverContext& mContext;
    std::string mFamily;
    std::string mParamPrefix;
    Subject mSubject;
    std::unique_ptr<plugin::IsosurfaceTechnique> mTechnique;
    experiment::ResultRow* mRow = nullptr;
    plugin::SampledField mField;
    std::optional<sdf::EvaluationResult> mEvaluated;
    TriangleMesh mMesh;
    std::vector<glm::dvec3> mSurfacePoints;
};

class IsosurfaceFamily final : public experiment::Family {
public:
    std::unique_ptr<experiment::FamilyRun> beginRun(experiment::RunSetup& setup) const override
    {
        return std::make_unique<IsosurfaceRun>(setup);
    }
};

plugin::FamilyInfo describeIsosurfaceFamily()
{
    plugin::FamilyInfo info{
        .name = "isosurface",
        .summary = "triangle meshes from sampled signed distance fields",
        .input = "SDF samples on a regular grid (+ exact field for Hermite data)",
        .output = "indexed triangle mesh",
        .groundTruth = "the analytic SDF of the model",
        .metrics =
            {
                {"deviation",
                 "distance of the mesh to the exact surface (max, mean, RMS) and volume error"},
                {"topology",
                 "watertight, boundary / non-manifold / inconsistent edges, Euler characteristic"},
                {"chamfer", "two-sided Chamfer and Hausdorff distance to a dense sampling of the "
                            "exact surface"},
                {"sharp_features", "edge-Chamfer and edge-F1 on the model's sharp features"},
                {"triangle_quality", "triangle-angle histogram and minimum angle"},
                {"self_intersections", "pairs of intersecting triangles (Embree collide)"},
            },
    };
    info.domain = plugin::FamilyDomain::Volume;
    info.report = {
        .cost = "extract.cpu_ms",
        .costLabel = "CPU time of the extraction (ms, median)",
        .error = "chamfer.mean",
        .errorLabel = "Chamfer distance to the true surface (mean, world units)",
        .passes = {"evaluate_field.cpu_ms", "extract.cpu_ms"},
        .passTimeLabel = "CPU time (ms, median)",
        .extraErrors = {{"hausdorff", "Hausdorff distance to the true surface (world units)"},
                        {"edge.chamfer",
                         "edge-Chamfer distance to the sharp features (world units)"}},
        .tableColumns = {"grid", "hausdorff", "rms_deviation", "edge.chamfer", "edge.f1",
                         "watertight", "boundary_edges", "non_manifold_edges", "self_intersections",
                         "angle.min_deg", "angle.sliver_fraction",
                         "counter.vertices_left_cell_share", "extract.mcells_per_s",
                         "evaluator.culling_rate", "evaluator.ideal_culling_rate"},
        .convergence = true,
        .histograms = {{.column = "angle.histogram_10deg",
                        .name = "angles",
                        .title = "triangle angles",
                        .xLabel = "interior angle (degrees, bin centre)",
                        .xRange = 180.0,
                        .caption =
                            "Triangle interior angles at the finest grid: share per 10-degree bin. "
                            "Slivers pile up near 0 and 180."}},
    };
    info.runtime = std::make_shared<IsosurfaceFamily>();
    info.stressCases = isosurface::makeIsosurfaceStressCases;
    return info;
}

} // namespace
} // namespace rtlab::families

RTLAB_REGISTER_FAMILY(isosurface, rtlab::families::describeIsosurfaceFamily)
