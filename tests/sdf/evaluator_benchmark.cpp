// Throughput of the hierarchical SDF evaluator next to brute force (SdfModel::evaluate at every
// sample) on the CSG gallery models, the Tomorrow Town landscape and a many-edit model built from
// it (rock_field: the landscape with 96 more edits), at 128 and 256 samples along each model's
// longest side. Values only (no Hermite data, no materials) in both; extra rows per size time the
// hierarchical evaluator with Hermite data on the landscape, and with
// EvaluationOptions::ellipsoidGradientBound (hierarchical_gradient_bound) on the landscape and the
// rock field. --quick: the ctest run (see main):
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
#include <glm/gtc/quaternion.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

using namespace rtlab;

namespace {

int gThreads = 0;

//! The landscape with 72 soft-blended ellipsoid rocks (aspect up to 3, some rotated) and 24
//! spherical digs, placed by a fixed linear congruential sequence: a many-edit model, where a
//! leaf's list is long and each sample it does not evaluate saves several primitives.
scene::SdfModel makeRockField(const scene::SdfModel& landscape)
{
    scene::SdfModel m = landscape;
    m.name = "rock_field";
    std::uint64_t state = 12345;
    const auto next = [&state] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return double(state >> 11) * 0x1.0p-53;
    };
    for (int i = 0; i < 96; ++i) {
        scene::CsgEdit e;
        const bool rock = i % 4 != 3;
        e.shape = rock ? scene::CsgShape::Ellipsoid : scene::CsgShape::Sphere;
        e.op = rock ? scene::CsgOp::Add : scene::CsgOp::Subtract;
        e.center = {-14.0 + 28.0 * next(), rock ? -0.2 + 1.0 * next() : 0.3 * next(),
                    -14.0 + 28.0 * next()};
        const double r = rock ? 0.4 + 0.9 * next() : 0.5 + 0.7 * next();
        e.size = rock ? glm::dvec3(r, r * (0.35 + 0.65 * next()), r * (0.5 + 0.5 * next()))
                      : glm::dvec3(r, 0.0, 0.0);
        e.blend = rock ? 0.3 : 0.15;
        if (rock && i % 3 == 0)
            e.rotation = glm::angleAxis(6.283185307179586 * next(), glm::dvec3(0.0, 1.0, 0.0));
        m.edits.push_back(e);
    }
    return m;
}

void runEvaluator(benchmark::State& state, const scene::SdfModel& model, int resolution, bool brute,
                  bool hermite, bool gradientBound = false)
{
    const sdf::GridSpec grid = sdf::makeModelGrid(model, resolution);
    sdf::EvaluationOptions options;
    options.computeHermite = hermite;
    options.ellipsoidGradientBound = gradientBound;
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
    // --quick: every row once at 48 samples, then each model's field checked bit for bit against
    // brute force (exit 1 otherwise), with and without the ellipsoid gradient bound: the ctest
    // that keeps this program from rotting.
    bool quick = false;
    for (int i = 1; i < argc; ++i)
        if (std::string(argv[i]) == "--quick") {
            quick = true;
            for (int j = i; j + 1 < argc; ++j)
                argv[j] = argv[j + 1];
            --argc;
            break;
        }
    benchmark::Initialize(&argc, argv);
    if (argc > 1)
        gThreads = std::atoi(argv[1]);
    static std::vector<scene::SdfModel> models = scene::makeCsgGallery().sdfModels;
    for (auto& m : scene::makeTomorrowTown().sdfModels)
        models.push_back(m);
    models.push_back(makeRockField(models.back()));
    const std::vector<int> resolutions = quick ? std::vector<int>{48} : std::vector<int>{128, 256};
    const auto add = [quick](const std::string& name, auto run) {
        benchmark::internal::Benchmark* b = benchmark::RegisterBenchmark(name.c_str(), run);
        b->Unit(benchmark::kMillisecond)->UseRealTime();
        if (quick)
            b->Iterations(1);
    };
    for (int resolution : resolutions)
        for (const auto& m : models) {
            for (bool brute : {false, true}) {
                const std::string name = std::string(brute ? "brute_force/" : "hierarchical/") + m.name + "/" +
                                         std::to_string(resolution);
                add(name, [&m, resolution, brute](benchmark::State& s) {
                    runEvaluator(s, m, resolution, brute, false);
                });
            }
            if (m.name == "landscape" || m.name == "rock_field")
                add("hierarchical_gradient_bound/" + m.name + "/" + std::to_string(resolution),
                    [&m, resolution](benchmark::State& s) {
                        runEvaluator(s, m, resolution, false, false, true);
                    });
            if (m.name == "landscape")
                add("hierarchical_hermite/" + m.name + "/" + std::to_string(resolution),
                    [&m, resolution](benchmark::State& s) {
                        runEvaluator(s, m, resolution, false, true);
                    });
        }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    if (!quick)
        return 0;
    int failures = 0;
    for (const auto& m : models) {
        const sdf::GridSpec grid = sdf::makeModelGrid(m, 48);
        sdf::EvaluationOptions o;
        o.computeHermite = false;
        const sdf::EvaluationResult brute =
            sdf::evaluateModelBruteForce(m, grid, sdf::kAllFrames, o);
        for (bool gradientBound : {false, true}) {
            o.ellipsoidGradientBound = gradientBound;
            const sdf::EvaluationResult r = sdf::evaluateModel(m, grid, sdf::kAllFrames, o);
            const bool same = r.field.values.size() == brute.field.values.size() &&
                              std::memcmp(r.field.values.data(), brute.field.values.data(),
                                          r.field.values.size() * sizeof(float)) == 0;
            const double rate = r.stats.getCullingRate();
            if (!same || !(rate > 0.0 && rate <= r.stats.getIdealCullingRate())) {
                std::fprintf(stderr, "%s (gradient bound %d): %s, culling rate %g, ideal %g\n",
                             m.name.c_str(), int(gradientBound),
                             same ? "same field" : "FIELD DIFFERS FROM BRUTE FORCE", rate,
                             r.stats.getIdealCullingRate());
                ++failures;
            }
        }
    }
    std::printf("quick check: %zu models, %d failures\n", models.size(), failures);
    return failures == 0 ? 0 : 1;
}
