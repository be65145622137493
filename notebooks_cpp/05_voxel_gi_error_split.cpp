// Notebook 05 (voxel_gi family): where does a voxel GI technique's error come from? The family's
// `split` metric measures two errors at the same pixels: the technique against its own voxels
// gathered along 256 rays per pixel (split.cone_rmse: what the 16-cone approximation costs) and
// those rays against the Embree ground truth (split.voxel_rmse: what the voxel geometry and the
// light buffers cost, leaking and over-occlusion included). A technique whose cone error is the
// larger loses more to its cones than to its voxels; otherwise the representation dominates and
// finer cones would not help.
//
// This walkthrough reads a voxel_gi study's results folder (a study with `metrics: [split]`, e.g.
// experiments/voxel_gi.yaml writes results/voxel_gi) and makes, for each scene:
//   <out>/split_<scene>.png|pdf   cone error against voxel error, one colour per technique
//   <out>/sky_split_<scene>.png|pdf   the same for the cones' sky, where the study has it (lit
//                                 frames whose sky comes through the cones; e.g.
//                                 experiments/cone_sky_split.yaml), one colour per technique and
//                                 sky_occlusion
// and prints, per technique, the mean of each error and which one dominates, as a Markdown table.
//
//   build/notebooks_cpp/05_voxel_gi_error_split [results/voxel_gi] [out folder]

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
    const std::string directory = argc > 1 ? argv[1] : "results/voxel_gi";
    const std::string out = argc > 2 ? argv[2] : directory + "/notebook_05";
    const std::vector<Row> rows = experiment::loadResults(directory);
    if (rows.empty()) {
        std::fprintf(stderr, "%s/results.jsonl has no rows; run the study first\n", directory.c_str());
        return 1;
    }
    std::filesystem::create_directories(out);

    // The indirect light's split, and, in lit frames whose sky comes through the cones, the same
    // for that sky (split.sky_*: the voxels along rays that see the sky in their own directions,
    // against Embree's direct irradiance without the point lights), per sky_occlusion.
    struct Quantity {
        const char* prefix; // of the split's columns
        const char* name;   // in the titles
        const char* file;   // figure name before the scene
    };
    int written = 0;
    for (const Quantity q : {Quantity{"split.", "indirect", "split_"}, Quantity{"split.sky_", "sky", "sky_split_"}}) {
        // 2. The rows (one per run and frame) with both halves of the split, by scene and technique.
        std::map<std::string, std::map<std::string, std::vector<std::pair<double, double>>>> byScene;
        std::map<std::string, std::map<std::string, std::vector<std::string>>> runIds;
        const std::string prefix = q.prefix;
        for (const auto& row : rows) {
            if (!row.count("status") || row.at("status") != "ok")
                continue;
            const double voxel = experiment::getNumber(row, prefix + "voxel_rmse");
            const double cone = experiment::getNumber(row, prefix + "cone_rmse");
            if (!std::isfinite(voxel) || !std::isfinite(cone))
                continue;
            const std::string scene = std::filesystem::path(row.count("scene") ? row.at("scene") : "?").stem().string();
            std::string technique = row.count("technique") ? row.at("technique") : "?";
            if (prefix == "split.sky_" && row.count("param.voxel_gi.sky_occlusion"))
                technique += " " + row.at("param.voxel_gi.sky_occlusion");
            byScene[scene][technique].emplace_back(voxel, cone);
            runIds[scene][technique].push_back(row.count("run_id") ? row.at("run_id") : "?");
        }
        for (const auto& [scene, techniques] : byScene) {
            // 3. The table: mean errors per technique, and which half dominates.
            std::printf("### %s, %s\n\n| technique | rows | voxel RMSE (representation) | cone RMSE (approximation) | "
                        "dominated by |\n|---|---|---|---|---|\n",
                        scene.c_str(), q.name);
            plot::ScatterSpec chart;
            chart.title = scene + ": where the " + q.name + " error comes from";
            chart.xLabel = "voxels against the ground truth: " + prefix + "voxel_rmse (" + q.name + " irradiance)";
            chart.yLabel = "cones against the voxels: " + prefix + "cone_rmse (" + q.name + " irradiance)";
            chart.drawParetoFronts = false;
            for (const auto& [technique, points] : techniques) {
                double voxel = 0, cone = 0;
                plot::Series s{technique};
                for (std::size_t i = 0; i < points.size(); ++i) {
                    voxel += points[i].first;
                    cone += points[i].second;
                    s.x.push_back(points[i].first);
                    s.y.push_back(points[i].second);
                    s.pointLabels.push_back(runIds[scene][technique][i]);
                }
                voxel /= double(points.size());
                cone /= double(points.size());
                std::printf("| %s | %zu | %.4g | %.4g | %s |\n", technique.c_str(), points.size(), voxel, cone,
                            cone > voxel ? "the cones" : "the voxels");
                chart.series.push_back(std::move(s));
            }
            // 4. The figure, PNG and vector PDF.
            plot::writeScatter(chart, out + "/" + q.file + scene);
            std::printf("\nfigure: %s/%s%s.pdf\n\n", out.c_str(), q.file, scene.c_str());
            ++written;
        }
    }
    if (written == 0) {
        std::printf("no run with split.voxel_rmse and split.cone_rmse in %s (add `metrics: [split]`)\n",
                    directory.c_str());
        return 1;
    }
    return 0;
}
