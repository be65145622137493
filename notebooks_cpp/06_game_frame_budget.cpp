// Notebook 06 (the game frame): where a lit frame's time goes, pass by pass, for each technique
// in the frame's slots, beside the error of the final frame. A paper's "frame budget" figure.
//
// This walkthrough reads a game-frame study's results folder (experiments/game_frame.yaml writes
// results/game_frame: tomorrow_town's 8 frames with each occlusion technique) and makes:
//   <out>/budget.png|pdf   one stacked bar per run: the mean over its frames of each pass that
//                          makes the frame (its GPU time where it ran GPU work, else its CPU time)
// and prints a Markdown table: the frame's wall time, the sum of its passes (the bar), the
// final-frame RMSE against Embree `full`, and the most expensive pass of each run. Bars are named
// by technique and the frame settings in which the runs differ (frame.culling here).
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
        std::map<std::string, std::string> settings; //!< the run's frame.* and param.* values
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
        // The settings a frame study sweeps: the frame's own and the technique's parameters.
        for (const char* key : {"frame.culling", "frame.indirect", "frame.gbuffer_on_gpu",
                                "frame.shadow_map_size", "frame.lighting", "frame.tonemapper"})
            if (row.count(key))
                run.settings[key] = row.at(key);
        for (const auto& [key, value] : row)
            if (key.rfind("param.", 0) == 0 && !value.empty())
                run.settings[key] = value;
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
        run.frameMs += experiment::getNumber(row, "frame.cpu_ms"); // the frame's wall time
        run.rmse += experiment::getNumber(row, "frame.rmse");
        ++run.frames;
    }
    if (runs.empty()) {
        std::printf("no lit-frame run (a frame_passes column) in %s\n", directory.c_str());
        return 1;
    }

    // 3. The table and the bars. A bar is named by its technique and the settings in which the
    //    runs differ (e.g. frame.culling); names too long to fit under the bars become numbers
    //    with a key.
    // (A parameter counts where it differs between runs of the same technique.)
    std::vector<std::string> varying;
    for (const auto& [id, run] : runs)
        for (const auto& [key, value] : run.settings)
            for (const auto& [otherId, other] : runs) {
                const bool comparable =
                    key.rfind("param.", 0) != 0 || other.technique == run.technique;
                if (comparable && other.settings.count(key) && other.settings.at(key) != value &&
                    std::find(varying.begin(), varying.end(), key) == varying.end())
                    varying.push_back(key);
            }
    plot::StackedBarSpec bars;
    bars.title = "frame budget: time of each pass per frame (mean over the frames)";
    bars.xLabel = "run";
    bars.yLabel = "time per frame (ms; GPU where the pass ran GPU work)";
    bars.passes = passOrder;
    std::printf(
        "| run | technique | frames | frame wall time (ms) | sum of its passes (ms) | frame RMSE "
        "| most expensive pass |\n|---|---|---|---|---|---|---|\n");
    for (auto& [id, run] : runs) {
        std::vector<double> values;
        std::string top;
        double topMs = -1.0, sumMs = 0.0;
        for (const std::string& pass : passOrder) {
            const double ms = run.passMs.count(pass) ? run.passMs.at(pass) / run.frames : 0.0;
            values.push_back(ms);
            sumMs += ms;
            if (ms > topMs) {
                topMs = ms;
                top = pass;
            }
        }
        std::printf("| %s | %s | %d | %.3g | %.3g | %.4g | %s (%.3g ms) |\n", id.c_str(),
                    run.technique.c_str(), run.frames, run.frameMs / run.frames, sumMs,
                    run.rmse / run.frames, top.c_str(), topMs);
        std::string label = run.technique;
        for (const std::string& key : varying)
            if (run.settings.count(key))
                label += "\n" + key.substr(key.find('.') + 1) + "=" + run.settings.at(key);
        bars.bars.push_back(label);
        bars.values.push_back(std::move(values));
    }
    if (!plot::barLabelsFit(bars)) {
        std::printf("\nbars:");
        for (std::size_t b = 0; b < bars.bars.size(); ++b) {
            std::string label = bars.bars[b];
            std::replace(label.begin(), label.end(), '\n', ' ');
            std::printf("%s %zu = %s", b == 0 ? "" : ";", b + 1, label.c_str());
            bars.bars[b] = std::to_string(b + 1);
        }
        std::printf("\n");
    }
    // 4. The figure, PNG and vector PDF.
    plot::writeStackedBars(bars, out + "/budget");
    std::printf("\nfigure: %s/budget.pdf\n", out.c_str());
    return 0;
}
