#include "report/report.h"

#include "core/error.h"
#include "core/strings.h"
#include "plot/charts.h"
#include "report/report_detail.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

namespace rtlab::report {

FamilyColumns getFamilyColumns(const plugin::Registry& registry, const std::string& family)
{
    if (const plugin::FamilyInfo* info = registry.findFamily(family))
        return info->report;
    // A run of several families ("occlusion+voxel_gi"): the first one's columns.
    for (std::size_t start = 0; start < family.size();) {
        const std::size_t plus = std::min(family.find('+', start), family.size());
        if (const plugin::FamilyInfo* info =
                registry.findFamily(family.substr(start, plus - start)))
            return info->report;
        start = plus + 1;
    }
    throw Error("no report columns for family '" + family + "' (not registered in this build)");
}

namespace detail {

double RunSummary::get(const std::string& column) const
{
    auto it = number.find(column);
    return it == number.end() ? std::nan("") : it->second;
}

std::vector<Group> groupRuns(const std::vector<experiment::Row>& rows,
                             const plugin::Registry& registry)
{
    // Runs by id, frames together.
    std::map<std::string, RunSummary> runs;
    std::vector<std::string> order;
    for (const auto& row : rows) {
        auto status = row.find("status");
        if (status == row.end() || status->second != "ok")
            continue;
        const std::string id = row.at("run_id");
        auto [it, inserted] = runs.try_emplace(id);
        if (inserted) {
            it->second.runId = id;
            it->second.technique = row.count("technique") ? row.at("technique") : "?";
            order.push_back(id);
        }
        it->second.frames.push_back(row);
    }
    std::map<std::string, Group> groups;
    std::vector<std::string> groupOrder;
    for (const auto& id : order) {
        RunSummary& run = runs[id];
        // The experiment's report.time_from_frame: time columns of a run of more frames than
        // that leave the first frames out.
        const double fromFrame =
            experiment::getNumber(run.frames.front(), "report.time_from_frame");
        const bool skipFirst =
            std::isfinite(fromFrame) && fromFrame > 0.0 && double(run.frames.size()) > fromFrame;
        run.timeFromFrame = skipFirst ? int(fromFrame) : 0;
        const auto isTime = [](const std::string& k) {
            return k.size() > 3 && k.compare(k.size() - 3, 3, "_ms") == 0;
        };
        std::map<std::string, std::pair<double, int>> sums;
        for (const auto& frame : run.frames)
            for (const auto& [k, v] : frame) {
                const double x = experiment::getNumber(frame, k);
                if (skipFirst && isTime(k) && experiment::getNumber(frame, "frame") < fromFrame)
                    continue;
                if (std::isfinite(x)) {
                    sums[k].first += x;
                    sums[k].second += 1;
                } else if (!run.text.count(k)) {
                    run.text[k] = v;
                }
            }
        for (const auto& [k, s] : sums)
            run.number[k] = s.first / s.second;
        // Results written before the technique_ms column: the GPU time was the technique's time.
        if (!run.number.count("technique_ms") && run.number.count("occlusion.gpu_ms"))
            run.number["technique_ms"] = run.number["occlusion.gpu_ms"];
        const std::string family = run.text.count("family") ? run.text["family"] : "?";
        std::string scene = std::filesystem::path(run.text.count("scene") ? run.text["scene"] : "?")
                                .stem()
                                .string();
        std::string key = scene, title = scene;
        const plugin::FamilyInfo* info = registry.findFamily(family.substr(0, family.find('+')));
        const bool volume = info && info->domain == plugin::FamilyDomain::Volume;
        if (!volume) {
            const std::string size =
                (run.text.count("width") ? run.text["width"]
                                         : std::to_string(int(run.get("width")))) +
                "x" + std::to_string(int(run.get("height")));
            key += "_" + size;
            title += ", " + size;
        }
        key = family + "_" + key;
        auto [git, added] = groups.try_emplace(key);
        if (added) {
            git->second.key = key;
            git->second.title = family + ": " + title;
            git->second.family = family;
            git->second.columns = getFamilyColumns(registry, family);
            groupOrder.push_back(key);
        }
        // Runs of the lit frame (frame: {lighting: true}) add its columns to the tables, and its
        // errors to the charts against each swept parameter.
        if (std::isfinite(run.get("frame.rmse")) &&
            std::find(git->second.columns.tableColumns.begin(),
                      git->second.columns.tableColumns.end(),
                      "frame.rmse") == git->second.columns.tableColumns.end()) {
            for (const char* c : {"frame.cpu_ms", "frame.rmse", "frame.flip",
                                  "frame.mean_signed_error", "direct.rmse", "frame.culling",
                                  "frame.sky"})
                git->second.columns.tableColumns.push_back(c);
            auto& paramErrors = git->second.columns.paramErrors;
            paramErrors.emplace_back("frame.rmse", "final frame RMSE against Embree full (radiance)");
            paramErrors.emplace_back("direct.rmse", "direct term RMSE against Embree direct (radiance)");
        }
        git->second.runs.push_back(run);
    }
    std::vector<Group> out;
    for (const auto& key : groupOrder) {
        Group g = groups[key];
        int fromFrame = 0;
        for (const auto& run : g.runs)
            fromFrame = std::max(fromFrame, run.timeFromFrame);
        if (fromFrame > 0) {
            const std::string note =
                "; runs of several frames: frames " + std::to_string(fromFrame) + " and later";
            g.columns.costLabel += note;
            g.columns.passTimeLabel =
                (g.columns.passTimeLabel.empty() ? "time (ms, median)" : g.columns.passTimeLabel) +
                note;
        }
        std::map<std::string, std::set<std::string>> values;
        for (const auto& run : g.runs)
            for (const auto& frame : run.frames)
                for (const auto& [k, v] : frame)
                    if (k.rfind("param.", 0) == 0 || k == "grid")
                        values[k].insert(v);
        if (g.runs.size() > 1)
            for (const auto& [k, vs] : values)
                if (vs.size() > 1)
                    g.varyingParams.push_back(k);
        // The units of the varying parameters, from the schemas of the group's techniques.
        const std::string family = g.family.substr(0, g.family.find('+'));
        for (const auto& run : g.runs)
            if (const plugin::TechniqueEntry* entry = registry.findTechnique(family, run.technique))
                for (const auto& k : g.varyingParams)
                    if (k.rfind("param.", 0) == 0 && !g.paramUnits.count(k))
                        if (const config::ParamSpec* spec = entry->schema.find(k.substr(6));
                            spec != nullptr && !spec->unit.empty())
                            g.paramUnits[k] = spec->unit;
        out.push_back(std::move(g));
    }
    return out;
}

std::string describeRun(const RunSummary& run, const std::vector<std::string>& varyingParams)
{
    std::string s;
    const auto& first = run.frames.front();
    for (const auto& p : varyingParams) {
        auto it = first.find(p);
        if (it == first.end())
            continue;
        s += (s.empty() ? "" : " ") + (p.rfind("param.", 0) == 0 ? p.substr(6) : p) + "=" +
             it->second;
    }
    return s;
}

MatchedLines collectMatchedLines(const std::vector<RunSummary>& runs, const std::string& param,
                                 const std::string& errorColumn, const std::vector<std::string>& varyingParams,
                                 std::size_t maxLinesPerTechnique)
{
    std::vector<std::string> others;
    for (const auto& p : varyingParams)
        if (p != param)
            others.push_back(p);
    // Run settings that are not technique parameters but change the error as much: the camera
    // path (a still camera, eight frames with digs), the frame's switches and the frame count.
    // `names` picks among the parameters and these; `others` with every one of these is the key.
    static const std::vector<std::string> kRunColumns = {"camera_path", "frame.culling", "frame.gbuffer_on_gpu",
                                                         "frame.sky"};
    const auto describeSetting = [&](const RunSummary& run, const std::vector<std::string>& names, bool key) {
        std::vector<std::string> params;
        for (const auto& n : names)
            if (std::find(kRunColumns.begin(), kRunColumns.end(), n) == kRunColumns.end() && n != "frames")
                params.push_back(n);
        std::string s = describeRun(run, params);
        const auto wanted = [&](const std::string& n) {
            return key || std::find(names.begin(), names.end(), n) != names.end();
        };
        const auto& first = run.frames.front();
        for (const auto& column : kRunColumns)
            if (auto it = first.find(column); it != first.end() && !it->second.empty() && wanted(column))
                s += (s.empty() ? "" : " ") + column + "=" + it->second;
        if (wanted("frames"))
            s += (s.empty() ? "" : " ") + std::string("frames=") + std::to_string(run.frames.size());
        return s;
    };
    // Techniques in first-seen order; per technique, per setting of the others: value -> (sum, n).
    std::vector<std::string> techniques;
    std::map<std::string, std::map<std::string, std::map<double, std::pair<double, int>>>> sums;
    std::map<std::string, std::map<std::string, const RunSummary*>> example;
    for (const RunSummary& run : runs) {
        const double x = run.get(param), y = run.get(errorColumn);
        if (!std::isfinite(x) || !std::isfinite(y))
            continue;
        if (!sums.count(run.technique))
            techniques.push_back(run.technique);
        const std::string setting = describeSetting(run, others, true);
        auto& sum = sums[run.technique][setting][x];
        sum.first += y;
        sum.second += 1;
        example[run.technique].emplace(setting, &run);
    }
    MatchedLines out;
    for (const std::string& technique : techniques) {
        auto& bySetting = sums[technique];
        std::vector<std::string> settings;
        for (const auto& [setting, values] : bySetting)
            if (values.size() >= 2)
                settings.push_back(setting);
        std::stable_sort(settings.begin(), settings.end(), [&](const std::string& a, const std::string& b) {
            return bySetting[a].size() > bySetting[b].size();
        });
        if (settings.size() > maxLinesPerTechnique) {
            out.leftOut += settings.size() - maxLinesPerTechnique;
            settings.resize(maxLinesPerTechnique);
        }
        // The label names the other parameters that differ among this technique's lines.
        std::vector<std::string> candidates = others;
        candidates.insert(candidates.end(),
                          {"camera_path", "frame.culling", "frame.gbuffer_on_gpu", "frame.sky", "frames"});
        std::vector<std::string> differing;
        for (const auto& p : candidates) {
            std::set<std::string> values;
            for (const auto& setting : settings)
                values.insert(describeSetting(*example[technique][setting], {p}, false));
            if (values.size() > 1)
                differing.push_back(p);
        }
        int variant = 0;
        for (const auto& setting : settings) {
            MatchedLine line;
            line.technique = technique;
            const std::string detail = describeSetting(*example[technique][setting], differing, false);
            line.label = technique + (detail.empty() ? "" : " " + detail);
            line.variant = variant++;
            for (const auto& [x, sum] : bySetting[setting])
                line.points[x] = sum.first / sum.second;
            out.lines.push_back(std::move(line));
        }
    }
    return out;
}

std::map<std::string, std::map<double, double>>
collectAcrossScenesLines(const std::vector<Group>& groups, const std::string& family,
                         const plugin::AcrossScenesFigure& spec)
{
    std::map<std::string, std::map<double, std::pair<double, int>>> sums;
    for (const auto& g : groups)
        if (g.family == family)
            for (const auto& run : g.runs) {
                const double x = run.get(spec.x), y = run.get(spec.y);
                if (!std::isfinite(x) || !std::isfinite(y))
                    continue;
                const std::string setting = describeRun(run, spec.seriesBy);
                auto& cell = sums[run.technique + (setting.empty() ? "" : " (" + setting + ")")][x];
                cell.first += y;
                cell.second += 1;
            }
    std::map<std::string, std::map<double, double>> lines;
    for (const auto& [name, points] : sums)
        for (const auto& [x, sum] : points)
            lines[name][x] = sum.first / sum.second;
    return lines;
}

} // namespace detail

ReportSummary writeStudyReport(const std::string& directory, const plugin::Registry& registry,
                               int timeFromFrame)
{
    auto rows = experiment::loadResults(directory);
    if (timeFromFrame > 0)
        for (auto& row : rows)
            row["report.time_from_frame"] = std::to_string(timeFromFrame);
    if (rows.empty())
        throw Error(directory + ": no results (results.jsonl is missing or empty)");
    const auto groups = detail::groupRuns(rows, registry);
    std::set<std::string> techniqueSet;
    for (const auto& g : groups)
        for (const auto& r : g.runs)
            techniqueSet.insert(r.technique);
    const std::vector<std::string> techniques(techniqueSet.begin(), techniqueSet.end());

    // Per-run PNGs: |error| of 0.25 (a quarter of the AO range) saturates the heat map.
    detail::writeRunImages(rows, 0.25f);

    ReportSummary summary;
    // Each group's runs against its family's sampling baseline, for its chart, the CSV and the
    // page.
    std::vector<std::vector<detail::EqualErrorRow>> equal;
    for (const auto& g : groups) {
        equal.push_back(detail::computeEqualError(g));
        summary.equalErrorRuns += int(equal.back().size());
    }
    std::vector<detail::Figures> figures;
    for (std::size_t gi = 0; gi < groups.size(); ++gi) {
        figures.push_back(detail::writeGroupFigures(groups[gi], equal[gi], directory, techniques));
        for (const auto& p : figures.back().plots)
            summary.plots.push_back(p + ".png");
    }
    // Figures over every scene of the study (a family's acrossScenes), shown with the family's
    // first group.
    for (std::size_t gi = 0; gi < groups.size(); ++gi) {
        const detail::Group& first = groups[gi];
        bool seen = false;
        for (std::size_t j = 0; j < gi; ++j)
            seen = seen || groups[j].family == first.family;
        if (seen)
            continue;
        for (const auto& spec : first.columns.acrossScenes) {
            const auto lines = detail::collectAcrossScenesLines(groups, first.family, spec);
            plot::LineSpec line;
            line.title = spec.title;
            line.xLabel = spec.xLabel;
            line.yLabel = spec.yLabel;
            line.colors = plot::ColorTable(techniques);
            for (const auto& [name, points] : lines) {
                if (points.size() < 2)
                    continue;
                plot::Series s{name};
                for (const auto& [x, y] : points) {
                    s.x.push_back(x);
                    s.y.push_back(y);
                }
                line.series.push_back(std::move(s));
            }
            if (line.series.empty())
                continue;
            const std::string path = directory + "/plots/" + detail::makeFileName(spec.name);
            plot::writeLineChart(line, path);
            figures[gi].plots.push_back(path);
            figures[gi].captions.push_back(spec.caption);
            summary.plots.push_back(path + ".png");
        }
    }
    std::string manifest;
    try {
        manifest = readTextFile(directory + "/manifest.json");
    } catch (const std::exception&) {
        manifest = "{}";
    }
    summary.equalError = detail::writeEqualErrorCsv(directory, groups, equal);
    detail::writeHtml(directory, groups, equal, figures, manifest);
    summary.html = directory + "/report.html";
    return summary;
}

} // namespace rtlab::report
