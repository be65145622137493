// The parts of the Slurm support that need no cluster: the sbatch script and the shard progress
// read from results tables.

#include "core/error.h"
#include "experiment/slurm.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace rtlab;
namespace fs = std::filesystem;

namespace {

experiment::SlurmJob makeJob()
{
    experiment::SlurmJob job;
    job.experimentName = "study";
    job.experimentPath = "/data/my experiments/study's.yaml";
    job.rtlabPath = "/opt/rtlab/build/rtlab";
    job.workingDirectory = "/data/work";
    job.outputDirectory = "/data/results/study";
    job.arraySize = 4;
    return job;
}

TEST(SlurmScript, OneArrayTaskPerShardWithQuotedPaths)
{
    const std::string s = experiment::makeSlurmScript(makeJob());
    EXPECT_EQ(s.rfind("#!/bin/bash\n", 0), 0u);
    EXPECT_NE(s.find("#SBATCH --array=1-4\n"), std::string::npos) << s;
    EXPECT_NE(s.find("#SBATCH --output=/data/results/study/slurm/%x-%A_%a.out\n"), std::string::npos) << s;
    EXPECT_EQ(s.find("--partition"), std::string::npos);
    EXPECT_EQ(s.find("--time"), std::string::npos);
    EXPECT_NE(s.find("cd '/data/work'\n"), std::string::npos) << s;
    // A space and a single quote in the path survive the shell.
    EXPECT_NE(s.find("'/opt/rtlab/build/rtlab' run '/data/my experiments/study'\\''s.yaml' --shard \"$i/4\" "
                     "--output '/data/results/study'/shard-\"$i\"-of-4 --no-report"),
              std::string::npos)
        << s;
}

TEST(SlurmScript, ChosenTasksBecomeRangesAndOptionsAreChecked)
{
    auto job = makeJob();
    job.arraySize = 8;
    job.tasks = {7, 2, 3, 3};
    job.partition = "gpu-h100";
    job.timeLimit = "1-02:00:00";
    const std::string s = experiment::makeSlurmScript(job);
    EXPECT_NE(s.find("#SBATCH --array=2-3,7\n"), std::string::npos) << s;
    EXPECT_NE(s.find("#SBATCH --partition=gpu-h100\n"), std::string::npos);
    EXPECT_NE(s.find("#SBATCH --time=1-02:00:00\n"), std::string::npos);
    job.tasks = {9};
    EXPECT_THROW(experiment::makeSlurmScript(job), InputError);
    job.tasks = {0};
    EXPECT_THROW(experiment::makeSlurmScript(job), InputError);
    job.tasks = {};
    job.partition = "gpu; rm -rf /";
    EXPECT_THROW(experiment::makeSlurmScript(job), InputError);
    job.partition = "";
    job.arraySize = 0;
    EXPECT_THROW(experiment::makeSlurmScript(job), InputError);
}

TEST(ShardProgress, CountsRunsDoneAndFailedPerShardFromTheTablesAndTheManifest)
{
    const fs::path dir = fs::temp_directory_path() / "rtlab_shard_progress_test";
    fs::remove_all(dir);
    // Shard 1 of 4: runs a (two frames, ok), b (failed), c (failed, then ok on a retry), and a
    // torn last line; its manifest lists the sweep's 10 runs. Shard 3 has started with nothing;
    // shards 2 and 4 have not started.
    fs::create_directories(dir / "shard-1-of-4");
    std::ofstream(dir / "shard-1-of-4" / "results.jsonl")
        << R"({"run_id":"a","config_hash":"ha","status":"ok"})" << "\n"
        << R"({"run_id":"a","config_hash":"ha","status":"ok"})" << "\n"
        << R"({"run_id":"b","config_hash":"hb","status":"failed"})" << "\n"
        << R"({"run_id":"c","config_hash":"hc","status":"failed"})" << "\n"
        << R"({"run_id":"c","config_hash":"hc","status":"ok"})" << "\n"
        << R"({"run_id":"d","config_ha)";
    std::ofstream(dir / "shard-1-of-4" / "manifest.json")
        << R"({"experiment":"x","runs":[{"id":"1"},{"id":"2"},{"id":"3"},{"id":"4"},{"id":"5"},)"
        << R"({"id":"6"},{"id":"7"},{"id":"8"},{"id":"9"},{"id":"10"}]})";
    fs::create_directories(dir / "shard-3-of-4");
    fs::create_directories(dir / "not-a-shard");
    const auto p = experiment::collectShardProgress(dir.string());
    ASSERT_EQ(p.size(), 4u);
    // Shard i of 4 holds the runs k with k mod 4 = i - 1: 3, 3, 2 and 2 of the 10.
    const std::size_t runs[] = {3, 3, 2, 2};
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(p[i].index, i + 1);
        EXPECT_EQ(p[i].count, 4);
        EXPECT_EQ(p[i].runs, runs[i]) << i;
    }
    EXPECT_TRUE(p[0].started);
    EXPECT_EQ(p[0].rows, 5u);
    EXPECT_EQ(p[0].done, 2u);   // a, c
    EXPECT_EQ(p[0].failed, 1u); // b
    EXPECT_FALSE(p[1].started);
    EXPECT_FALSE(p[2].started); // a folder without a results table
    EXPECT_EQ(p[2].directory, (dir / "shard-3-of-4").string());
    fs::remove_all(dir);
}

} // namespace
