#pragma once
// Runs an expanded experiment: one row per run in the results table, resumable, failures recorded
// in their row while the sweep goes on.

#include "experiment/experiment.h"
#include "experiment/results.h"

#include <functional>
#include <map>
#include <memory>
#include <string>

namespace rtlab::plugin {
class Registry;
}
namespace rtlab::gpu {
class Context;
}
namespace rtlab::pipeline {
struct PassRecord;
}

namespace rtlab::experiment {

struct RunnerOptions {
    std::string outputDirectory;        //!< results/<experiment name> when empty
    bool quiet = false;                 //!< no progress output (tests)
    int shardIndex = 1;                 //!< run only runs k with k % shardCount == shardIndex - 1
    int shardCount = 1;                 //!< 1 = the whole sweep
    bool queryVulkanForManifest = true; //!< tests turn it off
};

//! Parses "i/N" (1 <= i <= N) into options.shardIndex and options.shardCount; throws
//! rtlab::InputError naming the argument otherwise.
void parseShard(const std::string& text, RunnerOptions& options);

//! Joins the results of shard folders into `outputDirectory`: rows of every results.jsonl (a run
//! that is "ok" in any shard wins over a failed attempt elsewhere, duplicates are dropped), the
//! run folders, a CSV, and the first shard's manifest with the list of shards. Returns the row
//! count. Throws rtlab::Error when a shard folder has no results.jsonl.
std::size_t mergeShards(const std::vector<std::string>& shardDirectories,
                        const std::string& outputDirectory);

struct RunnerSummary {
    std::size_t total = 0;       //!< runs in this shard
    std::size_t alreadyDone = 0; //!< found complete in the results table (resumed)
    std::size_t succeeded = 0;
    std::size_t failed = 0;
    std::string outputDirectory;
};

//! What a family gets besides the run: the registry, the run's output folder, and the
//! Vulkan device (opened on first use and shared by every run of the sweep).
class DriverContext {
public:
    DriverContext(const plugin::Registry& registry, std::string runDirectory);
    ~DriverContext();
    const plugin::Registry& registry() const { return mRegistry; }
    const std::string& runDirectory() const { return mRunDirectory; }
    void setRunDirectory(std::string directory) { mRunDirectory = std::move(directory); }
    gpu::Context& getGpu();

private:
    const plugin::Registry& mRegistry;
    std::string mRunDirectory;
    std::unique_ptr<gpu::Context> mGpu;
};

//! Runs every run of `experiment` not already complete in the output folder.
RunnerSummary runExperiment(const Experiment& experiment, const plugin::Registry& registry,
                            const RunnerOptions& options);

//! Writes a frame's pass log: the columns "passes" ("gbuffer:run;reference:skipped(read from the
//! cache)"), "passes_run", "passes_skipped", and the time of every pass that ran: for passes timed
//! with the run's repeats the columns of addTimingColumns, for the others <pass>.cpu_ms (and
//! <pass>.gpu_ms when the pass ran GPU work), and the frame's time: frame.cpu_ms and frame.gpu_ms,
//! the sums over the passes that ran and make the frame (not measurement passes).
void writePassRecords(ResultRow& row, const std::vector<pipeline::PassRecord>& records);

//! Current and peak resident memory of the process: columns memory.rss_mb, memory.peak_rss_mb.
void addMemoryColumns(ResultRow& row);

//! Adds the timing columns of one pass: <pass>.cpu_ms (median), <pass>.cpu_ms_iqr,
//! <pass>.first_use_ms, <pass>.setup_ms, and <pass>.gpu_ms when it ran GPU work.
void addTimingColumns(ResultRow& row, const std::string& pass,
                      const struct metrics::TimingReport& report);

} // namespace rtlab::experiment
