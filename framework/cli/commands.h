#pragma once
// The `rtlab` subcommands. Each returns the process exit code:
// 0 success, 1 the work ran but something failed, 2 bad input (file, config or arguments),
// 3 the environment lacks something (no Vulkan device, ...).

#include <string>

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
};
int runExperimentCommand(const RunOptions& options);

struct NewTechniqueOptions {
    std::string family;
    std::string name;
    std::string sourceDirectory;  //!< repository root; default: the one rtlab was built from
};
int newTechnique(const NewTechniqueOptions& options);

struct GpuOptions {
    std::string device;  //!< device name substring; empty = automatic
    bool validation = false;
};
int gpuSmoke(const GpuOptions& options);

//! The repository root rtlab was built from ($RTLAB_SOURCE_DIR overrides).
std::string defaultSourceDirectory();

} // namespace rtlab::cli
