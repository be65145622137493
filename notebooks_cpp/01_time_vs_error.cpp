// Notebook 01: the figure a paper on real-time techniques prints first: time against error, with
// each technique's Pareto front, and beside it the images that show what the error looks like.
//
// This walkthrough reads a study's results folder (by default the smoke study `./rtlab.sh run`
// writes) through the framework's public API and makes, for each scene:
//   <out>/pareto_<scene>.png|pdf   run time against error, one colour per technique, fronts drawn
//   <out>/strip_<scene>.png|pdf    reference | each technique's best run, error maps below, with a
//                                  zoomed crop (for studies whose runs wrote images)
// and prints the front runs as a Markdown table for the paper's appendix.
//
//   build/notebooks_cpp/01_time_vs_error [results/smoke] [out folder] [cost column] [error column]
//
// Nothing here knows which techniques exist; the columns come from the command line or the
// defaults of the smoke study.

#include "experiment/analysis.h"
#include "experiment/image_files.h"
#include "plot/charts.h"
#include "plot/image_grid.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>

using namespace rtlab;
using experiment::Row;

int main(int argc, char** argv)
{
    // 1. Where the results are, where the figures go, and which columns to trade off. The
    //    defaults are the smoke study's: median CPU time of the technique's pass, and RMS
    //    distance to the true surface.
    const std::string directory = argc > 1 ? argv[1] : "results/smoke";
    const std::string out = argc > 2 ? argv[2] : directory + "/notebook_01";
    const std::string cost = argc > 3 ? argv[3] : "extract.cpu_ms";
    const std::string error = argc > 4 ? argv[4] : "rms_deviation";

    // 2. Read the tidy table: one row per run (and frame), every column as text.
    const std::vector<Row> rows = experiment::loadResults(directory);
    if (rows.empty()) {
        std::fprintf(stderr, "%s/results.jsonl has no rows; run the study first (./rtlab.sh run)\n",
                     directory.c_str());
        return 1;
    }
    std::filesystem::create_directories(out);

    // 3. Group the successful runs by scene: a front across scenes would compare a sphere with a
    //    box. Colours are fixed per technique for the whole study (sorted names -> palette).
    std::map<std::string, std::vector<Row>> byScene;
    std::set<std::string> techniques;
    for (const auto& row : rows)
        if (row.count("status") && row.at("status") == "ok") {
            byScene[std::filesystem::path(row.count("scene") ? row.at("scene") : "?").stem().string()].push_back(row);
            techniques.insert(row.count("technique") ? row.at("technique") : "?");
        }
    const plot::ColorTable colors(std::vector<std::string>(techniques.begin(), techniques.end()));

    for (const auto& [scene, sceneRows] : byScene) {
        // A scene of another family's study (the smoke study also holds AO runs, whose columns
        // are ao.*) has no run with both columns: say so rather than draw an empty chart.
        bool any = false;
        for (const auto& r : sceneRows)
            any = any || (std::isfinite(experiment::getNumber(r, cost)) &&
                          std::isfinite(experiment::getNumber(r, error)));
        if (!any) {
            std::printf("\n### %s: no run has both %s and %s; skipped\n", scene.c_str(), cost.c_str(),
                        error.c_str());
            continue;
        }
        // 4. The Pareto plot: one series per technique; every other run is dominated by a front
        //    run that is at least as fast and at least as accurate.
        plot::ScatterSpec scatter;
        scatter.title = scene + ": time against error";
        scatter.xLabel = cost + " (ms)";
        scatter.yLabel = error;
        scatter.colors = colors;
        std::map<std::string, std::vector<const Row*>> byTechnique;
        for (const auto& r : sceneRows)
            byTechnique[r.count("technique") ? r.at("technique") : "?"].push_back(&r);
        for (const auto& [technique, runs] : byTechnique) {
            plot::Series s{technique};
            for (const Row* r : runs) {
                s.x.push_back(experiment::getNumber(*r, cost));
                s.y.push_back(experiment::getNumber(*r, error));
                s.pointLabels.push_back(r->at("run_id"));
            }
            scatter.series.push_back(std::move(s));
        }
        plot::writeScatter(scatter, out + "/pareto_" + scene);

        // 5. The front as a table, cheapest first.
        const auto front = experiment::findParetoFront(sceneRows, cost, error);
        std::printf("\n### %s: %zu of %zu runs on the front\n\n", scene.c_str(), front.size(), sceneRows.size());
        std::printf("| run | technique | %s | %s |\n|---|---|---|---|\n", cost.c_str(), error.c_str());
        for (std::size_t i : front) {
            const Row& r = sceneRows[i];
            std::printf("| %s | %s | %.4g | %.4g |\n", r.at("run_id").c_str(),
                        r.count("technique") ? r.at("technique").c_str() : "?", experiment::getNumber(r, cost),
                        experiment::getNumber(r, error));
        }

        // 6. The image strip: the reference, then each technique's lowest-error run, with their
        //    error maps below and a crop magnified 4x. Only runs that wrote images take part.
        plot::ImageGridSpec strip;
        strip.title = scene + ": reference and each technique's most accurate run";
        std::vector<plot::GridCell> top, bottom;
        auto grey = [](const Image<float>& a) {
            Image<glm::vec3> c(a.width, a.height);
            for (std::size_t i = 0; i < a.pixels.size(); ++i)
                c.pixels[i] = glm::vec3(a.pixels[i]);
            return c;
        };
        for (const auto& [technique, runs] : byTechnique) {
            const Row* best = nullptr;
            for (const Row* r : runs)
                if (r->count("image.technique") &&
                    (!best || experiment::getNumber(*r, error) < experiment::getNumber(*best, error)))
                    best = r;
            if (!best)
                continue;
            if (top.empty()) {
                strip.columnTitles.push_back("reference");
                top.push_back(plot::makeColorCell(grey(experiment::readExrScalar(best->at("image.reference")))));
                bottom.push_back(plot::makeErrorCell(Image<float>(top.back().color.width, top.back().color.height, 0.0f)));
            }
            strip.columnTitles.push_back(technique);
            top.push_back(plot::makeColorCell(grey(experiment::readExrScalar(best->at("image.technique")))));
            Image<float> e = experiment::readExrScalar(best->at("image.error"));
            for (auto& v : e.pixels)
                v = std::abs(v);
            bottom.push_back(plot::makeErrorCell(std::move(e)));
        }
        if (top.size() > 1) {
            const int w = top.front().color.width, h = top.front().color.height;
            strip.rows = {top, bottom};
            strip.crops = {{w / 3, h / 3, std::max(2, w / 6), std::max(2, h / 6)}};
            strip.cropZoom = 4;
            plot::writeImageGrid(strip, out + "/strip_" + scene);
            std::printf("\nimage strip: %s/strip_%s.png\n", out.c_str(), scene.c_str());
        }
    }
    return 0;
}
