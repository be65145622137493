// What a dig costs the render mesher: Tomorrow Town's landscape meshed in full at a dig's frame
// (what every dig frame did before SdfMesher::update) next to the incremental update from the
// frame before (the dig's cells only), for each of the town's three digs (frames 2, 4 and 6), at
// the town's own resolution (128 cells along the longest side) and at 256.
//   build/tests/scene/sdf_remesh_benchmark [--benchmark_filter=<regex>]
// Counters: cells_meshed (cells whose vertex was computed again; the full rows mesh every cell),
// cells (the grid's cells), triangles. --quick, last (the ctest): every row once at 48 cells.

#include "scene/procedural.h"
#include "scene/sdf_mesher.h"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <memory>
#include <string>

using namespace rtlab;

namespace {

void runFull(benchmark::State& state, const scene::SdfModel& model, int resolution, int frame)
{
    std::size_t triangles = 0;
    for (auto _ : state) {
        const scene::SdfMesh mesh = scene::meshSdfModel(model, {.resolution = resolution, .frame = frame});
        triangles = mesh.triangleMaterial.size();
        benchmark::DoNotOptimize(triangles);
    }
    scene::SdfMesher probe(model, {.resolution = resolution});
    const scene::SdfMeshChange change = probe.update(frame);
    state.counters["cells_meshed"] = double(change.cellsMeshed);
    state.counters["cells"] = double(change.cellCount);
    state.counters["triangles"] = double(triangles);
}

void runIncremental(benchmark::State& state, const scene::SdfModel& model, int resolution, int frame)
{
    scene::SdfMeshChange change;
    for (auto _ : state) {
        // Built and dropped outside the timed part: a frame keeps its mesher.
        state.PauseTiming();
        auto mesher = std::make_unique<scene::SdfMesher>(model, scene::SdfMeshOptions{.resolution = resolution});
        mesher->update(frame - 1);
        state.ResumeTiming();
        change = mesher->update(frame);
        benchmark::DoNotOptimize(change.cellsMeshed);
        state.PauseTiming();
        mesher.reset();
        state.ResumeTiming();
        if (change.full)
            state.SkipWithError(("meshed in full: " + change.what).c_str());
    }
    state.counters["cells_meshed"] = double(change.cellsMeshed);
    state.counters["cells"] = double(change.cellCount);
}

} // namespace

int main(int argc, char** argv)
{
    // --quick, last on the command line: the ctest run.
    const bool quick = argc > 1 && std::string(argv[argc - 1]) == "--quick";
    if (quick)
        --argc;
    benchmark::Initialize(&argc, argv);
    static const scene::Scene town = scene::makeTomorrowTown();
    const scene::SdfModel& land = town.sdfModels.front();
    const std::vector<int> resolutions = quick ? std::vector<int>{48} : std::vector<int>{128, 256};
    for (const int resolution : resolutions)
        for (const int frame : {2, 4, 6})
            for (const bool incremental : {false, true}) {
                const std::string name = std::string(incremental ? "incremental/" : "full/") +
                                         land.name + "/" + std::to_string(resolution) + "/dig_frame_" +
                                         std::to_string(frame);
                benchmark::internal::Benchmark* b = benchmark::RegisterBenchmark(
                    name.c_str(), [&land, resolution, frame, incremental](benchmark::State& s) {
                        if (incremental)
                            runIncremental(s, land, resolution, frame);
                        else
                            runFull(s, land, resolution, frame);
                    });
                b->Unit(benchmark::kMillisecond)->UseRealTime();
                if (quick)
                    b->Iterations(1);
            }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
