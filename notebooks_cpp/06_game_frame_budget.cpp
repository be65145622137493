// Notebook 06 (the game frame): where a lit frame's time goes, pass by pass, for each technique
// in the frame's slots, beside the error of the final frame. A paper's "frame budget" figure.
//
// This walkthrough reads a game-frame study's results folder (experiments/game_frame.yaml writes
// results/game_frame: tomorrow_town's 8 frames with each occlusion technique) and makes:
//   <out>/budget.png|pdf   one stacked bar per run: the mean over its frames of each pass that
//                          makes the frame (its GPU time where it ran GPU work, else its CPU time)
// and prints a Markdown table: frame time, final-frame RMSE against Embree `full`, and the most
// expensive pass of each run.
//
//   build/notebooks_cpp/06_game_frame_budget [results/game_frame] [out folder]

#include "experiment/analysis.h"
#include "plot/charts.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

using namespace rtlab;
using experiment::Row;

int main(int argc, char** argv)
{
    // 1. The results and where the figure goes.
    const std::string directory = argc > 1 ? argv[1] : "results/game_frame";
    const std::string out = argc > 2 ? argv[2] : directory + "/notebook_06";
    const std::vector<Row> rows = experiment::loadResults(directory);
    if (rows.empty()) {
        std::fprintf(stderr, "%s/results.jsonl has no rows; run the study first\n", directory.c_str());
        return 1;
    }
    std::filesystem::create_directories(out);

    // 2. Per run: the mean time of every frame pass over its frames (`frame_passes` names the
    //    passes that make the frame; measurement passes such as ground truths are not in it), the
    //    mean frame time and the mean final-frame error.
    struct RunBudget {
        std::string technique;
        std::map<std::string, double> passMs;
        double frameMs = 0.0, rmse = 0.0;
        int frames = 0;
    };
    std::map<std::string, RunBudget> runs; // by run id, in id order
    std::vector<std::string> passOrder;
    for (const auto& row : rows) {
        if (!row.count("status") || row.at("status") != "ok" || !row.count("frame_passes"))
            continue;
        RunBudget& run = runs[row.at("run_id")];
        run.technique = row.count("technique") ? row.at("technique") : "?";
        std::istringstream passes(row.at("frame_passes"));
        for (std::string pass; std::getline(passes, pass, ';');) {
            if (pass.empty())
                continue;
            double ms = experiment::getNumber(row, pass + ".gpu_ms");
            if (!std::isfinite(ms))
                ms = experiment::getNumber(row, pass + ".cpu_ms");
            if (!std::isfinite(ms))
                continue; // skipped in this frame (culled): it costs nothing
            run.passMs[pass] += ms;
            if (std::find(passOrder.begin(), passOrder.end(), pass) == passOrder.end())
                passOrder.push_back(pass);
        }
        const double frameGpu = experiment::getNumber(row, "frame.gpu_ms");
        run.frameMs += frameGpu > 0.0 ? frameGpu : experiment::getNumber(row, "frame.cpu_ms");
        run.rmse += experiment::getNumber(row, "frame.rmse");
        ++run.frames;
    }
    if (runs.empty()) {
        std::printf("no lit-frame run (a frame_passes column) in %s\n", directory.c_str());
        return 1;
    }

    // 3. The table and the bars.
    plot::StackedBarSpec bars;
    bars.title = "frame budget: time of each pass per frame (mean over the frames)";
    bars.xLabel = "run";
    bars.yLabel = "time per frame (ms; GPU where the pass ran GPU work)";
    bars.passes = passOrder;
    std::printf("| run | technique | frames | frame time (ms) | frame RMSE | most expensive pass |\n"
                "|---|---|---|---|---|---|\n");
    for (auto& [id, run] : runs) {
        std::vector<double> values;
        std::string top;
        double topMs = -1.0;
        for (const std::string& pass : passOrder) {
            const double ms = run.passMs.count(pass) ? run.passMs.at(pass) / run.frames : 0.0;
            values.push_back(ms);
            if (ms > topMs) {
                topMs = ms;
                top = pass;
            }
        }
        std::printf("| %s | %s | %d | %.3g | %.4g | %s (%.3g ms) |\n", id.c_str(), run.technique.c_str(), run.frames,
                    run.frameMs / run.frames, run.rmse / run.frames, top.c_str(), topMs);
        bars.bars.push_back(run.technique + " (" + id + ")");
        bars.values.push_back(std::move(values));
    }
    // 4. The figure, PNG and vector PDF.
    plot::writeStackedBars(bars, out + "/budget");
    std::printf("\nfigure: %s/budget.pdf\n", out.c_str());
    return 0;
}
