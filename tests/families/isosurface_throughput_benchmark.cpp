// Throughput of every registered isosurface technique on the very same sampled grid, as ratios to
// the two baselines, VTK's Flying Edges and OpenVDB's volumeToMesh, at the same thread count.
// Fields: a sphere (smooth) and csg_gallery's chamfered_cube (sharp), each evaluated once by the
// hierarchical SDF evaluator at grid^3 samples with Hermite data; every technique meshes those
// samples (dual contouring also reads the Hermite data). Each technique runs inside a TBB arena of
// `threads` workers, with its own `threads` parameter set to the same count where it has one
// (VTK's SMP backend is TBB; OpenVDB uses TBB), after one warm-up call; the techniques then take
// turns for --repeats rounds (each an untimed and a timed call) and each time is the median of its
// rounds' wall time around extract().
//
//   isosurface_throughput_benchmark [--grid 256] [--threads N] [--repeats 5] [--technique NAME]...
//                                   [--quick]
// --technique (repeatable) times only the named techniques (a ratio column is 0 when its
// baseline was not timed), e.g. to profile one of them with perf.
// --threads 0 (the default) runs at 1 thread and at all hardware threads. --quick: grid 32, one
// repeat (the ctest that keeps it compiling and running).

#include "families/isosurface/isosurface.h"
#include "plugin/technique.h"
#include "scene/procedural.h"
#include "sdf/evaluator.h"

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace rtlab;

namespace {

struct Options {
    int grid = 256;
    int threads = 0;
    int repeats = 5;
    std::vector<std::string> only; //!< --technique: time only these (empty: every one)
};

scene::SdfModel findModel(const std::string& name)
{
    for (const auto& m : scene::makeProceduralScene("csg_gallery").sdfModels)
        if (m.name == name)
            return m;
    std::fprintf(stderr, "no csg_gallery model %s\n", name.c_str());
    std::exit(2);
}

scene::SdfModel makeSphereModel()
{
    scene::SdfModel m{.name = "sphere"};
    scene::CsgEdit e;
    e.shape = scene::CsgShape::Sphere;
    e.size = glm::dvec3(0.7);
    m.edits.push_back(e);
    m.boundsMin = glm::dvec3(-0.8);
    m.boundsMax = glm::dvec3(0.8);
    return m;
}

//! One technique's mesher, created with the thread count, and its extraction times.
struct Timed {
    std::unique_ptr<plugin::Technique> technique;
    plugin::IsosurfaceTechnique* mesher = nullptr;
    TriangleMesh mesh;
    std::vector<double> ms;
};

//! Times every technique on one input: one untimed warm-up call each, then `repeats` rounds in
//! which the techniques take turns (an untimed call, then a timed one), each keeping the median of
//! its rounds. Alternating keeps a slow phase of a shared machine (other tenants, clock changes)
//! from landing on one technique only and skewing the ratios, which compare techniques timed
//! within the same rounds.
void timeTechniques(const std::vector<const plugin::TechniqueEntry*>& entries,
                    const plugin::IsosurfaceInput& input, int threads, int repeats,
                    std::map<std::string, double>& ms, std::map<std::string, std::size_t>& tris)
{
    std::vector<Timed> timed(entries.size());
    for (std::size_t i = 0; i < entries.size(); ++i) {
        config::ParamSet params = config::ParamSet::defaultsOf(entries[i]->schema);
        if (entries[i]->schema.find("threads"))
            params.set("threads", std::int64_t(threads));
        timed[i].technique = entries[i]->create(params);
        timed[i].mesher = dynamic_cast<plugin::IsosurfaceTechnique*>(timed[i].technique.get());
    }
    tbb::task_arena arena(threads);
    arena.execute([&] {
        for (Timed& t : timed)
            t.mesher->extract(input, t.mesh);
        for (int r = 0; r < repeats; ++r)
            for (Timed& t : timed) {
                // Each timed call follows an untimed one of the same technique, so it finds its
                // own workspace in the caches as in back-to-back runs, not the previous one's.
                t.mesher->extract(input, t.mesh);
                const auto start = std::chrono::steady_clock::now();
                t.mesher->extract(input, t.mesh);
                t.ms.push_back(std::chrono::duration<double, std::milli>(
                                   std::chrono::steady_clock::now() - start)
                                   .count());
            }
    });
    for (std::size_t i = 0; i < entries.size(); ++i) {
        std::vector<double>& v = timed[i].ms;
        std::sort(v.begin(), v.end());
        const std::size_t mid = v.size() / 2;
        ms[entries[i]->info.name] = v.size() % 2 ? v[mid] : 0.5 * (v[mid - 1] + v[mid]);
        tris[entries[i]->info.name] = timed[i].mesh.indices.size() / 3;
    }
}

} // namespace

int main(int argc, char** argv)
{
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&] {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "%s needs a value\n", a.c_str());
                std::exit(2);
            }
            return std::atoi(argv[++i]);
        };
        if (a == "--grid")
            options.grid = next();
        else if (a == "--threads")
            options.threads = next();
        else if (a == "--repeats")
            options.repeats = next();
        else if (a == "--technique") {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "--technique needs a value\n");
                return 2;
            }
            options.only.push_back(argv[++i]);
        } else if (a == "--quick") {
            options.grid = 32;
            options.repeats = 1;
        } else {
            std::fprintf(stderr,
                         "unknown argument %s; usage: %s [--grid N] [--threads N] [--repeats N] "
                         "[--technique NAME]... [--quick]\n",
                         a.c_str(), argv[0]);
            return 2;
        }
    }
    if (options.grid < 4 || options.repeats < 1 || options.threads < 0) {
        std::fprintf(stderr, "--grid must be >= 4, --repeats >= 1, --threads >= 0\n");
        return 2;
    }
    std::vector<int> threadCounts = {options.threads};
    if (options.threads == 0)
        threadCounts = {1, tbb::info::default_concurrency()};
    std::vector<const plugin::TechniqueEntry*> techniques;
    for (const auto* entry : plugin::builtinRegistry().techniques("isosurface"))
        if (options.only.empty() || std::find(options.only.begin(), options.only.end(),
                                              entry->info.name) != options.only.end())
            techniques.push_back(entry);
    if (techniques.size() != (options.only.empty() ? techniques.size() : options.only.size())) {
        std::fprintf(stderr, "--technique: not every name is a registered isosurface technique\n");
        return 2;
    }

    std::printf(
        "| field | threads | technique | triangles | median ms | Mcells/s | / vtk_flying_edges | "
        "/ openvdb_volume_to_mesh |\n|---|---|---|---|---|---|---|---|\n");
    for (const scene::SdfModel& model : {makeSphereModel(), findModel("chamfered_cube")}) {
        const auto evaluated = sdf::evaluateModel(model, sdf::makeModelGrid(model, options.grid));
        const sdf::ExactFunctions exact = sdf::makeExactFunctions(model);
        plugin::IsosurfaceInput input;
        input.field = &evaluated.field;
        input.hermite = &evaluated.hermite;
        input.exactValue = exact.value;
        input.exactGradient = exact.gradient;
        const glm::ivec3 n = evaluated.field.samples;
        const double cells = double(n.x - 1) * double(n.y - 1) * double(n.z - 1);
        for (int threads : threadCounts) {
            std::map<std::string, double> ms;
            std::map<std::string, std::size_t> tris;
            timeTechniques(techniques, input, threads, options.repeats, ms, tris);
            for (const auto* entry : techniques) {
                const std::string& name = entry->info.name;
                auto ratio = [&](const char* baseline) {
                    return ms.count(baseline) ? ms[name] / ms[baseline] : 0.0;
                };
                std::printf("| %s %dx%dx%d | %d | %s | %zu | %.1f | %.1f | %.2f | %.2f |\n",
                            model.name.c_str(), n.x, n.y, n.z, threads, name.c_str(), tris[name],
                            ms[name], cells / (ms[name] * 1e3), ratio("vtk_flying_edges"),
                            ratio("openvdb_volume_to_mesh"));
            }
        }
    }
    std::printf("Ratios are time / baseline time (above 1: slower than the baseline).\n");
    return 0;
}
