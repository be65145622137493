#include "experiment/slurm.h"

#include "core/error.h"
#include "experiment/results.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>

namespace rtlab::experiment {
namespace {

namespace fs = std::filesystem;

//! Single-quoted for bash (a ' inside becomes '\'').
std::string quoteForShell(const std::string& s)
{
    std::string out = "'";
    for (char c : s)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

//! Partition names and time limits are single sbatch words: letters, digits and -_:.,
void checkWord(const std::string& value, const char* option)
{
    static const std::regex word("[A-Za-z0-9_.,:-]*");
    if (!std::regex_match(value, word))
        throw InputError({option, 0, 0}, std::string(option) + " '" + value +
                                             "': expected letters, digits and - _ . , : only");
}

//! The number of runs of the sweep from a shard's manifest (its "runs" list); 0 when unreadable.
std::size_t readSweepSize(const fs::path& manifest)
{
    try {
        // The manifest is JSON, which YAML reads.
        const YAML::Node root = YAML::LoadFile(manifest.string());
        const YAML::Node runs = root["runs"];
        return runs && runs.IsSequence() ? runs.size() : 0;
    } catch (const std::exception&) {
        return 0;
    }
}

} // namespace

std::string getShardDirectory(const std::string& outputDirectory, int index, int count)
{
    return (fs::path(outputDirectory) / ("shard-" + std::to_string(index) + "-of-" + std::to_string(count))).string();
}

std::string makeSlurmScript(const SlurmJob& job)
{
    if (job.arraySize < 1)
        throw InputError({"--array-size", 0, 0}, "--array-size " + std::to_string(job.arraySize) + ": expected 1 or more");
    std::vector<int> tasks = job.tasks;
    if (tasks.empty())
        for (int i = 1; i <= job.arraySize; ++i)
            tasks.push_back(i);
    std::sort(tasks.begin(), tasks.end());
    tasks.erase(std::unique(tasks.begin(), tasks.end()), tasks.end());
    for (int t : tasks)
        if (t < 1 || t > job.arraySize)
            throw InputError({"--tasks", 0, 0}, "--tasks " + std::to_string(t) + ": expected a task in 1.." +
                                                    std::to_string(job.arraySize));
    checkWord(job.partition, "--partition");
    checkWord(job.timeLimit, "--time");

    // Runs of consecutive tasks as ranges: 1-16, or 2-3,7.
    std::string array;
    for (std::size_t i = 0; i < tasks.size();) {
        std::size_t j = i;
        while (j + 1 < tasks.size() && tasks[j + 1] == tasks[j] + 1)
            ++j;
        array += (array.empty() ? "" : ",") + std::to_string(tasks[i]) +
                 (j > i ? "-" + std::to_string(tasks[j]) : std::string());
        i = j + 1;
    }
    const std::string logs = (fs::path(job.outputDirectory) / "slurm").string();
    std::ostringstream s;
    s << "#!/bin/bash\n"
      << "# rtlab sweep '" << job.experimentName << "' as a Slurm array: task i runs shard i of " << job.arraySize
      << " (rtlab run --shard i/" << job.arraySize << ").\n"
      << "# A task that stops early keeps its complete rows; submitting it again computes the rest.\n"
      << "#SBATCH --job-name=rtlab-" << job.experimentName << "\n"
      << "#SBATCH --array=" << array << "\n"
      << "#SBATCH --output=" << logs << "/%x-%A_%a.out\n"
      << "#SBATCH --ntasks=1\n";
    if (!job.partition.empty())
        s << "#SBATCH --partition=" << job.partition << "\n";
    if (!job.timeLimit.empty())
        s << "#SBATCH --time=" << job.timeLimit << "\n";
    s << "set -euo pipefail\n"
      << "cd " << quoteForShell(job.workingDirectory) << "\n"
      << "i=${SLURM_ARRAY_TASK_ID:?this script is an array job: submit it with sbatch}\n"
      << "exec " << quoteForShell(job.rtlabPath) << " run " << quoteForShell(job.experimentPath) << " --shard \"$i/"
      << job.arraySize << "\" --output " << quoteForShell(job.outputDirectory) << "/shard-\"$i\"-of-"
      << job.arraySize << " --no-report\n";
    return s.str();
}

std::vector<ShardProgress> collectShardProgress(const std::string& directory)
{
    static const std::regex shardName("shard-([0-9]+)-of-([0-9]+)");
    std::map<std::pair<int, int>, ShardProgress> found; // (count, index)
    std::map<int, std::size_t> sweepSize;                // count -> runs of the sweep
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(directory, ec)) {
        std::smatch m;
        const std::string name = entry.path().filename().string();
        if (!entry.is_directory() || !std::regex_match(name, m, shardName))
            continue;
        ShardProgress p;
        p.directory = entry.path().string();
        p.index = std::stoi(m[1]);
        p.count = std::stoi(m[2]);
        if (p.index < 1 || p.index > p.count)
            continue;
        const ResultsStore store(p.directory);
        p.started = fs::exists(store.jsonlPath());
        if (const std::size_t size = readSweepSize(entry.path() / "manifest.json"); size > 0)
            sweepSize[p.count] = size;
        if (p.started) {
            std::map<std::string, bool> ok; // config hash -> any ok row
            for (const auto& row : store.readRows()) {
                ++p.rows;
                std::string hash, status;
                for (const auto& [column, value] : row) {
                    if (column == "config_hash")
                        hash = value;
                    else if (column == "status")
                        status = value;
                }
                ok[hash] = ok[hash] || status == "ok";
            }
            for (const auto& [hash, good] : ok)
                (good ? p.done : p.failed) += 1;
        }
        found[{p.count, p.index}] = p;
    }
    // Every shard of each array size, started or not.
    std::set<int> counts;
    for (const auto& [key, p] : found)
        counts.insert(key.first);
    std::vector<ShardProgress> out;
    for (int n : counts)
        for (int i = 1; i <= n; ++i) {
            auto it = found.find({n, i});
            ShardProgress p = it != found.end() ? it->second : ShardProgress{};
            if (it == found.end()) {
                p.directory = getShardDirectory(directory, i, n);
                p.index = i;
                p.count = n;
            }
            // Shard i of n holds the runs k (0-based) with k mod n = i - 1.
            const std::size_t m = sweepSize.count(n) ? sweepSize[n] : 0;
            p.runs = m >= std::size_t(i) ? (m - std::size_t(i)) / std::size_t(n) + 1 : 0;
            out.push_back(p);
        }
    return out;
}

} // namespace rtlab::experiment
