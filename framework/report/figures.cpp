// The figures of one group of runs (one family on one scene): time against error with Pareto
// fronts, error against each swept parameter, stacked per-pass times, and an image grid.

#include "report/report_detail.h"

#include "experiment/image_files.h"
#include "plot/charts.h"
#include "plot/image_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

namespace rtlab::report::detail {

std::string makeFileName(std::string s)
{
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-')
            c = '_';
    return s;
}

namespace {

Image<glm::vec3> toGrey(const Image<float>& image)
{
    Image<glm::vec3> out(image.width, image.height);
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        out.pixels[i] = glm::vec3(std::isfinite(image.pixels[i]) ? image.pixels[i] : 0.0f);
    return out;
}

// The crop around the largest absolute error, a sixth of the image wide, inside the image.
plot::PixelRect findWorstRegion(const Image<float>& error)
{
    std::size_t worst = 0;
    float best = -1.0f;
    for (std::size_t i = 0; i < error.pixels.size(); ++i)
        if (std::isfinite(error.pixels[i]) && std::abs(error.pixels[i]) > best) {
            best = std::abs(error.pixels[i]);
            worst = i;
        }
    const int size = std::max(4, std::min(error.width, error.height) / 6);
    const int w = std::min(size, error.width), h = std::min(size, error.height);
    const int cx = int(worst % std::size_t(error.width)),
              cy = int(worst / std::size_t(error.width));
    return {std::clamp(cx - w / 2, 0, error.width - w), std::clamp(cy - h / 2, 0, error.height - h),
            w, h};
}

} // namespace

Figures writeGroupFigures(const Group& group, const std::string& directory,
                          const std::vector<std::string>& techniques)
{
    Figures figures;
    const FamilyColumns& columns = group.columns;
    const std::string plots = directory + "/plots";
    std::filesystem::create_directories(plots);
    const plot::ColorTable colors(techniques);
    const std::string stem = makeFileName(group.key);

    // Runs by technique, in the study's technique order.
    std::map<std::string, std::vector<const RunSummary*>> byTechnique;
    for (const auto& run : group.runs)
        byTechnique[run.technique].push_back(&run);

    // 1. Time against error, one series per technique, its Pareto front drawn and labelled.
    plot::ScatterSpec scatter;
    scatter.title = group.title + ": time against error";
    scatter.xLabel = columns.costLabel;
    scatter.yLabel = columns.errorLabel;
    scatter.colors = colors;
    for (const auto& [technique, runs] : byTechnique) {
        plot::Series s{technique};
        for (const RunSummary* run : runs) {
            s.x.push_back(run->get(columns.cost));
            s.y.push_back(run->get(columns.error));
            s.pointLabels.push_back(describeRun(*run, group.varyingParams));
        }
        scatter.series.push_back(std::move(s));
    }
    const std::string scatterPath = plots + "/time_vs_error_" + stem;
    plot::writeScatter(scatter, scatterPath);
    figures.plots.push_back(scatterPath);
    figures.captions.push_back(
        "Run time against error on " + group.title +
        ". Each technique's Pareto front is the staircase; faded points are dominated.");

    // 1b. The same for each further error column the study has.
    for (const auto& [column, label] : columns.extraErrors) {
        plot::ScatterSpec extra = scatter;
        extra.title = group.title + ": time against " + label.substr(0, label.find(" ("));
        extra.yLabel = label;
        bool any = false;
        std::size_t k = 0;
        for (const auto& [technique, runs] : byTechnique) {
            plot::Series& s = extra.series[k++];
            for (std::size_t i = 0; i < runs.size(); ++i) {
                s.y[i] = runs[i]->get(column);
                any = any || std::isfinite(s.y[i]);
            }
        }
        if (!any)
            continue;
        const std::string path = plots + "/time_vs_" + makeFileName(column) + "_" + stem;
        plot::writeScatter(extra, path);
        figures.plots.push_back(path);
        figures.captions.push_back("Run time against " + label + " on " + group.title +
                                   ", Pareto front per technique.");
    }

    // 1c. Convergence (grid sweeps): error against cell size on log-log axes, and the order p of
    //     error ~ h^p fitted by least squares on the logarithms of the per-cell-size means.
    if (columns.convergence && std::find(group.varyingParams.begin(), group.varyingParams.end(),
                                         "grid") != group.varyingParams.end()) {
        plot::LineSpec line;
        line.title = group.title + ": convergence under grid refinement";
        line.xLabel = "cell size h (world units)";
        line.yLabel = columns.errorLabel;
        line.xScale = plot::AxisScale::Log;
        line.yScale = plot::AxisScale::Log;
        line.colors = colors;
        std::string orders;
        // One line per technique and configuration (the other swept parameters), so that variants
        // that converge at different orders (e.g. linear vs midpoint vertices) are not averaged.
        std::vector<std::string> configParams;
        for (const auto& p : group.varyingParams)
            if (p != "grid")
                configParams.push_back(p);
        for (const auto& [technique, techniqueRuns] : byTechnique) {
            std::map<std::string, std::vector<const RunSummary*>> byConfig;
            for (const RunSummary* run : techniqueRuns)
                byConfig[describeRun(*run, configParams)].push_back(run);
            for (const auto& [config, runs] : byConfig) {
                std::map<double, std::pair<double, int>> byCell;
                for (const RunSummary* run : runs) {
                    const double h = run->get("cell_size"), e = run->get(columns.error);
                    if (h > 0.0 && e > 0.0 && std::isfinite(e)) {
                        byCell[h].first += e;
                        byCell[h].second += 1;
                    }
                }
                if (byCell.size() < 2)
                    continue;
                plot::Series s;
                double sx = 0, sy = 0, sxx = 0, sxy = 0;
                for (const auto& [h, sum] : byCell) {
                    const double e = sum.first / sum.second;
                    s.x.push_back(h);
                    s.y.push_back(e);
                    const double lx = std::log(h), ly = std::log(e);
                    sx += lx;
                    sy += ly;
                    sxx += lx * lx;
                    sxy += lx * ly;
                }
                const double n = double(byCell.size());
                const double order = (n * sxy - sx * sy) / (n * sxx - sx * sx);
                char text[64];
                std::snprintf(text, sizeof text, "%.2f", order);
                const std::string name = technique + (config.empty() ? "" : " " + config);
                s.label = name + " (order " + text + ")";
                orders += (orders.empty() ? "" : ", ") + name + " " + text;
                plot::Color c = line.colors.getColor(technique);
                line.colors.setColor(s.label, c);
                line.series.push_back(std::move(s));
            }
        }
        if (!line.series.empty()) {
            const std::string path = plots + "/convergence_" + stem;
            plot::writeLineChart(line, path);
            figures.plots.push_back(path);
            figures.captions.push_back(
                "Convergence on " + group.title + ": mean " + columns.error +
                " against cell size, log-log; fitted order p of error ~ h^p: " + orders + ".");
        }
    }

    // 1d. Histograms the family declares (e.g. triangle angles): the share of each bin per
    //     technique, summed over the technique's runs at the finest grid of the group.
    for (const plugin::HistogramFigure& histogram : columns.histograms) {
        plot::LineSpec line;
        line.title = group.title + ": " + histogram.title;
        line.xLabel = histogram.xLabel;
        line.yLabel = "share";
        line.xScale = plot::AxisScale::Linear;
        line.yScale = plot::AxisScale::Linear;
        line.colors = colors;
        double finest = 0;
        for (const auto& run : group.runs)
            finest = std::max(finest, run.get("grid"));
        for (const auto& [technique, runs] : byTechnique) {
            std::vector<double> counts;
            for (const RunSummary* run : runs) {
                auto it = run->text.find(histogram.column);
                if (it == run->text.end() || (std::isfinite(finest) && run->get("grid") != finest))
                    continue;
                std::istringstream in(it->second);
                double c;
                for (std::size_t i = 0; in >> c; ++i) {
                    if (counts.size() <= i)
                        counts.resize(i + 1, 0.0);
                    counts[i] += c;
                }
            }
            double total = 0;
            for (double c : counts)
                total += c;
            if (total <= 0)
                continue;
            plot::Series s{technique};
            const double width = histogram.xRange / double(counts.size());
            for (std::size_t i = 0; i < counts.size(); ++i) {
                s.x.push_back((double(i) + 0.5) * width);
                s.y.push_back(counts[i] / total);
            }
            line.series.push_back(std::move(s));
        }
        if (!line.series.empty()) {
            const std::string path = plots + "/" + histogram.name + "_" + stem;
            plot::writeLineChart(line, path);
            figures.plots.push_back(path);
            figures.captions.push_back(
                group.title + ": " + histogram.caption +
                (finest > 0 ? " (grid " + std::to_string(int(finest)) + ")" : ""));
        }
    }

    // 2. Error against each swept numeric parameter: the mean error over the runs with that value.
    for (const auto& param : group.varyingParams) {
        const std::string name = param.rfind("param.", 0) == 0 ? param.substr(6) : param;
        plot::LineSpec line;
        line.title = group.title + ": error against " + name;
        line.xLabel = name == "grid" ? "grid (samples per axis)" : name;
        line.yLabel = columns.errorLabel;
        line.colors = colors;
        for (const auto& [technique, runs] : byTechnique) {
            std::map<double, std::pair<double, int>> byValue;
            for (const RunSummary* run : runs) {
                const double x = run->get(param), y = run->get(columns.error);
                if (std::isfinite(x) && std::isfinite(y)) {
                    byValue[x].first += y;
                    byValue[x].second += 1;
                }
            }
            if (byValue.size() < 2)
                continue;
            plot::Series s{technique};
            for (const auto& [x, sum] : byValue) {
                s.x.push_back(x);
                s.y.push_back(sum.first / sum.second);
            }
            line.series.push_back(std::move(s));
        }
        if (line.series.empty())
            continue; // not numeric, or one value per technique
        const std::string path = plots + "/error_vs_" + makeFileName(name) + "_" + stem;
        plot::writeLineChart(line, path);
        figures.plots.push_back(path);
        figures.captions.push_back("Mean error against " + name + " on " + group.title +
                                   " (averaged over the other swept axes).");
    }

    // 3. Per-pass time of each technique's Pareto-front runs, stacked.
    plot::StackedBarSpec bars;
    bars.title = group.title + ": time per pass of the Pareto-front runs";
    bars.yLabel = columns.passTimeLabel.empty() ? "time (ms, median)" : columns.passTimeLabel;
    bars.passes = columns.passes;
    for (const auto& [technique, runs] : byTechnique) {
        std::vector<double> x, y;
        for (const RunSummary* run : runs) {
            x.push_back(run->get(columns.cost));
            y.push_back(run->get(columns.error));
        }
        for (std::size_t i : plot::findParetoFront(x, y)) {
            const std::string label = describeRun(*runs[i], group.varyingParams);
            bars.bars.push_back(technique + (label.empty() ? "" : "\n" + label));
            std::vector<double> values;
            for (const auto& pass : columns.passes)
                values.push_back(runs[i]->get(pass));
            bars.values.push_back(values);
        }
    }
    if (!bars.bars.empty()) {
        if (bars.bars.size() > 16) {
            bars.bars.resize(16);
            bars.values.resize(16);
        }
        const std::string path = plots + "/pass_times_" + stem;
        plot::writeStackedBars(bars, path);
        figures.plots.push_back(path);
        figures.captions.push_back(
            "Time per pass of the runs on each technique's Pareto front on " + group.title + ".");
    }

    // 4. Images (screen-space families): reference | each technique's lowest-error run, over
    //    their error maps, with crops around the worst error.
    plot::ImageGridSpec grid;
    grid.title = group.title + ": frame 0 of each technique's lowest-error run";
    std::vector<plot::GridCell> images, errors;
    Image<float> firstError;
    for (const auto& [technique, runs] : byTechnique) {
        const RunSummary* best = nullptr;
        for (const RunSummary* run : runs)
            if (!best || run->get(columns.error) < best->get(columns.error))
                best = run;
        const auto& frame0 = best->frames.front();
        if (!frame0.count("image.technique") ||
            !std::filesystem::exists(frame0.at("image.technique")))
            continue;
        if (images.empty()) {
            grid.columnTitles.push_back("reference");
            images.push_back(plot::makeColorCell(
                toGrey(experiment::readExrScalar(frame0.at("image.reference")))));
            // Under the reference: its own noise floor (per-pixel standard error), on the same
            // scale as the techniques' errors.
            std::string stderrPath = frame0.at("image.reference");
            stderrPath.replace(stderrPath.rfind("reference.exr"), 13, "reference_stderr.exr");
            // A family whose reference is exact writes no noise floor: it is zero.
            const Image<float> reference = experiment::readExrScalar(frame0.at("image.reference"));
            errors.push_back(
                plot::makeErrorCell(std::filesystem::exists(stderrPath)
                                        ? experiment::readExrScalar(stderrPath)
                                        : Image<float>(reference.width, reference.height, 0.0f)));
        }
        grid.columnTitles.push_back(technique + " " + describeRun(*best, group.varyingParams));
        images.push_back(
            plot::makeColorCell(toGrey(experiment::readExrScalar(frame0.at("image.technique")))));
        Image<float> error = experiment::readExrScalar(frame0.at("image.error"));
        for (auto& e : error.pixels)
            e = std::abs(e);
        if (firstError.width == 0)
            firstError = error;
        errors.push_back(plot::makeErrorCell(std::move(error)));
    }
    if (images.size() > 1) {
        grid.rows = {images, errors};
        grid.rowTitles = {"image", "|error| (reference: standard error)"};
        grid.crops = {findWorstRegion(firstError)};
        grid.errorLabel = "absolute error (unitless)";
        grid.imageScale = images.front().color.width < 400 ? 2 : 1;
        const std::string path = plots + "/images_" + stem;
        plot::writeImageGrid(grid, path);
        figures.plots.push_back(path);
        figures.captions.push_back(
            "Reference and each technique's lowest-error run on " + group.title +
            " (frame 0), over their absolute error maps; the crop is the region of the "
            "largest error, magnified.");
    }
    Figures lit = writeLitFrameFigures(group, directory, colors);
    figures.plots.insert(figures.plots.end(), lit.plots.begin(), lit.plots.end());
    figures.captions.insert(figures.captions.end(), lit.captions.begin(), lit.captions.end());
    return figures;
}

} // namespace rtlab::report::detail
