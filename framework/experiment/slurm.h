#pragma once
// Sweeps on a Slurm cluster: `rtlab run <exp> --slurm` writes an sbatch array script whose task i
// runs shard i of N of the sweep (`rtlab run --shard i/N`, into <output>/shard-i-of-N), and
// submits it; `rtlab status <output>` shows each shard's progress from its results table;
// `rtlab merge` joins the shards. A task that was killed leaves a results table whose complete
// rows are kept: resubmitted, it computes only the runs still missing.

#include <cstddef>
#include <string>
#include <vector>

namespace rtlab::experiment {

struct SlurmJob {
    std::string experimentName;
    std::string experimentPath;   //!< absolute
    std::string rtlabPath;        //!< absolute path of the rtlab program the tasks run
    std::string workingDirectory; //!< absolute; the tasks start there (relative paths in the
                                  //!< experiment resolve as they do for a local run)
    std::string outputDirectory;  //!< absolute; shards go to <output>/shard-i-of-N
    int arraySize = 4;            //!< N, the shard count
    std::vector<int> tasks;       //!< the array tasks to submit (1-based); empty: 1..N
    std::string partition;        //!< empty: the cluster's default
    std::string timeLimit;        //!< sbatch --time, e.g. "2:00:00"; empty: the partition's
};

//! The folder of shard i of n under `outputDirectory` (what `rtlab run --shard i/n` writes by
//! default for an experiment's default output).
std::string getShardDirectory(const std::string& outputDirectory, int index, int count);

//! The sbatch script of `job`. Throws rtlab::InputError for an array size below 1, a task
//! outside 1..N, or a partition or time limit holding characters a shell or sbatch would read
//! as more than one word.
std::string makeSlurmScript(const SlurmJob& job);

//! Progress of one shard folder, read from its results table and manifest.
struct ShardProgress {
    std::string directory;
    int index = 0;           //!< i of shard-i-of-N
    int count = 0;           //!< N
    bool started = false;    //!< the folder has a results table
    std::size_t runs = 0;    //!< runs of the sweep in this shard (from the manifest; 0: unknown)
    std::size_t done = 0;    //!< runs with an "ok" row
    std::size_t failed = 0;  //!< runs whose rows all failed
    std::size_t rows = 0;    //!< complete rows (one per run and frame)
};

//! Every shard folder shard-i-of-N directly under `directory`, ordered by N then i, including the
//! ones of an array size whose shards have not all started (listed as not started, with their
//! run counts when any sibling's manifest gives the sweep size).
std::vector<ShardProgress> collectShardProgress(const std::string& directory);

} // namespace rtlab::experiment
