#include "experiment/runner.h"

#include "core/error.h"
#include "core/json.h"
#include "core/progress.h"
#include "experiment/family.h"
#include "experiment/gpu_timing.h"
#include "experiment/lit_frame.h"
#include "experiment/manifest.h"
#include "gpu/context.h"
#include "pipeline/frame_graph.h"
#include "pipeline/frame_start.h"
#include "plugin/technique.h"
#include "reference/reference.h"
#include "scene/camera_paths.h"
#include "scene/scene_file.h"
#include "scene/sdf_shapes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "core/strings.h"

namespace rtlab::experiment {

DriverContext::DriverContext(const plugin::Registry& registry, std::string runDirectory)
    : mRegistry(registry), mRunDirectory(std::move(runDirectory))
{
}

DriverContext::~DriverContext() = default;

gpu::Context& DriverContext::getGpu()
{
    if (!mGpu)
        mGpu = std::make_unique<gpu::Context>();
    return *mGpu;
}

namespace {

//! Prints each of the scene's loading warnings once per process, on stderr (the rows carry them
//! too, as scene.warnings).
void reportSceneWarnings(const scene::Scene& scene)
{
    static std::mutex mutex;
    static std::set<std::string> printed;
    const std::lock_guard lock(mutex);
    for (const auto& w : scene.warnings)
        if (printed.insert(w).second)
            std::fprintf(stderr, "warning: %s\n", w.c_str());
}

} // namespace

void writePassRecords(ResultRow& row, const std::vector<pipeline::PassRecord>& records)
{
    std::int64_t ran = 0, skipped = 0;
    double frameCpu = 0.0, frameGpu = 0.0, frameHost = 0.0;
    std::uint64_t frameUpload = 0, frameReadback = 0, frameSubmits = 0, frameWaits = 0;
    std::string framePasses;
    for (const auto& r : records) {
        (r.ran ? ran : skipped) += 1;
        if (!r.measurement)
            framePasses += (framePasses.empty() ? "" : ";") + r.name;
        if (!r.ran || !r.time)
            continue;
        // What crossed the bus, and the host's own time: per call the CPU wall time less the
        // waits on the device (gpu/bus_counters.h), the median over the timed calls.
        const double hostMs = r.hostMs;
        if (!r.measurement) {
            frameCpu += r.time->cpuMs.median;
            if (!r.time->gpuMs.empty())
                frameGpu += r.time->gpuTotalMedianMs();
            frameHost += hostMs;
            frameUpload += r.uploadBytes;
            frameReadback += r.readbackBytes;
            frameSubmits += r.submits;
            frameWaits += r.waits;
        }
        row.set(r.name + ".host_ms", hostMs)
            .set(r.name + ".upload_bytes", std::int64_t(r.uploadBytes))
            .set(r.name + ".readback_bytes", std::int64_t(r.readbackBytes))
            .set(r.name + ".submits", std::int64_t(r.submits))
            .set(r.name + ".waits", std::int64_t(r.waits));
        if (r.timing == pipeline::PassTiming::Repeated) {
            addTimingColumns(row, r.name, *r.time);
        } else {
            row.set(r.name + ".cpu_ms", r.time->cpuMs.median);
            if (!r.time->gpuMs.empty())
                row.set(r.name + ".gpu_ms", r.time->gpuTotalMedianMs());
        }
    }
    row.set("passes", pipeline::formatPassRecords(records))
        .set("passes_run", ran)
        .set("passes_skipped", skipped);
    // The frame's own time: every pass that makes it (not the ground truths, metrics and files).
    row.set("frame.cpu_ms", frameCpu)
        .set("frame.gpu_ms", frameGpu)
        .set("frame.host_ms", frameHost)
        .set("frame.upload_bytes", std::int64_t(frameUpload))
        .set("frame.readback_bytes", std::int64_t(frameReadback))
        .set("frame.submits", std::int64_t(frameSubmits))
        .set("frame.waits", std::int64_t(frameWaits))
        .set("frame_passes", framePasses);
}

void applySamplingOptions(const ReferenceOptions& options, reference::ReferenceSettings& settings)
{
    settings.targetStdErr = options.targetStdErr;
    settings.targetRelStdErr = options.targetRelStdErr;
    settings.maxSamples = options.maxSamples;
    settings.batchSize = std::min(settings.batchSize, settings.maxSamples);
    settings.seed = options.seed;
}

void addParamColumns(ResultRow& row, const plugin::Technique& technique, const std::string& prefix)
{
    const config::ParamSet effective = technique.effectiveParams();
    for (const auto& [name, value] : effective.values())
        row.set(prefix + name, config::formatValue(value));
}

void addMemoryColumns(ResultRow& row)
{
    // VmRSS and VmHWM of /proc/self/status, in kB.
    std::ifstream in("/proc/self/status");
    double rss = std::nan(""), peak = std::nan("");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("VmRSS:", 0) == 0)
            rss = std::stod(line.substr(6)) / 1024.0;
        else if (line.rfind("VmHWM:", 0) == 0)
            peak = std::stod(line.substr(6)) / 1024.0;
    }
    row.set("memory.rss_mb", rss).set("memory.peak_rss_mb", peak);
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

std::string joinFamilies(const RunConfig& run, bool techniques)
{
    std::string s;
    for (const auto& [family, choice] : run.techniques)
        s += (s.empty() ? "" : "+") + (techniques ? choice.technique : family);
    return s;
}

// One run: the frame graph of its families (with the shared frame start when they are screen
// families), executed once per frame; one row per frame.
std::vector<ResultRow> executeRun(const RunConfig& run, DriverContext& context,
                                  const ResultRow& common)
{
    const plugin::Registry& registry = context.registry();
    std::vector<const plugin::FamilyInfo*> families;
    bool screen = false;
    for (const auto& [family, choice] : run.techniques) {
        const plugin::FamilyInfo* info = registry.findFamily(family);
        if (!info || !info->runtime)
            throw Error("family '" + family +
                        "' cannot run in experiments (it registers no runtime)");
        families.push_back(info);
        screen = screen || info->domain == plugin::FamilyDomain::Screen;
    }
    for (const plugin::FamilyInfo* info : families)
        if (info->domain == plugin::FamilyDomain::Volume && families.size() > 1)
            throw Error("family '" + info->name +
                        "' works on a sampled volume and cannot share a run with other "
                        "families (" +
                        joinFamilies(run, false) + ")");
    pipeline::FrameGraph graph;
    std::vector<std::string> outputs;
    std::optional<scene::Scene> scene;
    std::unique_ptr<pipeline::FrameStart> start;
    int frames = 1;
    if (screen) {
        if (scene::findAnalyticShape(run.scene))
            throw Error(
                "scene '" + run.scene +
                "' is an analytic shape for isosurface studies; screen-space families need a scene "
                "with geometry and a camera (e.g. ao_testbed, tomorrow_town, or a .yaml file)");
        scene = scene::loadScene(run.scene);
        reportSceneWarnings(*scene);
        if (run.frames > scene->frameCount && (run.cameraPath.empty() || run.cameraPath == "scene"))
            throw Error(
                "the run asks for " + std::to_string(run.frames) + " frames but scene '" +
                scene->name + "' has " + std::to_string(scene->frameCount) +
                " (choose a camera_path such as orbit to move the camera over more frames)");
        scene::selectCameraPath(*scene, run.cameraPath, run.frames);
        start = std::make_unique<pipeline::FrameStart>(
            *scene, context.getGpu(), pipeline::FrameStartOptions{run.width, run.height});
        start->addPasses(graph);
        frames = run.frames;
    }
    std::vector<std::unique_ptr<FamilyRun>> familyRuns;
    for (const plugin::FamilyInfo* info : families) {
        RunSetup setup{run,
                       *info,
                       context,
                       graph,
                       start.get(),
                       outputs,
                       families.size() > 1 ? "param." + info->name + "." : "param."};
        familyRuns.push_back(info->runtime->beginRun(setup));
    }

    std::unique_ptr<LitFrame> litFrame;
    if (run.lighting) {
        if (!start)
            throw Error("frame: {lighting: true} needs a screen family (the lit frame is composed "
                        "from the G-buffer)");
        litFrame = std::make_unique<LitFrame>(run, context, *start, graph, outputs);
    }

    ResultRow base = common;
    if (scene && !scene->warnings.empty()) {
        std::string joined;
        for (const auto& w : scene->warnings)
            joined += (joined.empty() ? "" : "; ") + w;
        base.set("scene.warnings", joined);
    }
    for (const auto& family : familyRuns)
        family->describe(base);
    if (litFrame)
        litFrame->describe(base);
    if (screen) {
        base.set("camera_path", run.cameraPath.empty() ? std::string("scene") : run.cameraPath)
            .set("scene_features", start->getFeatures().toString())
            .set("gpu_time_source",
                 std::string(toString(chooseGpuTimeSource(context.getGpu().getDeviceInfo()))));
        base.set("frame.culling", run.culling).set("frame.gbuffer_on_gpu", run.gbufferOnGpu);
        for (const auto& [name, value] : scene->parameters)
            base.set("scene." + name, value);
    }
    std::vector<ResultRow> rows;
    for (int frame = 0; frame < frames; ++frame) {
        ResultRow row = base;
        if (screen)
            row.set("frame", std::int64_t(frame));
        for (const auto& family : familyRuns)
            family->beginFrame(frame, row);
        if (litFrame)
            litFrame->beginFrame(row);
        pipeline::FrameOptions options;
        options.features = start ? start->getFeatures() : scene::FeatureSet{};
        options.outputs = outputs;
        options.frame = frame;
        options.culling = run.culling;
        options.timing = run.timing;
        if (screen)
            options.collectGpuTimes = [&] { return collectGpuPassTimes(context.getGpu()); };
        const auto records = graph.execute(options);
        row.set("frame.gpu_images_created", std::int64_t(graph.lastGpuAllocations()))
            .set("frame.gpu_images_reused", std::int64_t(graph.lastGpuReuses()));
        if (start && start->getStats().remeshFrame == frame)
            row.set("frame.sdf_remesh", start->getStats().remesh)
                .set("frame.sdf_cells_meshed", start->getStats().cellsMeshed)
                .set("frame.sdf_cells", start->getStats().cells);
        for (const auto& family : familyRuns)
            family->endFrame(frame, records, row);
        if (litFrame)
            litFrame->endFrame(row);
        writePassRecords(row, records);
        rows.push_back(std::move(row));
    }
    return rows;
}

} // namespace

RunnerSummary runExperiment(const Experiment& experiment, const plugin::Registry& registry,
                            const RunnerOptions& options)
{
    RunnerSummary summary;
    const bool sharded = options.shardCount > 1;
    const std::string shard =
        sharded ? std::to_string(options.shardIndex) + "/" + std::to_string(options.shardCount)
                : "";
    summary.outputDirectory = !options.outputDirectory.empty() ? options.outputDirectory
                              : sharded ? "results/" + experiment.name + "/shard-" +
                                              std::to_string(options.shardIndex) + "-of-" +
                                              std::to_string(options.shardCount)
                                        : "results/" + experiment.name;
    ResultsStore store(summary.outputDirectory);
    writeManifest(experiment, collectBuildInfo(options.queryVulkanForManifest),
                  summary.outputDirectory, shard);
    const auto done = store.completedHashes();

    std::vector<const RunConfig*> mine;
    for (std::size_t k = 0; k < experiment.runs.size(); ++k)
        if (int(k % std::size_t(options.shardCount)) == options.shardIndex - 1)
            mine.push_back(&experiment.runs[k]);
    summary.total = mine.size();

    std::unique_ptr<Progress> progress;
    if (!options.quiet)
        progress = std::make_unique<Progress>(
            "rtlab run " + experiment.name + (sharded ? " shard " + shard : ""), mine.size());

    DriverContext context(registry, summary.outputDirectory);
    for (const RunConfig* runPtr : mine) {
        const RunConfig& run = *runPtr;
        const std::string hash = run.hash();
        if (done.count(hash)) {
            ++summary.alreadyDone;
            if (progress)
                progress->advance(1, run.id() + " (done before)");
            continue;
        }
        ResultRow common;
        common.set("experiment", experiment.name)
            .set("shard", shard)
            .set("run_id", run.id())
            .set("config_hash", hash)
            .set("status", std::string("ok"))
            .set("error", std::string())
            .set("scene", run.scene)
            .set("grid", std::int64_t(run.grid))
            .set("width", std::int64_t(run.width))
            .set("height", std::int64_t(run.height));
        if (experiment.reportTimeFromFrame > 0)
            common.set("report.time_from_frame", std::int64_t(experiment.reportTimeFromFrame));
        context.setRunDirectory(summary.outputDirectory + "/runs/" + run.id());
        std::vector<ResultRow> rows;
        try {
            std::filesystem::create_directories(context.runDirectory());
            common.set("family", joinFamilies(run, false))
                .set("technique", joinFamilies(run, true));
            for (auto& row : executeRun(run, context, common)) {
                addMemoryColumns(row);
                rows.push_back(std::move(row));
            }
            ++summary.succeeded;
        } catch (const std::exception& e) {
            rows.assign(1, common);
            rows[0].set("status", std::string("failed")).set("error", std::string(e.what()));
            ++summary.failed;
        }
        store.append(rows);
        if (progress)
            progress->advance(1, run.id());
    }
    if (progress)
        progress->finish();
    store.writeCsv();
    return summary;
}

} // namespace rtlab::experiment

namespace rtlab::experiment {

void parseShard(const std::string& text, RunnerOptions& options)
{
    const auto slash = text.find('/');
    int i = 0, n = 0;
    bool ok = slash != std::string::npos;
    if (ok) {
        try {
            std::size_t used = 0;
            i = std::stoi(text.substr(0, slash), &used);
            ok = used == slash;
            n = std::stoi(text.substr(slash + 1), &used);
            ok = ok && used == text.size() - slash - 1;
        } catch (const std::exception&) {
            ok = false;
        }
    }
    if (!ok || n < 1 || i < 1 || i > n)
        throw InputError({"--shard", 0, 0},
                         "expected i/N with 1 <= i <= N (e.g. 2/4), found '" + text + "'");
    options.shardIndex = i;
    options.shardCount = n;
}

std::size_t mergeShards(const std::vector<std::string>& shardDirectories,
                        const std::string& outputDirectory)
{
    namespace fs = std::filesystem;
    ResultsStore out(outputDirectory);
    if (fs::exists(out.jsonlPath()))
        fs::remove(out.jsonlPath());
    // Rows keyed by config hash; an ok row replaces a failed one, never the other way round.
    std::vector<std::string> order;
    std::map<std::string, std::pair<bool, std::string>> rows;
    std::vector<std::string> shardNames;
    for (const auto& dir : shardDirectories) {
        const fs::path jsonl = fs::path(dir) / "results.jsonl";
        if (!fs::exists(jsonl))
            throw Error(dir + ": not a results folder (no results.jsonl)");
        std::ifstream in(jsonl);
        for (std::string line; std::getline(in, line);) {
            if (line.empty() || line.front() != '{' || line.back() != '}')
                continue; // a torn line from an interrupted shard
            const auto hashAt = line.find("\"config_hash\":\"");
            if (hashAt == std::string::npos)
                continue;
            const auto start = hashAt + 15;
            const std::string hash = line.substr(start, line.find('"', start) - start);
            const bool ok = line.find("\"status\":\"ok\"") != std::string::npos;
            auto it = rows.find(hash);
            if (it == rows.end()) {
                order.push_back(hash);
                rows[hash] = {ok, line};
            } else if (ok && !it->second.first) {
                it->second = {ok, line};
            }
        }
        if (fs::exists(fs::path(dir) / "runs"))
            fs::copy(fs::path(dir) / "runs", fs::path(outputDirectory) / "runs",
                     fs::copy_options::recursive | fs::copy_options::overwrite_existing);
        shardNames.push_back(dir);
    }
    {
        std::ofstream merged(out.jsonlPath(), std::ios::trunc);
        for (const auto& hash : order)
            merged << rows[hash].second << "\n";
    }
    const fs::path firstManifest = fs::path(shardDirectories.front()) / "manifest.json";
    if (fs::exists(firstManifest)) {
        std::string manifest = readTextFile(firstManifest.string());
        while (!manifest.empty() && (manifest.back() == '\n' || manifest.back() == '}'))
            manifest.pop_back();
        std::vector<std::string> quoted;
        for (const auto& s : shardNames)
            quoted.push_back(jsonEscape(s));
        std::ofstream(fs::path(outputDirectory) / "manifest.json")
            << manifest << ",\"merged_from\":" << jsonArray(quoted) << "}\n";
    }
    return out.writeCsv();
}

} // namespace rtlab::experiment
