// Sweep expansion: cross product in file order (technique axes first), validation of axes.

#include "core/error.h"
#include "experiment/experiment.h"
#include "test_registry.h"

#include <gtest/gtest.h>

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
