// Notebook 01: time against error, from a study's results table.
//
// A paper comparing techniques shows which settings are worth their cost. This walkthrough reads
// the results of a study (by default the smoke study that `./rtlab.sh run` writes), and for each
// scene prints the runs on the Pareto front of extraction time against RMS distance to the true
// surface, as a Markdown table ready for a paper's appendix.
//
//   build/notebooks_cpp/01_time_vs_error [results/smoke] [cost column] [error column]
//
// Everything it uses is the framework's public API: experiment/analysis.h reads the table and
// finds the front; nothing here knows which techniques exist.

#include "experiment/analysis.h"

#include <cstdio>
#include <map>
#include <string>

using namespace rtlab::experiment;

int main(int argc, char** argv)
{
    // 1. Where the results are, and which columns to trade off. The defaults are the smoke
    //    study's: median CPU time of the technique's pass, and RMS distance to the surface.
    const std::string directory = argc > 1 ? argv[1] : "results/smoke";
    const std::string cost = argc > 2 ? argv[2] : "extract.cpu_ms";
    const std::string error = argc > 3 ? argv[3] : "rms_deviation";

    // 2. Read the tidy table: one row per run, every column as text.
    const std::vector<Row> rows = loadResults(directory);
    if (rows.empty()) {
        std::fprintf(stderr, "%s/results.jsonl has no rows; run the study first (./rtlab.sh run)\n",
                     directory.c_str());
        return 1;
    }

    // 3. Group by scene: a front across scenes would compare a sphere with a box.
    std::map<std::string, std::vector<Row>> byScene;
    for (const auto& row : rows)
        if (row.count("status") && row.at("status") == "ok")
            byScene[row.count("scene") ? row.at("scene") : "?"].push_back(row);

    // 4. For each scene, the Pareto front, cheapest first. Every other run is dominated: some
    //    front run is at least as fast and at least as accurate.
    for (const auto& [scene, sceneRows] : byScene) {
        const auto front = findParetoFront(sceneRows, cost, error);
        std::printf("\n### %s: %zu of %zu runs on the front\n\n", scene.c_str(), front.size(),
                    sceneRows.size());
        std::printf("| run | technique | %s | %s |\n|---|---|---|---|\n", cost.c_str(), error.c_str());
        for (std::size_t i : front) {
            const Row& r = sceneRows[i];
            std::printf("| %s | %s | %.4g | %.4g |\n", r.at("run_id").c_str(),
                        r.count("technique") ? r.at("technique").c_str() : "?", getNumber(r, cost),
                        getNumber(r, error));
        }
    }
    return 0;
}
