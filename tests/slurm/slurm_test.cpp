// Sweeps on a real Slurm cluster: a one-node cluster on localhost (slurm_cluster.sh: munged,
// slurmctld, slurmd from Debian's packages, a generated configuration), a 4-shard sweep submitted
// with `rtlab run --slurm`, followed with `rtlab status`, joined with `rtlab merge` and compared
// with the same sweep run locally: the same runs, each once, with the same values in every column
// that is not a time, a memory size, a shard name or a file path. Then a task that stopped early
// (a shard whose results table ends in the middle of a row, as a kill leaves it, and a task
// cancelled while it runs) is submitted again and resumes: no run lost, none repeated.

#include "experiment/analysis.h"

#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <sys/wait.h>

using namespace rtlab;
namespace fs = std::filesystem;

namespace {

struct Result {
    int code = -1;
    std::string output;
};

Result runShell(const std::string& command)
{
    Result r;
    std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (pipe == nullptr)
        return r;
    std::array<char, 4096> buffer;
    while (const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe))
        r.output.append(buffer.data(), n);
    const int status = ::pclose(pipe);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

const std::string kRtlab = RTLAB_EXE;
const std::string kCluster = std::string(RTLAB_SOURCE_DIR) + "/tests/slurm/slurm_cluster.sh";

// 12 isosurface runs, a few seconds in all: enough for every shard to hold three.
const char* kExperiment = R"(name: slurm_check
base:
  scene: sphere
  grid: 32
  timing: {warmup: 0, repeats: 1}
sweep:
  variants:
    - {scene: [sphere, box], grid: [24, 32, 48], isosurface.technique: [marching_cubes, dual_contouring]}
)";

//! Columns whose values differ between two runs of the same sweep for reasons other than what
//! was computed: times, rates from times, memory, the shard, paths into the output folder.
bool isVolatileColumn(const std::string& column)
{
    static const std::regex pattern(R"((^shard$)|(^memory\.)|(_ms$)|(_ms_iqr$)|(_per_s$)|(_file$)|(^image\.))");
    return std::regex_search(column, pattern);
}

class SlurmSweep : public testing::Test {
protected:
    void SetUp() override
    {
        mWork = fs::temp_directory_path() / ("rtlab_slurm_test_" + std::to_string(::getpid()));
        fs::remove_all(mWork);
        fs::create_directories(mWork);
        const Result started = runShell(kCluster + " start " + (mWork / "cluster").string());
        ASSERT_EQ(started.code, 0) << "the one-node Slurm cluster did not start:\n" << started.output;
        ::setenv("SLURM_CONF", (mWork / "cluster" / "slurm.conf").c_str(), 1);
        std::ofstream(mWork / "slurm_check.yaml") << kExperiment;
    }
    void TearDown() override
    {
        runShell(kCluster + " stop " + (mWork / "cluster").string());
        ::unsetenv("SLURM_CONF");
        if (HasFailure())
            return;
        // slurmctld may still be writing its state files as it exits (job_state.old appears
        // and vanishes under remove_all): retry for up to 5 s instead of failing the test.
        for (int attempt = 0; attempt < 50; ++attempt) {
            std::error_code error;
            fs::remove_all(mWork, error);
            if (!error)
                return;
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
        }
        ADD_FAILURE() << "could not remove " << mWork << " after the cluster stopped";
    }

    //! Runs rtlab in the work folder.
    Result rtlab(const std::string& args) const
    {
        return runShell("cd '" + mWork.string() + "' && " + kRtlab + " " + args);
    }

    //! Submits with `args`, returns the job id.
    std::string submit(const std::string& args) const
    {
        const Result r = rtlab("run slurm_check.yaml --slurm -o cluster_results " + args);
        EXPECT_EQ(r.code, 0) << r.output;
        std::smatch m;
        const std::regex job("submitted as Slurm job ([0-9]+)");
        if (!std::regex_search(r.output, m, job)) {
            ADD_FAILURE() << "no job id in:\n" << r.output;
            return "";
        }
        return m[1];
    }

    //! Waits until the job has left the queue (5 minutes at most).
    void wait(const std::string& job) const
    {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(5);
        while (std::chrono::steady_clock::now() < deadline) {
            const Result q = runShell("squeue -h -j " + job);
            if (q.code != 0 || q.output.find_first_not_of(" \n") == std::string::npos)
                return;
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
        }
        ADD_FAILURE() << "job " << job << " still queued after 5 minutes:\n" << runShell("squeue").output;
    }

    fs::path mWork;
};

//! run_id -> the row's non-volatile columns; fails on a run that appears twice.
std::map<std::string, std::map<std::string, std::string>> indexRows(const std::string& directory)
{
    std::map<std::string, std::map<std::string, std::string>> out;
    for (const auto& row : experiment::loadResults(directory)) {
        const std::string id = row.at("run_id");
        EXPECT_EQ(out.count(id), 0u) << "run " << id << " appears twice in " << directory;
        auto& kept = out[id];
        for (const auto& [column, value] : row)
            if (!isVolatileColumn(column))
                kept[column] = value;
    }
    return out;
}

} // namespace

TEST_F(SlurmSweep, ShardsOnTheClusterMergeIntoTheLocalRunsAndAStoppedTaskResumes)
{
    // The same sweep on this machine, as the comparison.
    const Result local = rtlab("run slurm_check.yaml -o local_results --no-report");
    ASSERT_EQ(local.code, 0) << local.output;

    const auto start = std::chrono::steady_clock::now();
    wait(submit("--array-size 4"));
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("4-shard sweep of 12 runs on the one-node cluster: %.1f s from submission to an empty queue\n",
                seconds);
    const Result status = rtlab("status cluster_results");
    EXPECT_EQ(status.code, 0);
    EXPECT_NE(status.output.find("all            12     12       0  complete"), std::string::npos) << status.output;
    std::size_t logs = 0;
    for (const auto& e : fs::directory_iterator(mWork / "cluster_results" / "slurm"))
        logs += e.path().extension() == ".out" ? 1 : 0;
    EXPECT_EQ(logs, 4u) << "one log per array task";

    // A task stopped by a kill: shard 2 keeps its first row and half of its second.
    const fs::path shard2 = mWork / "cluster_results" / "shard-2-of-4" / "results.jsonl";
    std::string first, second;
    {
        std::ifstream in(shard2);
        std::getline(in, first);
        std::getline(in, second);
    }
    ASSERT_FALSE(second.empty());
    std::ofstream(shard2, std::ios::trunc) << first << "\n" << second.substr(0, second.size() / 2);
    const Result stopped = rtlab("status cluster_results");
    EXPECT_NE(stopped.output.find("2/4             3      1       0  running or stopped"), std::string::npos)
        << stopped.output;

    // And a task cancelled while it runs (it may also finish first: then nothing is left to do).
    const std::string again = submit("--array-size 4 --tasks 3");
    runShell("scancel " + again);
    wait(again);

    // Both submitted again: they compute only what is missing.
    wait(submit("--array-size 4 --tasks 2,3"));
    const Result resumed = rtlab("status cluster_results");
    EXPECT_NE(resumed.output.find("all            12     12       0  complete"), std::string::npos) << resumed.output;

    const Result merged = rtlab("merge -o merged cluster_results/shard-1-of-4 cluster_results/shard-2-of-4 "
                                "cluster_results/shard-3-of-4 cluster_results/shard-4-of-4");
    ASSERT_EQ(merged.code, 0) << merged.output;
    const auto cluster = indexRows((mWork / "merged").string());
    const auto reference = indexRows((mWork / "local_results").string());
    ASSERT_EQ(cluster.size(), 12u);
    ASSERT_EQ(reference.size(), 12u);
    for (const auto& [id, columns] : reference) {
        ASSERT_EQ(cluster.count(id), 1u) << "run " << id << " is missing from the cluster's results";
        const auto& other = cluster.at(id);
        for (const auto& [column, value] : columns) {
            const auto it = other.find(column);
            ASSERT_NE(it, other.end()) << id << ": no column " << column;
            EXPECT_EQ(it->second, value) << id << ": column " << column;
        }
    }
}
