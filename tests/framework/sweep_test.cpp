// Sweep expansion: cross product in file order (technique axes first), validation of axes.

#include "core/error.h"
#include "experiment/experiment.h"
#include "test_registry.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

using namespace rtlab;

namespace {
std::string errorOf(const std::string& text)
{
    const auto registry = test::makeTestRegistry();
    try {
        experiment::parseExperiment(text, "sweep.yaml", registry);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}
} // namespace

TEST(Sweep, CrossProductOfAllAxes)
{
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: sphere
  techniques: {isosurface: {technique: fake_mesher, params: {scale: 2}}}
sweep:
  scene: [sphere, torus, box]
  grid: [8, 16]
  isosurface.resolution: [1, 2, 3, 4]
)",
                                               "sweep.yaml", registry);
    ASSERT_EQ(e.runs.size(), 3u * 2u * 4u);
    std::set<std::string> ids, hashes;
    for (const auto& r : e.runs) {
        ids.insert(r.id());
        hashes.insert(r.hash());
        EXPECT_EQ(r.techniques.at("isosurface").params.getFloat("scale"), 2.0);  // base kept
    }
    EXPECT_EQ(ids.size(), e.runs.size());
    EXPECT_EQ(hashes.size(), e.runs.size());
    // Axes in file order: the first run is the first value of every axis.
    EXPECT_EQ(e.runs.front().scene, "sphere");
    EXPECT_EQ(e.runs.front().grid, 8);
    EXPECT_EQ(e.runs.front().techniques.at("isosurface").params.getInt("resolution"), 1);
    EXPECT_EQ(e.runs.back().scene, "box");
    EXPECT_EQ(e.runs.back().grid, 16);
    EXPECT_EQ(e.runs.back().techniques.at("isosurface").params.getInt("resolution"), 4);
}

TEST(Sweep, HashIgnoresNothingThatMatters)
{
    const auto registry = test::makeTestRegistry();
    const auto a = experiment::parseExperiment(
        "base: {scene: sphere, techniques: {isosurface: {technique: fake_mesher}}}\n", "a.yaml", registry);
    const auto b = experiment::parseExperiment(
        "base: {scene: sphere, techniques: {isosurface: {technique: fake_mesher, params: {scale: 1.0}}}}\n",
        "b.yaml", registry);
    const auto c = experiment::parseExperiment(
        "base: {scene: sphere, techniques: {isosurface: {technique: fake_mesher, params: {scale: 1.5}}}}\n",
        "c.yaml", registry);
    EXPECT_EQ(a.runs[0].hash(), b.runs[0].hash());  // explicit default == implicit default
    EXPECT_NE(a.runs[0].hash(), c.runs[0].hash());
}

TEST(Sweep, SweptParameterIsValidated)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  isosurface.resolution: [4, 100]
)");
    EXPECT_NE(err.find("sweep.yaml:5:30:"), std::string::npos) << err;
    EXPECT_NE(err.find("expected an integer in [1, 64]"), std::string::npos) << err;
}

TEST(Sweep, UnknownParameterAxis)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  isosurface.scael: [1, 2]
)");
    EXPECT_NE(err.find("sweep.yaml:5:3:"), std::string::npos) << err;
    EXPECT_NE(err.find("declares no parameter 'scael'; did you mean scale?"), std::string::npos) << err;
}

TEST(Sweep, AxisNeedsAList)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  grid: 16
)");
    EXPECT_NE(err.find("sweep.yaml:5:9:"), std::string::npos) << err;
    EXPECT_NE(err.find("needs a non-empty list"), std::string::npos) << err;
}

TEST(Sweep, RepeatedValueIsAnError)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  grid: [16, 16]
)");
    EXPECT_NE(err.find("are identical"), std::string::npos) << err;
}

TEST(Sweep, ZipMovesAxesTogether)
{
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: sphere
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  scene: [sphere, box]
  zip:
    - {grid: [8, 16, 32], isosurface.resolution: [2, 4, 8]}
)",
                                               "zip.yaml", registry);
    ASSERT_EQ(e.runs.size(), 2u * 3u);  // not 2 x 3 x 3
    for (const auto& r : e.runs)
        EXPECT_EQ(r.techniques.at("isosurface").params.getInt("resolution") * 4, r.grid);
    EXPECT_EQ(e.sweepKeys, (std::vector<std::string>{"scene", "zip(grid+isosurface.resolution)"}));
}

TEST(Sweep, ZipListsMustHaveEqualLengths)
{
    const std::string err = errorOf(R"(base:
  scene: sphere
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  zip:
    - {grid: [8, 16, 32], isosurface.resolution: [2, 4]}
)");
    EXPECT_NE(err.find("sweep.yaml:6:50:"), std::string::npos) << err;
    EXPECT_NE(err.find("has 2 values but 'grid' has 3"), std::string::npos) << err;
}

TEST(Sweep, VariantsConcatenateSubSweeps)
{
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: sphere
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  scene: [sphere, box]
  variants:
    - {isosurface.resolution: [1, 2]}
    - {isosurface.scale: [3, 4, 5], isosurface.mode: [exact]}
)",
                                               "variants.yaml", registry);
    ASSERT_EQ(e.runs.size(), 2u * (2u + 3u));
    int exact = 0;
    for (const auto& r : e.runs)
        exact += r.techniques.at("isosurface").params.getString("mode") == "exact";
    EXPECT_EQ(exact, 6);  // only the second variant sets it
    EXPECT_EQ(e.sweepKeys, (std::vector<std::string>{"scene", "isosurface.resolution", "isosurface.scale",
                                                     "isosurface.mode"}));
}

// A study of two families: the base names no technique, each variant names its family's.
TEST(Sweep, BaseWithoutTechniquesTakesThemFromEachVariant)
{
    const auto e = experiment::parseExperiment(R"(base:
  scene: sphere
  grid: 32
sweep:
  variants:
    - {isosurface.technique: [marching_cubes, dual_contouring]}
    - {scene: [ao_testbed], resolution: [[64, 36]], occlusion.technique: [gtao]}
)",
                                               "two_families.yaml", plugin::builtinRegistry());
    ASSERT_EQ(e.runs.size(), 3u);
    EXPECT_EQ(e.runs[0].techniques.count("isosurface"), 1u);
    EXPECT_EQ(e.runs[1].techniques.at("isosurface").technique, "dual_contouring");
    ASSERT_EQ(e.runs[2].techniques.size(), 1u);
    EXPECT_EQ(e.runs[2].techniques.at("occlusion").technique, "gtao");

    // A run that ends up with no technique is an error naming the run.
    const auto registry = test::makeTestRegistry();
    std::string error;
    try {
        experiment::parseExperiment(R"(base:
  scene: sphere
sweep:
  variants:
    - {isosurface.technique: [fake_mesher]}
    - {scene: [box]}
)",
                                    "missing.yaml", registry);
    } catch (const InputError& ex) {
        error = ex.what();
    }
    EXPECT_NE(error.find("missing.yaml:"), std::string::npos) << error;
    EXPECT_NE(error.find("run 2 of the expansion"), std::string::npos) << error;
    EXPECT_NE(error.find("has no technique"), std::string::npos) << error;
    EXPECT_NE(errorOf("base:\n  scene: sphere\n").find("has no technique"), std::string::npos)
        << errorOf("base:\n  scene: sphere\n");
}

TEST(Sweep, CameraPathMetricsAndGroundTruthOverrideAreBaseKeysAndCameraPathAnAxis)
{
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: ao_testbed
  frames: 4
  camera_path: orbit
  metrics: [deviation, chamfer]
  reference: {quantity: obscurance, falloff: smoothstep, radius: 0.5}
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  camera_path: [static, orbit, dolly]
)",
                                               "sweep.yaml", registry);
    ASSERT_EQ(e.runs.size(), 3u);
    EXPECT_EQ(e.base.cameraPath, "orbit");
    EXPECT_EQ(e.runs[0].cameraPath, "static");
    EXPECT_EQ(e.runs[2].cameraPath, "dolly");
    EXPECT_EQ(e.base.metrics, (std::vector<std::string>{"deviation", "chamfer"}));
    EXPECT_TRUE(e.base.wantsMetric("chamfer"));
    EXPECT_FALSE(e.base.wantsMetric("topology"));
    EXPECT_EQ(e.base.reference.quantity, "obscurance");
    EXPECT_EQ(e.base.reference.falloff, "smoothstep");
    EXPECT_DOUBLE_EQ(e.base.reference.radius, 0.5);
    EXPECT_NE(e.runs[0].hash(), e.runs[1].hash()) << "the camera path is part of what a run is";
    EXPECT_NE(e.runs[0].id().find("static"), std::string::npos) << e.runs[0].id();
}

TEST(Sweep, TheGroundTruthsSampleCapIsAnAxis)
{
    // A study at two image sizes can cap the ground truth's paths per pixel at the larger one.
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: ao_testbed
  reference: {target_stderr: 0.02, max_samples: 256}
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  reference.max_samples: [256, 32]
)",
                                               "sweep.yaml", registry);
    ASSERT_EQ(e.runs.size(), 2u);
    EXPECT_EQ(e.runs[0].reference.maxSamples, 256);
    EXPECT_EQ(e.runs[1].reference.maxSamples, 32);
    EXPECT_DOUBLE_EQ(e.runs[1].reference.targetStdErr, 0.02) << "the rest of base's reference kept";
    EXPECT_NE(e.runs[0].hash(), e.runs[1].hash());
    const std::string zero = errorOf(R"(base:
  scene: ao_testbed
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  reference.max_samples: [0]
)");
    EXPECT_NE(zero.find("sweep.yaml:5:27"), std::string::npos) << zero;
    EXPECT_NE(zero.find("reference.max_samples"), std::string::npos) << zero;
}

TEST(Sweep, TheReportsTimeFromFrameIsAnExperimentSettingOutsideTheRuns)
{
    const auto registry = test::makeTestRegistry();
    const std::string body = R"(base:
  scene: ao_testbed
  frames: 4
  techniques: {isosurface: {technique: fake_mesher}}
)";
    const auto with = experiment::parseExperiment("report: {time_from_frame: 2}\n" + body,
                                                  "sweep.yaml", registry);
    const auto without = experiment::parseExperiment(body, "sweep.yaml", registry);
    EXPECT_EQ(with.reportTimeFromFrame, 2);
    EXPECT_EQ(without.reportTimeFromFrame, 0);
    EXPECT_EQ(with.runs.at(0).hash(), without.runs.at(0).hash())
        << "how the report averages is not what a run is";
    const std::string bad = errorOf("report: {time_from: 1}\n" + body);
    EXPECT_NE(bad.find("sweep.yaml:1:"), std::string::npos) << bad;
    EXPECT_NE(bad.find("time_from_frame"), std::string::npos) << bad;
}

TEST(Sweep, KeysAddedLaterLeaveTheHashOfRunsThatDoNotUseThemUnchanged)
{
    // Results written before camera_path, metrics and the ground-truth override existed must
    // still be recognised as complete: the canonical JSON only mentions those keys when set.
    experiment::RunConfig run;
    run.scene = "sphere";
    const std::string json = run.toJson();
    EXPECT_EQ(json.find("camera_path"), std::string::npos) << json;
    EXPECT_EQ(json.find("metrics"), std::string::npos) << json;
    EXPECT_EQ(json.find("quantity"), std::string::npos) << json;
}

TEST(Sweep, BadCameraPathMetricOrQuantityNamesTheLineAndTheValidNames)
{
    const std::string unknownPath = errorOf(R"(base:
  scene: ao_testbed
  camera_path: orbitt
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(unknownPath.find("sweep.yaml:3:16"), std::string::npos) << unknownPath;
    EXPECT_NE(unknownPath.find("orbit"), std::string::npos) << unknownPath;
    const std::string unknownMetric = errorOf(R"(base:
  scene: sphere
  metrics: [chamfer, rmse]
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(unknownMetric.find("sweep.yaml:3:22"), std::string::npos) << unknownMetric;
    EXPECT_NE(unknownMetric.find("deviation"), std::string::npos) << "lists the valid metrics: " << unknownMetric;
    const std::string twice = errorOf(R"(base:
  scene: sphere
  metrics: [chamfer, chamfer]
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(twice.find("listed twice"), std::string::npos) << twice;
    const std::string quantity = errorOf(R"(base:
  scene: sphere
  reference: {quantity: irradiance}
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(quantity.find("sweep.yaml:3:25"), std::string::npos) << quantity;
    EXPECT_NE(quantity.find("ao_uniform"), std::string::npos) << quantity;
    const std::string radius = errorOf(R"(base:
  scene: sphere
  reference: {radius: -1}
  techniques: {isosurface: {technique: fake_mesher}}
)");
    EXPECT_NE(radius.find("reference.radius"), std::string::npos) << radius;
}

TEST(Sweep, ANamedCameraPathMustBeOneOfTheScenes)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_sweep_camera_paths";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "room.yaml") << R"(scene: room
base: ao_testbed
frames: 3
camera_paths:
  low_pass:
    - {time: 0, position: [0, 0.3, 3], target: [0, 0.3, 0]}
    - {time: 1, position: [1, 0.3, 3], target: [0, 0.3, 0]}
)";
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: room.yaml
  camera_path: low_pass
  techniques: {isosurface: {technique: fake_mesher}}
)",
                                               (dir / "ok.yaml").string(), registry);
    EXPECT_EQ(e.runs.at(0).cameraPath, "low_pass");
    try {
        experiment::parseExperiment(R"(base:
  scene: room.yaml
  camera_path: high_pass
  techniques: {isosurface: {technique: fake_mesher}}
)",
                                    (dir / "bad.yaml").string(), registry);
        ADD_FAILURE() << "an unknown named path was accepted";
    } catch (const InputError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("bad.yaml:3:16"), std::string::npos) << message;
        EXPECT_NE(message.find("low_pass"), std::string::npos) << message;
    }
}
