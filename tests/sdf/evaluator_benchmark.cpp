// Throughput of the hierarchical SDF evaluator next to brute force (SdfModel::evaluate at every
// sample) on the CSG gallery models and the Tomorrow Town landscape, at 128 and 256 samples along
// each model's longest side. Values only (no Hermite data, no materials) in both; one extra row
// per size times the hierarchical evaluator with Hermite data on the landscape. Not a ctest test:
//   build/tests/sdf/sdf_evaluator_benchmark [--benchmark_filter=<regex>] [threads]
// Counters: samples_per_s (grid samples per wall-clock second), culling_rate (1 - primitive
// evaluations / brute force's, bound evaluations included), evals (primitive evaluations per run),
// in_band (samples with |d| <= band), ideal_rate (the culling rate of one primitive evaluation per
// band sample and nothing else: no exact evaluator culls more), sample_evals / bound_evals (the
// two parts of evals: at samples, and bounding cells), edges (Hermite edges, where computed),
// emptyN / fullN / visitedN (cells of level N, 0 = coarsest, proven outside / inside the band,
// and visited).

#include "sdf/evaluator.h"

#include "scene/procedural.h"

#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

using namespace rtlab;

namespace {

int gThreads = 0;

void runEvaluator(benchmark::State& state, const scene::SdfModel& model, int resolution, bool brute,
                  bool hermite)
{
    const sdf::GridSpec grid = sdf::makeModelGrid(model, resolution);
    sdf::EvaluationOptions options;
    options.computeHermite = hermite;
    options.threadCount = gThreads;
    sdf::EvaluationStats stats;
    for (auto _ : state) {
        const sdf::EvaluationResult r = brute ? sdf::evaluateModelBruteForce(model, grid, sdf::kAllFrames, options)
                                              : sdf::evaluateModel(model, grid, sdf::kAllFrames, options);
        benchmark::DoNotOptimize(r.field.values.data());
        stats = r.stats;
    }
    state.counters["samples_per_s"] =
        benchmark::Counter(double(stats.samples) * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["culling_rate"] = brute ? 0.0 : stats.getCullingRate();
    state.counters["ideal_rate"] = stats.getIdealCullingRate(); // one evaluation per band sample
    state.counters["evals"] = double(stats.getFieldEvaluations());
    state.counters["in_band"] = double(stats.samplesInBand);
    state.counters["samples"] = double(stats.samples);
    state.counters["sample_evals"] = double(stats.sampleEvaluations);
    state.counters["bound_evals"] = double(stats.boundEvaluations);
    if (hermite)
        state.counters["edges"] = double(stats.hermiteEdges);
    // Cells proven outside (empty) or inside (full) the band, per level (0 = coarsest).
    for (std::size_t l = 0; l < stats.cellsEmpty.size(); ++l) {
        state.counters["empty" + std::to_string(l)] = double(stats.cellsEmpty[l]);
        state.counters["full" + std::to_string(l)] = double(stats.cellsFull[l]);
        state.counters["visited" + std::to_string(l)] = double(stats.cellsVisited[l]);
    }
}

} // namespace

int main(int argc, char** argv)
{
    benchmark::Initialize(&argc, argv);
    if (argc > 1)
        gThreads = std::atoi(argv[1]);
    static std::vector<scene::SdfModel> models = scene::makeCsgGallery().sdfModels;
    for (auto& m : scene::makeTomorrowTown().sdfModels)
        models.push_back(m);
    for (int resolution : {128, 256})
        for (const auto& m : models) {
            for (bool brute : {false, true}) {
                const std::string name = std::string(brute ? "brute_force/" : "hierarchical/") + m.name + "/" +
                                         std::to_string(resolution);
                benchmark::RegisterBenchmark(name.c_str(), [&m, resolution, brute](benchmark::State& s) {
                    runEvaluator(s, m, resolution, brute, false);
                })->Unit(benchmark::kMillisecond)->UseRealTime();
            }
            if (m.name == "landscape") {
                const std::string name = "hierarchical_hermite/" + m.name + "/" + std::to_string(resolution);
                benchmark::RegisterBenchmark(name.c_str(), [&m, resolution](benchmark::State& s) {
                    runEvaluator(s, m, resolution, false, true);
                })->Unit(benchmark::kMillisecond)->UseRealTime();
            }
        }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
