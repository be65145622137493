// Notebook 03 (isosurface family): the convergence figure a meshing paper prints. How fast does
// each mesher's distance to the exact surface shrink as the grid is refined?
//
// This walkthrough reads an isosurface study's results folder (by default the smoke study
// `./rtlab.sh run` writes, whose sphere and box are meshed at 32, 64 and 128 samples) and makes,
// for each scene:
//   <out>/convergence_<scene>.png|pdf   error against cell size on log-log axes, one line per
//                                       technique configuration, its fitted order in the legend
// and prints the orders as a Markdown table: error ~ C h^p, p fitted by least squares on
// (log h, log error) over the grid sweep. Marching cubes' Chamfer distance is O(h^2) on smooth
// shapes (linear interpolation along edges); midpoint vertices give O(h).
//
//   build/notebooks_cpp/03_isosurface_convergence [results/smoke] [out folder] [error column]

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
    // 1. Where the results are, where the figure goes, which error to plot. The default is the
    //    mean two-sided distance to the exact surface.
    const std::string directory = argc > 1 ? argv[1] : "results/smoke";
    const std::string out = argc > 2 ? argv[2] : directory + "/notebook_03";
    const std::string error = argc > 3 ? argv[3] : "chamfer.mean";

    const std::vector<Row> rows = experiment::loadResults(directory);
    if (rows.empty()) {
        std::fprintf(stderr, "%s/results.jsonl has no rows; run the study first (./rtlab.sh run)\n", directory.c_str());
        return 1;
    }
    std::filesystem::create_directories(out);

    // 2. The isosurface runs: those with a cell size and the error. A configuration is the
    //    technique with its parameters (marching cubes with linear and with midpoint vertices
    //    converge at different orders, so they are never pooled).
    std::map<std::string, std::map<std::string, std::vector<std::pair<double, double>>>> byScene;
    for (const auto& row : rows) {
        if (!row.count("status") || row.at("status") != "ok")
            continue;
        const double h = experiment::getNumber(row, "cell_size");
        const double e = experiment::getNumber(row, error);
        if (!(h > 0.0) || !(e > 0.0))
            continue;
        std::string configuration = row.count("technique") ? row.at("technique") : "?";
        for (const auto& [column, value] : row)
            if (column.rfind("param.vertex_placement", 0) == 0 && value != "linear")
                configuration += " " + column.substr(6) + "=" + value;
        const std::string scene = std::filesystem::path(row.count("scene") ? row.at("scene") : "?").stem().string();
        byScene[scene][configuration].emplace_back(h, e);
    }
    if (byScene.empty()) {
        std::printf("no isosurface run with cell_size and %s in %s\n", error.c_str(), directory.c_str());
        return 1;
    }

    for (const auto& [scene, configurations] : byScene) {
        std::printf("| scene | configuration | grids | fitted order p (error ~ h^p) |\n|---|---|---|---|\n");
        // 3. Per configuration: the least-squares slope of log error on log h.
        plot::LineSpec chart;
        chart.title = scene + ": " + error + " against cell size";
        chart.xLabel = "cell size h (world units)";
        chart.yLabel = error + " (world units)";
        chart.xScale = plot::AxisScale::Log;
        chart.yScale = plot::AxisScale::Log;
        for (const auto& [configuration, points] : configurations) {
            double sx = 0, sy = 0, sxx = 0, sxy = 0;
            const double n = double(points.size());
            for (const auto& [h, e] : points) {
                sx += std::log(h);
                sy += std::log(e);
                sxx += std::log(h) * std::log(h);
                sxy += std::log(h) * std::log(e);
            }
            const double order = points.size() >= 2 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : NAN;
            char label[64];
            std::snprintf(label, sizeof label, "%.2f", order);
            std::printf("| %s | %s | %zu | %s |\n", scene.c_str(), configuration.c_str(), points.size(),
                        points.size() >= 2 ? label : "one grid: none");
            plot::Series s{configuration + (points.size() >= 2 ? " (p = " + std::string(label) + ")" : "")};
            for (const auto& [h, e] : points) {
                s.x.push_back(h);
                s.y.push_back(e);
            }
            chart.series.push_back(std::move(s));
        }
        // 4. The figure, PNG and vector PDF.
        plot::writeLineChart(chart, out + "/convergence_" + scene);
        std::printf("\nfigure: %s/convergence_%s.pdf\n\n", out.c_str(), scene.c_str());
        // A configuration whose error does not fall (p near 0) has reached its floor: dual
        // contouring reproduces a box's faces and edges exactly at every grid.
    }
    return 0;
}
