#pragma once
// The `rtlab` subcommands. Each returns the process exit code:
// 0 success, 1 the work ran but something failed, 2 bad input (file, config or arguments),
// 3 the environment lacks something (no Vulkan device, ...).

#include <cstdint>
#include <string>
#include <vector>

namespace rtlab::experiment {
struct Experiment;
}

namespace rtlab::cli {

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitEnvironment = 3;

struct ListOptions {
    std::string family;  //!< only this family when not empty
    bool json = false;
};
int listTechniques(const ListOptions& options);

struct RunOptions {
    std::string experimentPath;
    std::string outputDirectory;
    bool dryRun = false;
    std::string shard;  //!< "i/N" or empty
    bool report = true; //!< write plots and report.html after the runs
    // --slurm: submit the sweep as an sbatch array of `arraySize` shards instead of running it
    bool slurm = false;
    int arraySize = 4;
    std::string partition;
    std::string timeLimit;
    std::vector<int> tasks; //!< resubmit only these array tasks (1-based)
};

//! Submits the loaded (validated) sweep `e` as a Slurm array (experiment/slurm.h); prints the job
//! id. runExperimentCommand calls it for --slurm.
int submitSlurmCommand(const RunOptions& options, const experiment::Experiment& e);

//! Per-shard progress of a results folder from its shards' results tables.
int statusCommand(const std::string& resultsDirectory);

//! Writes the plots and report.html of a results folder.
int reportCommand(const std::string& resultsDirectory, int timeFromFrame = 0);
int runExperimentCommand(const RunOptions& options);

struct NewTechniqueOptions {
    std::string family;
    std::string name;
    std::string sourceDirectory;  //!< repository root; default: the one rtlab was built from
};
int newTechnique(const NewTechniqueOptions& options);

struct NewFamilyOptions {
    std::string name;
    std::string sourceDirectory;  //!< repository root; empty = the one rtlab was built from
};
//! Writes framework/families/<name>/ from framework/families/_template/, the family's technique
//! template techniques/_template/<name>/, a first technique techniques/<name>/<name>_example/ and
//! experiments/<name>.yaml.
int newFamily(const NewFamilyOptions& options);

struct SceneOptions {
    std::string scene; //!< procedural scene name or scene file
    int frame = 0;
};
//! Prints what a scene holds, its loader warnings, the load time and the peak resident memory.
int sceneCommand(const SceneOptions& options);

struct GpuOptions {
    std::string device;  //!< device name substring; empty = automatic
    bool validation = false;
};
int gpuSmoke(const GpuOptions& options);

struct StressCommandOptions {
    std::vector<std::string> families;
    std::vector<std::string> techniques;
    std::vector<std::string> cases;
    std::string outputDirectory = "results/stress";
    std::uint64_t seed = 1;
    bool cpuOnly = false;    //!< skip the Vulkan paths
    std::string device;      //!< Vulkan device name substring; empty = automatic
    std::string commandLine; //!< as typed, for the page
};
//! Every chosen technique through its family's stress cases: a table, heat maps and a page;
//! exit 1 when a case failed.
int stressCommand(const StressCommandOptions& options);

struct MergeOptions {
    std::string outputDirectory;
    std::vector<std::string> shardDirectories;
};
int mergeCommand(const MergeOptions& options);

struct BestOptions {
    std::string resultsDirectory;
    std::string maxTime;   //!< e.g. "5ms"
    double maxError = -1.0;
    std::string timeColumn;   //!< "" = the family's time column (report/report.h)
    std::string errorColumn;  //!< "" = the family's error column
    std::vector<std::string> where;  //!< "column=value" filters, all must hold
    bool perTechnique = false;       //!< one answer per technique (the equal-time comparison)
};
int bestCommand(const BestOptions& options);

struct ReferenceOptions {
    std::string scene;            //!< procedural scene name or scene file
    std::string quantity = "ao";
    std::string outputDirectory;
    int width = 256;
    int height = 256;
    int frame = 0;
    double radius = -1.0;         //!< world units; <= 0 = unbounded (ao, bent)
    std::string falloff = "linear";
    int bounces = 2;
    double targetStdErr = 0.005;
    double targetRelStdErr = 0.01;
    int maxSamples = 4096;
    std::uint64_t seed = 0;
    int threads = 0;
    bool noCache = false;
    std::string gbuffer = "vulkan";  //!< "vulkan" (rasterised) or "embree" (ray cast)
    int throughputSamples = 0;       //!< > 0: also measure Mrays/s against raw rtcIntersect1
};
int referenceCommand(const ReferenceOptions& options);

//! The repository root rtlab was built from ($RTLAB_SOURCE_DIR overrides).
std::string defaultSourceDirectory();

} // namespace rtlab::cli
