// Questions asked of a results table, shards and their merge.

#include "core/error.h"
#include "experiment/analysis.h"
#include "experiment/runner.h"
#include "test_registry.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

using namespace rtlab;
using experiment::Row;

namespace {
Row makeRow(const std::string& id, double ms, double err, const std::string& status = "ok")
{
    return {{"run_id", id}, {"status", status}, {"t", std::to_string(ms)}, {"e", std::to_string(err)}};
}
} // namespace

TEST(Analysis, BestUnderATimeBudgetAndUnderAnErrorBound)
{
    const std::vector<Row> rows = {makeRow("a", 1, 0.4), makeRow("b", 3, 0.2), makeRow("c", 2, 0.1),
                                   makeRow("d", 0.5, 0.0, "failed"), makeRow("e", 8, 0.05)};
    experiment::BestQuery q{.costColumn = "t", .errorColumn = "e"};
    q.maxCost = 2.5;
    EXPECT_EQ(experiment::findBest(rows, q), 2);  // c: the lowest error within 2.5 ms
    q.maxCost = 0.9;
    EXPECT_EQ(experiment::findBest(rows, q), -1);  // only the failed run is that fast
    q.maxCost = -1.0;
    q.maxError = 0.2;
    EXPECT_EQ(experiment::findBest(rows, q), 2);  // c is cheaper than b at error <= 0.2
    q.maxError = 0.06;
    EXPECT_EQ(experiment::findBest(rows, q), 4);
}

TEST(Analysis, DurationsWithUnits)
{
    EXPECT_DOUBLE_EQ(experiment::parseDurationMs("5ms"), 5.0);
    EXPECT_DOUBLE_EQ(experiment::parseDurationMs("0.5 s"), 500.0);
    EXPECT_DOUBLE_EQ(experiment::parseDurationMs("250us"), 0.25);
    EXPECT_DOUBLE_EQ(experiment::parseDurationMs("2"), 2.0);
    EXPECT_THROW(experiment::parseDurationMs("fast"), std::invalid_argument);
    EXPECT_THROW(experiment::parseDurationMs("-1ms"), std::invalid_argument);
}

TEST(Shards, ParseAndReject)
{
    experiment::RunnerOptions o;
    experiment::parseShard("2/4", o);
    EXPECT_EQ(o.shardIndex, 2);
    EXPECT_EQ(o.shardCount, 4);
    for (const char* bad : {"0/4", "5/4", "2", "a/b", "2/4x", "1/0"})
        EXPECT_THROW(experiment::parseShard(bad, o), InputError) << bad;
}

TEST(Shards, TwoShardsMergeIntoTheWholeSweep)
{
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(R"(name: sharded
base:
  scene: sphere
  grid: 8
  timing: {warmup: 0, repeats: 1}
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  isosurface.resolution: [1, 2, 3, 4, 5]
)",
                                               "sharded.yaml", registry);
    const auto root = std::filesystem::temp_directory_path() / "rtlab_shard_test";
    std::filesystem::remove_all(root);
    std::vector<std::string> dirs;
    std::size_t total = 0;
    for (int i = 1; i <= 2; ++i) {
        experiment::RunnerOptions o{.outputDirectory = (root / ("s" + std::to_string(i))).string(), .quiet = true,
                                    .queryVulkanForManifest = false};
        o.shardIndex = i;
        o.shardCount = 2;
        const auto s = experiment::runExperiment(e, registry, o);
        EXPECT_EQ(s.total, i == 1 ? 3u : 2u);  // runs 0, 2, 4 and 1, 3
        total += s.succeeded;
        dirs.push_back(o.outputDirectory);
    }
    EXPECT_EQ(total, 5u);
    EXPECT_EQ(experiment::mergeShards(dirs, (root / "all").string()), 5u);
    const auto rows = experiment::loadResults((root / "all").string());
    std::set<std::string> resolutions;
    for (const auto& r : rows)
        resolutions.insert(r.at("param.resolution"));
    EXPECT_EQ(resolutions.size(), 5u);
    EXPECT_TRUE(std::filesystem::exists(root / "all" / "manifest.json"));
    EXPECT_THROW(experiment::mergeShards({(root / "nothing").string()}, (root / "x").string()), Error);
}
