// rtlab scene: what a scene holds and what loading it cost, so that a downloaded model can be
// checked before a study runs on it: meshes (triangles, vertices, normals computed or read),
// materials, SDF models, lights, characters, frames, the loader's warnings, the load time and the
// process's peak resident memory.

#include "cli/commands.h"

#include "core/error.h"
#include "scene/scene_file.h"

#include <fmt/core.h>

#include <chrono>
#include <fstream>
#include <string>

namespace rtlab::cli {
namespace {

//! The process's peak resident set (VmHWM of /proc/self/status), in MiB; -1 where unavailable.
double readPeakResidentMiB()
{
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line))
        if (line.rfind("VmHWM:", 0) == 0)
            return std::stod(line.substr(6)) / 1024.0; // kB
    return -1.0;
}

} // namespace

int sceneCommand(const SceneOptions& options)
{
    try {
        const double peakBefore = readPeakResidentMiB();
        const auto start = std::chrono::steady_clock::now();
        const scene::Scene scene = scene::loadScene(options.scene);
        const double loadSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const auto buildStart = std::chrono::steady_clock::now();
        const scene::RenderScene frame = scene.buildRenderScene(options.frame);
        const double buildSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - buildStart).count();
        const double peakAfter = readPeakResidentMiB();

        fmt::print("scene:       {} ({})\n", scene.name, scene.source);
        std::size_t meshTriangles = 0;
        for (const auto& m : scene.meshes) {
            meshTriangles += m.indices.size() / 3;
            fmt::print("mesh:        {}: {} triangles, {} vertices, normals: {}\n", m.name,
                       m.indices.size() / 3, m.positions.size(),
                       m.normalsSource.empty() ? std::string(m.normals.empty() ? "computed" : "given")
                                               : m.normalsSource);
        }
        fmt::print("materials:   {}\n", scene.materials.size());
        fmt::print("sdf models:  {}\n", scene.sdfModels.size());
        fmt::print("lights:      {} point lights\n", scene.pointLights.size());
        fmt::print("characters:  {}\n", scene.characters.size());
        fmt::print("frames:      {}\n", scene.frameCount);
        fmt::print("frame {}:     {} triangles in all ({} from meshes)\n", options.frame,
                   frame.indices.size() / 3, meshTriangles);
        for (const auto& w : scene.warnings)
            fmt::print("warning:     {}\n", w);
        fmt::print("load:        {:.3f} s (scene file and meshes), {:.3f} s (frame {} built)\n",
                   loadSeconds, buildSeconds, options.frame);
        if (peakAfter >= 0.0)
            fmt::print("peak memory: {:.0f} MiB resident ({:.0f} MiB before loading)\n", peakAfter,
                       peakBefore);
        return kExitOk;
    } catch (const Error& e) {
        fmt::print(stderr, "rtlab scene: {}\n", e.what());
        return kExitBadInput;
    }
}

} // namespace rtlab::cli
