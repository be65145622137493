// The isosurface family's frame graph on real models with the real marching cubes: the evaluator's
// columns, the metrics a run asks for, the feature metrics' dependence on declared features, and
// the exported files.

#include "experiment/analysis.h"
#include "experiment/runner.h"
#include "plugin/technique.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace rtlab {
namespace {

std::vector<experiment::Row> runStudy(const std::string& name, const std::string& text)
{
    const auto dir = std::filesystem::temp_directory_path() / ("rtlab_isosurface_driver_" + name);
    std::filesystem::remove_all(dir);
    const auto& registry = plugin::builtinRegistry();
    const auto e = experiment::parseExperiment(text, (dir / "study.yaml").string(), registry);
    experiment::runExperiment(
        e, registry,
        {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    return experiment::loadResults(dir.string());
}

TEST(IsosurfaceDriver, MeshesAGalleryModelThroughTheEvaluatorWithEveryMetric)
{
    const auto rows = runStudy("gallery", R"(base:
  scene: csg_gallery/cube
  grid: 24
  timing: {warmup: 0, repeats: 1}
  techniques: {isosurface: {technique: marching_cubes}}
)");
    ASSERT_EQ(rows.size(), 1u);
    const auto& row = rows[0];
    ASSERT_EQ(row.at("status"), "ok") << row.at("error");
    EXPECT_EQ(row.at("passes").find("evaluate_field:run;extract:run;surface_samples:run"), 0u)
        << row.at("passes");
    EXPECT_EQ(row.at("passes_skipped"), "0") << row.at("passes");
    // The evaluator ran and culled (0.21 at 24 samples: coarse grids leave little to cull; its
    // own tests bound the rate at 128 samples).
    EXPECT_GT(experiment::getNumber(row, "evaluator.culling_rate"), 0.0);
    EXPECT_GT(experiment::getNumber(row, "evaluator.hermite_edges"), 0.0);
    EXPECT_EQ(row.at("exact_distance"), "true");
    EXPECT_EQ(row.at("watertight"), "true");
    // A cube's 12 edges: marching cubes cuts them, but within a cell (tolerance of edge-F1).
    const double cell = experiment::getNumber(row, "cell_size");
    EXPECT_GT(experiment::getNumber(row, "edge.recall"), 0.5);
    EXPECT_LT(experiment::getNumber(row, "chamfer.mean"), cell);
    EXPECT_LT(experiment::getNumber(row, "hausdorff"), cell);
    EXPECT_EQ(experiment::getNumber(row, "self_intersections"), 0.0);
    for (const char* file : {"mesh.obj", "mesh.ply", "mesh.vtp", "field.vti"})
        EXPECT_TRUE(std::filesystem::exists(
            std::filesystem::path(row.at("mesh_file")).parent_path() / file))
            << file;
}

TEST(IsosurfaceDriver,
     SkipsTheFeatureMetricForAModelWithoutDeclaredFeaturesAndWhatTheRunDoesNotAskFor)
{
    const auto rows = runStudy("landscape", R"(base:
  scene: tomorrow_town/landscape
  grid: 24
  metrics: [topology, sharp_features]
  timing: {warmup: 0, repeats: 1}
  techniques: {isosurface: {technique: marching_cubes}}
)");
    ASSERT_EQ(rows.size(), 1u);
    const auto& row = rows[0];
    ASSERT_EQ(row.at("status"), "ok") << row.at("error");
    const std::string& passes = row.at("passes");
    EXPECT_NE(
        passes.find("metric.sharp_features:skipped(input 'feature_curves' is not available: model "
                    "'tomorrow_town/landscape' declares no sharp feature curves)"),
        std::string::npos)
        << passes;
    EXPECT_NE(passes.find("surface_samples:skipped(no consumer"), std::string::npos) << passes;
    EXPECT_NE(passes.find("metric.topology:run"), std::string::npos) << passes;
    EXPECT_EQ(row.count("chamfer.mean"), 0u);
    EXPECT_EQ(row.at("exact_distance"), "false") << "a CSG landscape's field is a distance bound";
}

// A smooth shape has no sharp features: its edge-Chamfer and edge-F1 are left empty (the score
// against no curves would be a vacuous 0 and 1), a box's are measured.
TEST(IsosurfaceDriver, EdgeMetricsOnlyWhereTheShapeHasSharpFeatures)
{
    const auto rows = runStudy("edges", R"(base:
  scene: sphere
  grid: 24
  timing: {warmup: 0, repeats: 1}
  techniques: {isosurface: {technique: marching_cubes}}
sweep:
  scene: [sphere, box]
)");
    ASSERT_EQ(rows.size(), 2u);
    for (const auto& row : rows) {
        ASSERT_EQ(row.at("status"), "ok") << row.at("error");
        const bool box = row.at("scene") == "box";
        EXPECT_EQ(experiment::getNumber(row, "edge.feature_segments"), box ? 12.0 : 0.0) << row.at("scene");
        EXPECT_EQ(std::isfinite(experiment::getNumber(row, "edge.chamfer")), box) << row.at("scene");
        EXPECT_EQ(std::isfinite(experiment::getNumber(row, "edge.f1")), box) << row.at("scene");
    }
}

} // namespace
} // namespace rtlab
