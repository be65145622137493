// Notebook 04 (occlusion family): bias against error. A screen-space AO technique can be wrong in
// two ways: noisy (it scatters around the truth) or biased (it sees too little or too much
// occlusion everywhere). The RMSE mixes both; the mean signed error is the bias alone
// (technique - truth: positive = brighter than the truth, it misses occlusion).
//
// This walkthrough reads an occlusion study's results folder (by default the smoke study
// `./rtlab.sh run` writes: GTAO, LSAO, bent-cone SSDO and ray-traced AO on ao_testbed) and makes,
// for each scene:
//   <out>/bias_<scene>.png|pdf   the absolute mean signed error against the RMSE, one colour
//                                per technique; a run on the diagonal is all bias, one near the
//                                x axis all noise
// and prints, per technique, the share of its mean squared error that bias explains
// (bias^2 / RMSE^2, averaged over its runs) as a Markdown table.
//
//   build/notebooks_cpp/04_occlusion_bias [results/smoke] [out folder]

#include "experiment/analysis.h"
#include "plot/charts.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

using namespace rtlab;
using experiment::Row;

int main(int argc, char** argv)
{
    // 1. The results and where the figures go.
    const std::string directory = argc > 1 ? argv[1] : "results/smoke";
    const std::string out = argc > 2 ? argv[2] : directory + "/notebook_04";
    const std::vector<Row> rows = experiment::loadResults(directory);
    if (rows.empty()) {
        std::fprintf(stderr, "%s/results.jsonl has no rows; run the study first (./rtlab.sh run)\n", directory.c_str());
        return 1;
    }
    std::filesystem::create_directories(out);

    // 2. The occlusion runs (and frames): those with both columns, by scene and technique.
    struct Point {
        double rmse, bias;
        std::string run;
    };
    std::map<std::string, std::map<std::string, std::vector<Point>>> byScene;
    for (const auto& row : rows) {
        if (!row.count("status") || row.at("status") != "ok")
            continue;
        const double rmse = experiment::getNumber(row, "ao.rmse");
        const double bias = experiment::getNumber(row, "ao.mean_signed_error");
        if (!std::isfinite(rmse) || !std::isfinite(bias))
            continue;
        const std::string scene = std::filesystem::path(row.count("scene") ? row.at("scene") : "?").stem().string();
        byScene[scene][row.count("technique") ? row.at("technique") : "?"].push_back(
            {rmse, bias, row.count("run_id") ? row.at("run_id") : "?"});
    }
    if (byScene.empty()) {
        std::printf("no occlusion run with ao.rmse and ao.mean_signed_error in %s\n", directory.c_str());
        return 1;
    }

    for (const auto& [scene, techniques] : byScene) {
        // 3. The table: the mean bias, the mean RMSE and the share of the MSE that is bias.
        std::printf("### %s\n\n| technique | runs | mean signed error | RMSE | bias^2 / RMSE^2 | reads as |\n"
                    "|---|---|---|---|---|---|\n",
                    scene.c_str());
        plot::ScatterSpec chart;
        chart.title = scene + ": bias against error";
        chart.xLabel = "RMSE against the ground truth (AO, unitless)";
        chart.yLabel = "absolute mean signed error (AO, unitless)";
        chart.xScale = plot::AxisScale::Linear;
        chart.yScale = plot::AxisScale::Linear;
        chart.drawParetoFronts = false;
        for (const auto& [technique, points] : techniques) {
            double bias = 0, rmse = 0, share = 0;
            plot::Series s{technique};
            for (const Point& p : points) {
                bias += p.bias;
                rmse += p.rmse;
                share += p.rmse > 0.0 ? p.bias * p.bias / (p.rmse * p.rmse) : 0.0;
                s.x.push_back(p.rmse);
                s.y.push_back(std::abs(p.bias));
                s.pointLabels.push_back(p.run);
            }
            const double n = double(points.size());
            bias /= n;
            rmse /= n;
            share /= n;
            // More than half of the MSE from the bias: the technique's error is mostly a shift.
            const char* reads = share > 0.5 ? (bias > 0.0 ? "biased bright (misses occlusion)" : "biased dark (over-occludes)")
                                            : "mostly noise or local error";
            std::printf("| %s | %zu | %+.4f | %.4f | %.2f | %s |\n", technique.c_str(), points.size(), bias, rmse, share,
                        reads);
            chart.series.push_back(std::move(s));
        }
        // 4. The figure, PNG and vector PDF.
        plot::writeScatter(chart, out + "/bias_" + scene);
        std::printf("\nfigure: %s/bias_%s.pdf\n\n", out.c_str(), scene.c_str());
    }
    return 0;
}
