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

Image<glm::vec3> toGrey(const Image<float>& image, float scale = 1.0f)
{
    Image<glm::vec3> out(image.width, image.height);
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        out.pixels[i] = glm::vec3(std::isfinite(image.pixels[i]) ? scale * image.pixels[i] : 0.0f);
    return out;
}

std::string formatScale(float v)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", double(v));
    return text;
}

// 1 for images in [0, 1] (occlusion); for an unbounded quantity (irradiance), 1 / the reference's
// 99th percentile, so that the grid's images share one exposure and the reference fills it.
float computeDisplayScale(const Image<float>& reference)
{
    std::vector<float> v;
    v.reserve(reference.pixels.size());
    for (const float x : reference.pixels)
        if (std::isfinite(x))
            v.push_back(x);
    if (v.empty())
        return 1.0f;
    const std::size_t k = std::min(v.size() - 1, std::size_t(0.99 * double(v.size())));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
    return v[k] > 1.0f ? 1.0f / v[k] : 1.0f;
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

std::string numberBarsThatDoNotFit(plot::StackedBarSpec& bars)
{
    std::string key;
    if (plot::barLabelsFit(bars))
        return key;
    for (std::size_t b = 0; b < bars.bars.size(); ++b) {
        std::string label = bars.bars[b];
        std::replace(label.begin(), label.end(), '\n', ' ');
        key += (key.empty() ? " Bars: " : "; ") + std::to_string(b + 1) + " = " + label;
        bars.bars[b] = std::to_string(b + 1);
    }
    return key;
}

Figures writeGroupFigures(const Group& group, const std::vector<EqualErrorRow>& equal,
                          const std::string& directory, const std::vector<std::string>& techniques)
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
        if (!any) {
            figures.notes.push_back("No chart of " + label + " on " + group.title +
                                    ": no run has a finite value (" + column + ").");
            continue;
        }
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
            // Labels name only the parameters that differ among this technique's configurations.
            std::vector<std::string> differing;
            for (const auto& p : configParams) {
                std::set<std::string> values;
                for (const auto& [config, runs] : byConfig)
                    values.insert(describeRun(*runs.front(), {p}));
                if (values.size() > 1)
                    differing.push_back(p);
            }
            int variant = 0; // the technique's configurations: same colour, own line pattern and marker
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
                s.variant = variant++;
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
                const std::string detail = describeRun(*runs.front(), differing);
                const std::string name = technique + (detail.empty() ? "" : " " + detail);
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

    // 2. Error against each swept numeric parameter, over matched runs only: one line per technique
    //    and setting of the other swept parameters (runs that differ in this parameter alone), so
    //    that a value swept in only one variant is not compared with the mean of every other run.
    //    Lines of one technique share its colour and differ in pattern and marker; at most
    //    kMaxLines per technique, those with the most values first.
    constexpr std::size_t kMaxLines = 5;
    std::vector<std::pair<std::string, std::string>> paramErrors = {{columns.error, columns.errorLabel}};
    paramErrors.insert(paramErrors.end(), columns.paramErrors.begin(), columns.paramErrors.end());
    for (const auto& param : group.varyingParams) {
        for (std::size_t e = 0; e < paramErrors.size(); ++e) {
            const auto& [errorColumn, errorLabel] = paramErrors[e];
            const std::string name = param.rfind("param.", 0) == 0 ? param.substr(6) : param;
            // The main error keeps its file names; the others are named after their column.
            const std::string what = e == 0 ? "error" : makeFileName(errorColumn);
            plot::LineSpec line;
            line.title = group.title + ": " + (e == 0 ? "error" : errorColumn) + " against " + name;
            const auto unit = group.paramUnits.find(param);
            line.xLabel = name == "grid" ? "grid (samples per axis)"
                          : unit != group.paramUnits.end() ? name + " (" + unit->second + ")"
                                                           : name;
            line.yLabel = errorLabel;
            line.colors = colors;
            const MatchedLines matched =
                collectMatchedLines(group.runs, param, errorColumn, group.varyingParams, kMaxLines);
            const std::size_t leftOut = matched.leftOut;
            for (const MatchedLine& m : matched.lines) {
                plot::Series s{m.label};
                s.variant = m.variant;
                for (const auto& [x, y] : m.points) {
                    s.x.push_back(x);
                    s.y.push_back(y);
                }
                line.colors.setColor(s.label, line.colors.getColor(m.technique));
                line.series.push_back(std::move(s));
            }
            if (line.series.empty())
                continue; // not numeric, or no two runs that differ in this parameter alone
            const std::string path = plots + "/" + what + "_vs_" + makeFileName(name) + "_" + stem;
            plot::writeLineChart(line, path);
            figures.plots.push_back(path);
            figures.captions.push_back(
                (e == 0 ? "Error" : errorLabel) + " against " + name + " on " + group.title +
                ", over runs that differ in " + name + " alone (one line per setting of the other swept parameters" +
                (leftOut > 0 ? "; " + std::to_string(leftOut) + " settings with fewer values not drawn" : "") + ").");
        }
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
        const std::string key = numberBarsThatDoNotFit(bars); // the key goes in the caption
        const std::string path = plots + "/pass_times_" + stem;
        plot::writeStackedBars(bars, path);
        figures.plots.push_back(path);
        figures.captions.push_back("Time per pass of the runs on each technique's Pareto front on " +
                                   group.title + "." + (key.empty() ? "" : key + "."));
    }

    // 3b. The speed-up of each run against the family's sampling baseline at the same error
    //     (computeEqualError), fastest first, up to 12 runs.
    plot::StackedBarSpec speedups;
    speedups.title = group.title + ": speed-up against " + columns.baseline + " at equal error";
    speedups.yLabel = "time of " + columns.baseline + " at the run's error / the run's time";
    speedups.passes = {"speed-up"};
    speedups.colors = plot::ColorTable(speedups.passes);
    speedups.totalDecimals = 1;
    for (const EqualErrorRow& row : equal)
        if (std::isfinite(row.speedup) && speedups.bars.size() < 12) {
            const std::string label = describeEqualErrorRun(*row.run, group);
            speedups.bars.push_back(row.run->technique + (label.empty() ? "" : "\n" + label));
            speedups.values.push_back({row.speedup});
        }
    if (!speedups.bars.empty()) {
        const std::string key = numberBarsThatDoNotFit(speedups);
        const std::string path = plots + "/equal_error_" + stem;
        plot::writeStackedBars(speedups, path);
        figures.plots.push_back(path);
        figures.captions.push_back(
            "How much longer " + columns.baseline + " takes at the error of each run on " +
            group.title +
            ": its time interpolated between its runs around that error (the table below, and "
            "equal_error.csv, also give the cheapest " +
            columns.baseline + " run reaching it)." + (key.empty() ? "" : key + "."));
    }

    // 4. Images (families that write them, findRunImages): reference | each technique's
    //    lowest-error run, over their error maps, with crops around the worst error. A study of
    //    one technique shows up to 4 of its runs instead, lowest error first (its variants side
    //    by side: the discontinuity of an interpolation, an ablation).
    plot::ImageGridSpec grid;
    std::vector<std::pair<std::string, const RunSummary*>> shown;
    if (byTechnique.size() == 1) {
        std::vector<const RunSummary*> runs = byTechnique.begin()->second;
        std::stable_sort(runs.begin(), runs.end(), [&](const RunSummary* a, const RunSummary* b) {
            return a->get(columns.error) < b->get(columns.error);
        });
        for (std::size_t i = 0; i < runs.size() && i < 4; ++i)
            shown.emplace_back(byTechnique.begin()->first, runs[i]);
        grid.title = group.title + ": frame 0 of " + byTechnique.begin()->first + "'s runs, lowest error first";
    } else {
        for (const auto& [technique, runs] : byTechnique) {
            const RunSummary* best = nullptr;
            for (const RunSummary* run : runs)
                if (!best || run->get(columns.error) < best->get(columns.error))
                    best = run;
            shown.emplace_back(technique, best);
        }
        grid.title = group.title + ": frame 0 of each technique's lowest-error run";
    }
    std::vector<plot::GridCell> images, errors;
    Image<float> firstError;
    float displayScale = 1.0f;
    for (const auto& [technique, best] : shown) {
        const RunImages files = findRunImages(best->frames.front());
        if (!files.valid() || !std::filesystem::exists(files.technique))
            continue;
        if (images.empty()) {
            grid.columnTitles.push_back("reference");
            const Image<float> reference = experiment::readExrScalar(files.reference);
            displayScale = computeDisplayScale(reference);
            images.push_back(plot::makeColorCell(toGrey(reference, displayScale)));
            // Under the reference: its own noise floor (per-pixel standard error), on the same
            // scale as the techniques' errors.
            std::string stderrPath = files.reference;
            if (const std::size_t at = stderrPath.rfind("reference.exr"); at != std::string::npos)
                stderrPath.replace(at, 13, "reference_stderr.exr");
            else
                stderrPath.clear();
            // A family whose reference is exact writes no noise floor: it is zero.
            errors.push_back(
                plot::makeErrorCell(std::filesystem::exists(stderrPath)
                                        ? experiment::readExrScalar(stderrPath)
                                        : Image<float>(reference.width, reference.height, 0.0f)));
        }
        // One technique: the figure's title names it, the columns their parameters.
        const std::string params = describeRun(*best, group.varyingParams);
        grid.columnTitles.push_back(byTechnique.size() == 1 ? params : technique + "\n" + params);
        images.push_back(plot::makeColorCell(toGrey(experiment::readExrScalar(files.technique), displayScale)));
        Image<float> error = experiment::readExrScalar(files.error);
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
            "largest error, magnified." +
            (displayScale != 1.0f ? " Images scaled by " + formatScale(displayScale) +
                                        " (1 / the reference's 99th percentile)."
                                  : std::string()));
    }
    Figures lit = writeLitFrameFigures(group, directory, colors);
    figures.plots.insert(figures.plots.end(), lit.plots.begin(), lit.plots.end());
    figures.captions.insert(figures.captions.end(), lit.captions.begin(), lit.captions.end());
    figures.notes.insert(figures.notes.end(), lit.notes.begin(), lit.notes.end());
    return figures;
}

} // namespace rtlab::report::detail
