// The runner: one row per run, failures recorded in their row, resume without recomputation.

#include "experiment/runner.h"
#include "test_registry.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace rtlab;

namespace {

const char* kStudy = R"(name: runner_study
base:
  scene: sphere
  grid: 8
  timing: {warmup: 0, repeats: 2}
  techniques: {isosurface: {technique: fake_mesher}}
sweep:
  isosurface.resolution: [1, 2, 3, 4]
)";

std::filesystem::path freshDirectory(const std::string& name)
{
    const auto dir = std::filesystem::temp_directory_path() / ("rtlab_runner_test_" + name);
    std::filesystem::remove_all(dir);
    return dir;
}

std::vector<std::string> readLines(const std::filesystem::path& path)
{
    std::vector<std::string> lines;
    std::ifstream in(path);
    for (std::string line; std::getline(in, line);)
        lines.push_back(line);
    return lines;
}

} // namespace

TEST(Runner, WritesOneRowPerRunWithTimingAndMetrics)
{
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(kStudy, "runner.yaml", registry);
    const auto dir = freshDirectory("rows");
    const auto s = experiment::runExperiment(e, registry, {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    EXPECT_EQ(s.total, 4u);
    EXPECT_EQ(s.succeeded, 4u);
    EXPECT_EQ(s.failed, 0u);

    experiment::ResultsStore store(dir.string());
    const auto rows = store.readRows();
    ASSERT_EQ(rows.size(), 4u);
    std::map<std::string, std::string> first(rows[0].begin(), rows[0].end());
    EXPECT_EQ(first["status"], "ok");
    EXPECT_EQ(first["technique"], "fake_mesher");
    EXPECT_EQ(first["param.resolution"], "1");
    EXPECT_EQ(first["triangles"], "1");  // the fake emits one triangle per resolution step
    EXPECT_EQ(first["extract.repeats"], "2");
    EXPECT_GE(std::stod(first["extract.cpu_ms"]), 0.0);
    EXPECT_TRUE(std::filesystem::exists(dir / "results.csv"));
    EXPECT_TRUE(std::filesystem::exists(dir / "manifest.json"));
    EXPECT_EQ(readLines(dir / "results.csv").size(), 5u);  // header + 4 rows
}

TEST(Runner, ResumesAfterAnInterruptionWithoutRecomputing)
{
    const auto registry = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(kStudy, "runner.yaml", registry);
    const auto dir = freshDirectory("resume");
    experiment::runExperiment(e, registry, {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    auto lines = readLines(dir / "results.jsonl");
    ASSERT_EQ(lines.size(), 4u);

    // Simulate a crash during the third run: two complete rows, then half a line.
    {
        std::ofstream out(dir / "results.jsonl", std::ios::trunc);
        out << lines[0] << "\n" << lines[1] << "\n" << lines[2].substr(0, lines[2].size() / 2);
    }
    const auto s = experiment::runExperiment(e, registry, {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    EXPECT_EQ(s.alreadyDone, 2u);
    EXPECT_EQ(s.succeeded, 2u);
    // The two finished rows are untouched, byte for byte.
    const auto after = readLines(dir / "results.jsonl");
    EXPECT_EQ(after[0], lines[0]);
    EXPECT_EQ(after[1], lines[1]);
    std::size_t skipped = 0;
    experiment::ResultsStore store(dir.string());
    EXPECT_EQ(store.readRows(&skipped).size(), 4u);
    EXPECT_EQ(skipped, 1u);  // the torn line is ignored, not parsed
    EXPECT_EQ(store.completedHashes().size(), 4u);

    // A third run computes nothing.
    const auto again = experiment::runExperiment(e, registry, {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    EXPECT_EQ(again.alreadyDone, 4u);
    EXPECT_EQ(again.succeeded, 0u);
}

TEST(Runner, AFailingRunIsRecordedAndTheSweepGoesOn)
{
    const auto registry = test::makeTestRegistry();
    // The torus is sampled, then the fake mesher runs; to make one run fail, use a family
    // without a driver.
    plugin::Registry withOcclusion = test::makeTestRegistry();
    const auto e = experiment::parseExperiment(kStudy, "runner.yaml", registry);
    auto broken = e;
    broken.runs[1].techniques["occlusion"] = {"no_such", {}};
    const auto dir = freshDirectory("failure");
    const auto s = experiment::runExperiment(broken, registry, {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    EXPECT_EQ(s.failed, 1u);
    EXPECT_EQ(s.succeeded, 3u);
    experiment::ResultsStore store(dir.string());
    const auto rows = store.readRows();
    ASSERT_EQ(rows.size(), 4u);
    std::map<std::string, std::string> failed(rows[1].begin(), rows[1].end());
    EXPECT_EQ(failed["status"], "failed");
    EXPECT_NE(failed["error"].find("occlusion"), std::string::npos) << failed["error"];
    // A failed run is retried next time; the others are not.
    const auto again = experiment::runExperiment(e, registry, {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    EXPECT_EQ(again.alreadyDone, 3u);
    EXPECT_EQ(again.succeeded, 1u);
}
