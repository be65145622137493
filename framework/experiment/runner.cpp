#include "experiment/runner.h"

#include "core/error.h"
#include "core/json.h"
#include "core/progress.h"
#include "plugin/technique.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

namespace rtlab::experiment {

const std::map<std::string, FamilyDriver>& familyDrivers()
{
    static const std::map<std::string, FamilyDriver> drivers = {
        {"isosurface", &runIsosurfaceFamily},
    };
    return drivers;
}

void addTimingColumns(ResultRow& row, const std::string& pass, const metrics::TimingReport& report)
{
    row.set(pass + ".cpu_ms", report.cpuMs.median);
    row.set(pass + ".cpu_ms_iqr", report.cpuMs.iqr());
    row.set(pass + ".first_use_ms", report.firstUseMs);
    row.set(pass + ".setup_ms", report.setupMs);
    row.set(pass + ".repeats", std::int64_t(report.cpuMs.count));
    if (!report.gpuMs.empty()) {
        row.set(pass + ".gpu_ms", report.gpuTotalMedianMs());
        for (const auto& [gpuPass, stats] : report.gpuMs) {
            row.set(pass + "." + gpuPass + ".gpu_ms", stats.median);
            row.set(pass + "." + gpuPass + ".gpu_ms_iqr", stats.iqr());
        }
    }
}

namespace {

std::string cpuModel()
{
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            return colon == std::string::npos ? line : line.substr(colon + 2);
        }
    return "unknown";
}

void writeManifest(const Experiment& experiment, const std::string& directory)
{
    std::vector<std::string> runs;
    for (const auto& r : experiment.runs)
        runs.push_back(JsonObject().add("id", r.id()).addRaw("config", r.toJson()).str());
    const std::string json = JsonObject()
                                 .add("experiment", experiment.name)
                                 .add("file", experiment.path)
                                 .add("description", experiment.description)
                                 .add("cpu", cpuModel())
                                 .add("hardware_threads", std::int64_t(std::thread::hardware_concurrency()))
                                 .addRaw("runs", jsonArray(runs))
                                 .str();
    const std::string path = directory + "/manifest.json";
    std::ofstream(path + ".tmp") << json << "\n";
    std::filesystem::rename(path + ".tmp", path);
}

} // namespace

RunnerSummary runExperiment(const Experiment& experiment, const plugin::Registry& registry,
                            const RunnerOptions& options)
{
    RunnerSummary summary;
    summary.outputDirectory =
        options.outputDirectory.empty() ? "results/" + experiment.name : options.outputDirectory;
    ResultsStore store(summary.outputDirectory);
    writeManifest(experiment, summary.outputDirectory);
    const auto done = store.completedHashes();
    summary.total = experiment.runs.size();

    std::unique_ptr<Progress> progress;
    if (!options.quiet)
        progress = std::make_unique<Progress>("rtlab run " + experiment.name, experiment.runs.size());

    for (const RunConfig& run : experiment.runs) {
        const std::string hash = run.hash();
        if (done.count(hash)) {
            ++summary.alreadyDone;
            if (progress)
                progress->advance(1, run.id() + " (done before)");
            continue;
        }
        ResultRow row;
        row.set("experiment", experiment.name)
            .set("run_id", run.id())
            .set("config_hash", hash)
            .set("status", std::string("ok"))
            .set("error", std::string())
            .set("scene", run.scene)
            .set("grid", std::int64_t(run.grid));
        const std::string runDirectory = summary.outputDirectory + "/runs/" + run.id();
        try {
            std::filesystem::create_directories(runDirectory);
            for (const auto& [family, choice] : run.techniques) {
                row.set("family", family).set("technique", choice.technique);
                auto driver = familyDrivers().find(family);
                if (driver == familyDrivers().end())
                    throw Error("family '" + family + "' cannot run in experiments yet (no driver)");
                driver->second(run, family, registry, runDirectory, row);
            }
            ++summary.succeeded;
        } catch (const std::exception& e) {
            row.set("status", std::string("failed")).set("error", std::string(e.what()));
            ++summary.failed;
        }
        store.append(row);
        if (progress)
            progress->advance(1, run.id());
    }
    if (progress)
        progress->finish();
    store.writeCsv();
    return summary;
}

} // namespace rtlab::experiment
