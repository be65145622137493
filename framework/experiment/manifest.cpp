#include "experiment/manifest.h"

#include "core/json.h"
#include "core/strings.h"
#include "gpu/context.h"

#include <CLI/Version.hpp>
#include <OpenImageIO/oiioversion.h>
#include <embree3/rtcore_config.h>
#include <fmt/core.h>
#include <glm/detail/setup.hpp>
#include <tbb/version.h>
#include <vulkan/vulkan_core.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

namespace rtlab::experiment {

namespace {

// Output of a shell command (stdout), trimmed; "" when it fails.
std::string runCommand(const std::string& command, int* status = nullptr)
{
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(::popen((command + " 2>/dev/null").c_str(), "r"),
                                               ::pclose);
    if (!pipe)
        return "";
    std::string out;
    std::array<char, 256> buf;
    while (std::fgets(buf.data(), int(buf.size()), pipe.get()))
        out += buf.data();
    const int rc = ::pclose(pipe.release());
    if (status)
        *status = rc;
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r'))
        out.pop_back();
    return out;
}

std::string readCpuModel()
{
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            return colon == std::string::npos ? line : line.substr(colon + 2);
        }
    return "unknown";
}

std::string sourceDirectory()
{
    if (const char* env = std::getenv("RTLAB_SOURCE_DIR"); env && *env)
        return env;
    return RTLAB_MANIFEST_SOURCE_DIR;
}

// Every parameter named "seed" in the expanded runs, as {"run id": {"family": seed}}; the runs'
// results depend on no other source of randomness (no clock, no thread count).
std::string collectSeeds(const Experiment& experiment)
{
    JsonObject seeds;
    for (const auto& run : experiment.runs) {
        JsonObject perFamily;
        bool any = false;
        for (const auto& [family, choice] : run.techniques)
            if (choice.params.has("seed")) {
                perFamily.add(family, config::formatValue(choice.params.get("seed")));
                any = true;
            }
        if (any)
            seeds.addRaw(run.id(), perFamily.str());
    }
    return seeds.str();
}

} // namespace

BuildInfo collectBuildInfo(bool queryVulkan)
{
    BuildInfo info;
    const std::string src = sourceDirectory();
    int status = -1;
    info.gitRevision = runCommand("git -C '" + src + "' rev-parse HEAD", &status);
    if (status != 0 || info.gitRevision.empty()) {
        info.gitRevision = "unknown (not a git checkout)";
    } else {
        info.gitDirty =
            !runCommand("git -C '" + src + "' status --porcelain --untracked-files=no").empty();
    }
    info.cpuModel = readCpuModel();
    info.hardwareThreads = std::thread::hardware_concurrency();
    if (queryVulkan) {
        try {
            const gpu::Context context{gpu::ContextOptions{}};
            info.vulkanDevice = context.getDeviceInfo().name;
            info.vulkanDriver = context.getDeviceInfo().driverInfo;
        } catch (const std::exception& e) {
            info.vulkanDevice = "";
            info.vulkanDriver = std::string("unavailable: ") + e.what();
        }
    }
    info.dependencies = JsonObject()
                            .add("compiler", std::string(__VERSION__))
                            .add("vulkan_headers", std::to_string(VK_HEADER_VERSION))
                            .add("embree", std::string(RTC_VERSION_STRING))
                            .add("openimageio", std::string(OIIO_VERSION_STRING))
                            .add("tbb", std::string(TBB_VERSION_STRING))
                            .add("fmt", std::to_string(FMT_VERSION))
                            .add("glm", std::to_string(GLM_VERSION))
                            .add("cli11", std::string(CLI11_VERSION))
                            .str();
    return info;
}

void writeManifest(const Experiment& experiment, const BuildInfo& info,
                   const std::string& directory, const std::string& shard)
{
    std::vector<std::string> runs;
    for (const auto& r : experiment.runs)
        runs.push_back(JsonObject()
                           .add("id", r.id())
                           .add("config_hash", r.hash())
                           .addRaw("config", r.toJson())
                           .str());
    std::string experimentText;
    try {
        experimentText = readTextFile(experiment.path);
    } catch (const std::exception&) {
        experimentText = ""; // parsed from memory (tests)
    }
    const std::string json = JsonObject()
                                 .add("experiment", experiment.name)
                                 .add("file", experiment.path)
                                 .add("file_text", experimentText)
                                 .add("description", experiment.description)
                                 .add("shard", shard)
                                 .add("git_revision", info.gitRevision)
                                 .add("git_dirty", info.gitDirty)
                                 .add("cpu", info.cpuModel)
                                 .add("hardware_threads", std::int64_t(info.hardwareThreads))
                                 .add("vulkan_device", info.vulkanDevice)
                                 .add("vulkan_driver", info.vulkanDriver)
                                 .addRaw("dependencies", info.dependencies)
                                 .addRaw("seeds", collectSeeds(experiment))
                                 .addRaw("runs", jsonArray(runs))
                                 .str();
    const std::string path = directory + "/manifest.json";
    {
        std::ofstream out(path + ".tmp", std::ios::trunc);
        out << json << "\n";
    }
    std::filesystem::rename(path + ".tmp", path);
}

} // namespace rtlab::experiment
