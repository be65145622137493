// rtlab run --slurm (submit a sweep as an sbatch array) and rtlab status (shard progress).

#include "cli/commands.h"

#include "core/error.h"
#include "experiment/experiment.h"
#include "experiment/slurm.h"

#include <fmt/core.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

namespace rtlab::cli {
namespace {

namespace fs = std::filesystem;

//! Runs `command` through the shell; returns its exit code and what it printed (stderr too).
std::pair<int, std::string> runShell(const std::string& command)
{
    std::string output;
    std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
    if (pipe == nullptr)
        return {-1, "cannot start: " + command};
    std::array<char, 4096> buffer;
    while (const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe))
        output.append(buffer.data(), n);
    const int status = ::pclose(pipe);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

} // namespace

int submitSlurmCommand(const RunOptions& options, const experiment::Experiment& e)
{
    if (!options.shard.empty()) {
        fmt::print(stderr, "--shard and --slurm: the Slurm array runs every shard; leave --shard out\n");
        return kExitBadInput;
    }
    experiment::SlurmJob job;
    job.experimentName = e.name;
    job.experimentPath = fs::absolute(options.experimentPath).lexically_normal().string();
    job.rtlabPath = fs::canonical("/proc/self/exe").string();
    job.workingDirectory = fs::current_path().string();
    job.outputDirectory =
        fs::absolute(options.outputDirectory.empty() ? "results/" + e.name : options.outputDirectory)
            .lexically_normal()
            .string();
    job.arraySize = options.arraySize;
    job.tasks = options.tasks;
    job.partition = options.partition;
    job.timeLimit = options.timeLimit;
    std::string script;
    try {
        script = experiment::makeSlurmScript(job);
    } catch (const InputError& error) {
        fmt::print(stderr, "{}\n", error.what());
        return kExitBadInput;
    }
    const fs::path logs = fs::path(job.outputDirectory) / "slurm";
    fs::create_directories(logs);
    const fs::path scriptPath = logs / (e.name + "-array-of-" + std::to_string(job.arraySize) + ".sbatch");
    {
        std::ofstream out(scriptPath);
        out << script;
        if (!out) {
            fmt::print(stderr, "rtlab run --slurm: cannot write {}\n", scriptPath.string());
            return kExitFailed;
        }
    }
    fs::permissions(scriptPath, fs::perms::owner_exec, fs::perm_options::add);

    // $RTLAB_SBATCH names another sbatch (a wrapper, or a test's stand-in).
    const char* sbatch = std::getenv("RTLAB_SBATCH");
    const std::string program = sbatch != nullptr && *sbatch != '\0' ? sbatch : "sbatch";
    const auto [code, output] = runShell(program + " --parsable '" + scriptPath.string() + "'");
    if (code == 127 || output.find("not found") != std::string::npos) {
        fmt::print(stderr, "rtlab run --slurm: '{}' is not available ({}); the script is {}\n", program, output,
                   scriptPath.string());
        return kExitEnvironment;
    }
    if (code != 0) {
        fmt::print(stderr, "rtlab run --slurm: sbatch failed ({}): {}\nthe script is {}\n", code, output,
                   scriptPath.string());
        return kExitFailed;
    }
    // --parsable prints "jobid" or "jobid;cluster".
    std::string jobId = output.substr(0, output.find_first_of(";\n"));
    fmt::print("{}: {} run(s) in {} shard(s), submitted as Slurm job {} (array {})\n", e.name, e.runs.size(),
               job.arraySize, jobId, script.substr(script.find("--array=") + 8,
                                                   script.find('\n', script.find("--array=")) -
                                                       script.find("--array=") - 8));
    fmt::print("script:   {}\nlogs:     {}/\n", scriptPath.string(), logs.string());
    fmt::print("progress: rtlab status {}\n", job.outputDirectory);
    fmt::print("then:     rtlab merge -o {} {}/shard-*-of-{}\n", job.outputDirectory, job.outputDirectory,
               job.arraySize);
    fmt::print("a task that stopped early: rtlab run {} --slurm --array-size {} --tasks <i> (it resumes)\n",
               options.experimentPath, job.arraySize);
    return kExitOk;
}

int statusCommand(const std::string& resultsDirectory)
{
    const auto shards = experiment::collectShardProgress(resultsDirectory);
    if (shards.empty()) {
        fmt::print(stderr, "rtlab status: {} holds no shard-i-of-N folder (run with --shard or --slurm)\n",
                   resultsDirectory);
        return kExitBadInput;
    }
    int count = 0;
    std::size_t runs = 0, done = 0, failed = 0;
    bool complete = true;
    auto printTotal = [&] {
        fmt::print("{:<10} {:>6} {:>6} {:>7}  {}\n", "all", runs, done, failed,
                   complete ? "complete: rtlab merge -o " + resultsDirectory + " " + resultsDirectory +
                                  "/shard-*-of-" + std::to_string(count)
                            : std::to_string(runs - std::min(runs, done + failed)) + " run(s) to go");
    };
    for (const auto& s : shards) {
        if (s.count != count) {
            if (count != 0)
                printTotal();
            count = s.count;
            runs = done = failed = 0;
            complete = true;
            fmt::print("{:<10} {:>6} {:>6} {:>7}  {}\n", "shard", "runs", "done", "failed", "state");
        }
        const bool finished = s.runs > 0 && s.done + s.failed >= s.runs;
        complete = complete && finished;
        runs += s.runs;
        done += s.done;
        failed += s.failed;
        const std::string state = !s.started ? "not started"
                                  : finished ? (s.failed > 0 ? "finished with failures" : "complete")
                                             : "running or stopped";
        fmt::print("{:<10} {:>6} {:>6} {:>7}  {}\n", std::to_string(s.index) + "/" + std::to_string(s.count), s.runs,
                   s.done, s.failed, state);
    }
    printTotal();
    return kExitOk;
}

} // namespace rtlab::cli
