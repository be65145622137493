#pragma once
// Runs an expanded experiment: one row per run in the results table, resumable, failures recorded
// in their row while the sweep goes on.

#include "experiment/experiment.h"
#include "experiment/results.h"

#include <functional>
#include <map>
#include <string>

namespace rtlab::plugin {
class Registry;
}

namespace rtlab::experiment {

struct RunnerOptions {
    std::string outputDirectory;  //!< results/<experiment name> when empty
    bool quiet = false;           //!< no progress output (tests)
    int shardIndex = 1;           //!< run only runs k with k % shardCount == shardIndex - 1
    int shardCount = 1;           //!< 1 = the whole sweep
    bool queryVulkanForManifest = true;  //!< tests turn it off
};

//! Parses "i/N" (1 <= i <= N) into options.shardIndex and options.shardCount; throws
//! rtlab::InputError naming the argument otherwise.
void parseShard(const std::string& text, RunnerOptions& options);

//! Joins the results of shard folders into `outputDirectory`: rows of every results.jsonl (a run
//! that is "ok" in any shard wins over a failed attempt elsewhere, duplicates are dropped), the
//! run folders, a CSV, and the first shard's manifest with the list of shards. Returns the row
//! count. Throws rtlab::Error when a shard folder has no results.jsonl.
std::size_t mergeShards(const std::vector<std::string>& shardDirectories, const std::string& outputDirectory);

struct RunnerSummary {
    std::size_t total = 0;        //!< runs in this shard
    std::size_t alreadyDone = 0;  //!< found complete in the results table (resumed)
    std::size_t succeeded = 0;
    std::size_t failed = 0;
    std::string outputDirectory;
};

//! Runs one family's part of a run and fills metric and timing columns of `row`.
//! `runDirectory` receives the run's output files.
using FamilyDriver = std::function<void(const RunConfig& run, const std::string& family,
                                        const plugin::Registry& registry, const std::string& runDirectory,
                                        ResultRow& row)>;

//! The drivers of the families that can run in experiments, by family name.
const std::map<std::string, FamilyDriver>& familyDrivers();

//! Runs every run of `experiment` not already complete in the output folder.
RunnerSummary runExperiment(const Experiment& experiment, const plugin::Registry& registry,
                            const RunnerOptions& options);

//! The isosurface family's driver: samples the analytic shape, extracts, measures.
void runIsosurfaceFamily(const RunConfig& run, const std::string& family, const plugin::Registry& registry,
                         const std::string& runDirectory, ResultRow& row);

//! Adds the timing columns of one pass: <pass>.cpu_ms (median), <pass>.cpu_ms_iqr,
//! <pass>.first_use_ms, <pass>.setup_ms, and <pass>.gpu_ms when it ran GPU work.
void addTimingColumns(ResultRow& row, const std::string& pass, const struct metrics::TimingReport& report);

} // namespace rtlab::experiment
