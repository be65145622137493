// Notebook 02: the speed-up at equal error. A real-time technique is worth its approximation only
// if the ground truth's own estimator needs much longer for the same error. For each run of each
// technique this walkthrough finds the cheapest run of a baseline (the family's path tracer or
// ray-traced AO at 1 ... N samples per pixel, on the same scene and chart) whose error is at most
// the run's, and divides the two times. That is the definition of the voxel GI issue's target
// ("the cheapest Embree run reaching the same RMSE must take at least 20x longer"); no
// interpolation between baseline runs, so a coarse sample ladder understates the speed-up.
//
// It makes, for each scene:
//   <out>/speedup_<scene>.png|pdf   speed-up against error, one colour per technique, log scale
// and prints a Markdown table per scene: run, error, time, the baseline run that matches it, its
// time, and the ratio. A run more accurate than every baseline run gets "> ratio to the most
// accurate one" (a lower bound).
//
//   build/notebooks_cpp/02_equal_error_speedup [results/voxel_gi] [out folder] [baseline]
//                                              [cost column] [error column]
// Defaults: the voxel GI study, baseline path_traced, technique_ms, indirect.rmse. For the
// occlusion runs of the smoke study: results/smoke out raytraced_ao technique_ms ao.rmse.

#include "experiment/analysis.h"
#include "plot/charts.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <vector>

using namespace rtlab;
using experiment::Row;

namespace {

//! One run: its technique and the means of the cost and error over its frames (rows).
struct Run {
    std::string id;
    std::string technique;
    double cost = 0.0;
    double error = 0.0;
};

} // namespace

int main(int argc, char** argv)
{
    // 1. Where the results are, where the figures go, which technique is the baseline and which
    //    columns to compare.
    const std::string directory = argc > 1 ? argv[1] : "results/voxel_gi";
    const std::string out = argc > 2 ? argv[2] : directory + "/notebook_02";
    const std::string baseline = argc > 3 ? argv[3] : "path_traced";
    const std::string cost = argc > 4 ? argv[4] : "technique_ms";
    const std::string error = argc > 5 ? argv[5] : "indirect.rmse";

    const std::vector<Row> rows = experiment::loadResults(directory);
    if (rows.empty()) {
        std::fprintf(stderr, "%s/results.jsonl has no rows; run the study first\n", directory.c_str());
        return 1;
    }
    std::filesystem::create_directories(out);

    // 2. Runs per scene: a multi-frame run has one row per frame; its cost and error are the
    //    means over the frames where both are finite.
    std::map<std::string, std::map<std::string, Run>> byScene;
    std::map<std::string, std::map<std::string, int>> frames;
    std::set<std::string> techniques;
    for (const auto& row : rows) {
        if (!row.count("status") || row.at("status") != "ok" || !row.count("run_id"))
            continue;
        const double c = experiment::getNumber(row, cost), e = experiment::getNumber(row, error);
        if (!std::isfinite(c) || !std::isfinite(e))
            continue;
        const std::string scene =
            std::filesystem::path(row.count("scene") ? row.at("scene") : "?").stem().string();
        Run& run = byScene[scene][row.at("run_id")];
        run.id = row.at("run_id");
        run.technique = row.count("technique") ? row.at("technique") : "?";
        run.cost += c;
        run.error += e;
        ++frames[scene][run.id];
        techniques.insert(run.technique);
    }
    const plot::ColorTable colors(std::vector<std::string>(techniques.begin(), techniques.end()));

    for (auto& [scene, runs] : byScene) {
        for (auto& [id, run] : runs) {
            run.cost /= frames[scene][id];
            run.error /= frames[scene][id];
        }
        // 3. The baseline's ladder, most accurate first.
        std::vector<const Run*> ladder;
        for (const auto& [id, run] : runs)
            if (run.technique == baseline)
                ladder.push_back(&run);
        if (ladder.empty()) {
            std::printf("\n### %s: no %s run with %s and %s; skipped\n", scene.c_str(),
                        baseline.c_str(), cost.c_str(), error.c_str());
            continue;
        }
        std::sort(ladder.begin(), ladder.end(),
                  [](const Run* a, const Run* b) { return a->error < b->error; });

        // 4. Per run of the other techniques, the cheapest baseline run at most as wrong.
        std::printf("\n### %s: speed-up at equal %s against the cheapest %s run as accurate\n\n",
                    scene.c_str(), error.c_str(), baseline.c_str());
        std::printf("| run | technique | %s | %s | %s run | its %s | speed-up |\n"
                    "|---|---|---|---|---|---|---|\n",
                    error.c_str(), cost.c_str(), baseline.c_str(), cost.c_str());
        plot::ScatterSpec chart;
        chart.title = scene + ": speed-up over " + baseline + " at equal error";
        chart.xLabel = error;
        chart.yLabel = baseline + " time / technique time at equal error";
        chart.yScale = plot::AxisScale::Log;
        chart.drawParetoFronts = false;
        chart.colors = colors;
        std::map<std::string, plot::Series> series;
        for (const auto& [id, run] : runs) {
            if (run.technique == baseline || !(run.cost > 0.0))
                continue;
            const Run* match = nullptr;
            for (const Run* b : ladder)
                if (b->error <= run.error && (!match || b->cost < match->cost))
                    match = b;
            if (match == nullptr) {
                // More accurate than every baseline run: the most accurate one bounds it below.
                std::printf("| %s | %s | %.4g | %.4g | none as accurate (best %s: %.4g) | > %.4g | > %.3g |\n",
                            id.c_str(), run.technique.c_str(), run.error, run.cost,
                            ladder.front()->id.c_str(), ladder.front()->error, ladder.front()->cost,
                            ladder.front()->cost / run.cost);
                continue;
            }
            const double ratio = match->cost / run.cost;
            std::printf("| %s | %s | %.4g | %.4g | %s (%.4g) | %.4g | %.3g |\n", id.c_str(),
                        run.technique.c_str(), run.error, run.cost, match->id.c_str(), match->error,
                        match->cost, ratio);
            auto& s = series.try_emplace(run.technique, plot::Series{run.technique}).first->second;
            s.x.push_back(run.error);
            s.y.push_back(ratio);
            s.pointLabels.push_back(id);
        }
        for (auto& [technique, s] : series)
            chart.series.push_back(std::move(s));
        if (!chart.series.empty()) {
            plot::writeScatter(chart, out + "/speedup_" + scene);
            std::printf("\nchart: %s/speedup_%s.png\n", out.c_str(), scene.c_str());
        }
    }
    return 0;
}
