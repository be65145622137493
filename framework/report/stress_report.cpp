#include "report/stress_report.h"

#include "core/error.h"
#include "plot/heat_map.h"
#include "report/report_detail.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace rtlab::report {
namespace {

using experiment::StressRecord;

//! Names in first-seen order.
std::vector<std::string> collectOrdered(const std::vector<const StressRecord*>& records,
                                        std::string StressRecord::*field)
{
    std::vector<std::string> out;
    for (const auto* r : records)
        if (std::find(out.begin(), out.end(), r->*field) == out.end())
            out.push_back(r->*field);
    return out;
}

plot::HeatCell makeCell(const StressRecord* r)
{
    if (r == nullptr)
        return {};
    if (!r->outcome.passed())
        return {plot::HeatCell::State::Fail};
    const double ratio = std::isfinite(r->outcome.deviation) && r->outcome.tolerance > 0.0
                             ? r->outcome.deviation / r->outcome.tolerance
                             : (std::isfinite(r->outcome.deviation) ? 0.0 : NAN);
    return {plot::HeatCell::State::Pass, ratio};
}

std::string formatRatio(double v)
{
    char text[32];
    std::snprintf(text, sizeof(text), "%.2f", v);
    return text;
}

} // namespace

StressReportFiles writeStressReport(const std::vector<StressRecord>& records, const std::string& directory,
                                    const std::string& commandLine)
{
    namespace fs = std::filesystem;
    fs::create_directories(directory);
    StressReportFiles files;
    {
        // A new table: a stress run is not resumed, it is repeated.
        experiment::ResultsStore store(directory);
        fs::remove(store.jsonlPath());
        std::vector<experiment::ResultRow> rows;
        for (const auto& r : records)
            rows.push_back(experiment::makeStressRow(r));
        store.append(rows);
        store.writeCsv();
        files.csv = store.csvPath();
    }

    std::map<std::string, std::vector<const StressRecord*>> byFamily;
    std::vector<std::string> families;
    std::size_t failed = 0;
    for (const auto& r : records) {
        if (byFamily.find(r.family) == byFamily.end())
            families.push_back(r.family);
        byFamily[r.family].push_back(&r);
        failed += r.outcome.passed() ? 0 : 1;
    }

    using detail::escapeHtml;
    std::ostringstream h;
    h << detail::getPageHead("rtlab stress");
    h << "<h1>Stress: every technique through its family's hostile inputs</h1>\n";
    h << "<p><code>" << escapeHtml(commandLine) << "</code></p>\n";
    h << "<p><b>" << records.size() - failed << " of " << records.size() << "</b> technique x case pairs passed"
      << (failed > 0 ? ", <b style=\"color:#d62728\">" + std::to_string(failed) + " failed</b>" : std::string())
      << ". A pass means every output was finite and in the family's range and, where the case has a closed form, "
         "within its stated tolerance. The table: <a href=\"results.csv\">results.csv</a>.</p>\n<ul>\n";
    for (const auto& f : families)
        h << "<li><a href=\"#" << escapeHtml(f) << "\">" << escapeHtml(f) << "</a></li>\n";
    h << "</ul>\n";

    for (const auto& family : families) {
        const auto& recs = byFamily[family];
        const auto techniques = collectOrdered(recs, &StressRecord::technique);
        const auto cases = collectOrdered(recs, &StressRecord::caseName);
        std::map<std::pair<std::string, std::string>, const StressRecord*> at;
        for (const auto* r : recs)
            at[{r->technique, r->caseName}] = r;

        plot::HeatMapSpec spec;
        std::size_t familyFailed = 0;
        for (const auto* r : recs)
            familyFailed += r->outcome.passed() ? 0 : 1;
        spec.title = family + ": " + std::to_string(techniques.size()) + " techniques x " +
                     std::to_string(cases.size()) + " stress cases, " + std::to_string(familyFailed) + " failed";
        spec.rowLabels = techniques;
        spec.columnLabels = cases;
        for (const auto& t : techniques) {
            std::vector<plot::HeatCell> row;
            for (const auto& c : cases) {
                const auto it = at.find({t, c});
                row.push_back(makeCell(it == at.end() ? nullptr : it->second));
            }
            spec.cells.push_back(std::move(row));
        }
        const std::string stem = "heatmap_" + family;
        plot::writeHeatMap(spec, (fs::path(directory) / stem).string());
        files.heatMaps.push_back((fs::path(directory) / (stem + ".png")).string());

        h << "<h2 id=\"" << escapeHtml(family) << "\">" << escapeHtml(family) << "</h2>\n";
        h << "<figure><img src=\"" << stem << ".png\" alt=\"" << escapeHtml(spec.title) << "\"><figcaption>"
          << escapeHtml(spec.title) << ". Green: passed; closed-form cases shade toward olive as their "
          << "deviation nears the tolerance; red: failed. <a href=\"" << stem << ".pdf\">PDF</a></figcaption></figure>\n";
        h << "<div class=\"scroll\"><table><tr><th>case</th><th>group</th>";
        for (const auto& t : techniques)
            h << "<th>" << escapeHtml(t) << "</th>";
        h << "<th style=\"text-align:left\">what it checks</th></tr>\n";
        for (const auto& c : cases) {
            const StressRecord* any = nullptr;
            for (const auto& t : techniques)
                if (auto it = at.find({t, c}); it != at.end())
                    any = it->second;
            h << "<tr><td style=\"text-align:left\">" << escapeHtml(c) << "</td><td>" << escapeHtml(any ? any->group : "")
              << "</td>";
            for (const auto& t : techniques) {
                const auto it = at.find({t, c});
                if (it == at.end()) {
                    h << "<td></td>";
                    continue;
                }
                const StressRecord& r = *it->second;
                const plot::HeatColor color = plot::getHeatColor(makeCell(&r));
                std::string text = r.outcome.passed() ? "ok" : "FAIL";
                if (std::isfinite(r.outcome.deviation) && r.outcome.tolerance > 0.0)
                    text += " " + formatRatio(r.outcome.deviation / r.outcome.tolerance);
                std::string tip;
                for (const auto& f : r.outcome.failures)
                    tip += (tip.empty() ? "" : "\n") + f;
                char background[32];
                std::snprintf(background, sizeof(background), "#%02x%02x%02x", color.r, color.g, color.b);
                h << "<td style=\"background:" << background << ";color:#fff\" title=\"" << escapeHtml(tip) << "\">"
                  << escapeHtml(text) << "<br><small>" << formatRatio(r.milliseconds) << " ms</small></td>";
            }
            h << "<td style=\"text-align:left\">" << escapeHtml(any ? any->description : "") << "</td></tr>\n";
        }
        h << "</table></div>\n<p>A number after ok / FAIL is the worst deviation from the case's closed form over "
             "its tolerance (at most 1 passes).</p>\n";
        if (familyFailed > 0) {
            h << "<h3>Failures</h3>\n<ul>\n";
            for (const auto* r : recs)
                for (const auto& f : r->outcome.failures)
                    h << "<li><b>" << escapeHtml(r->technique) << "</b> on <b>" << escapeHtml(r->caseName)
                      << "</b>: " << escapeHtml(f) << "</li>\n";
            h << "</ul>\n";
        }
    }
    h << "</body></html>\n";
    files.html = (fs::path(directory) / "stress.html").string();
    std::ofstream out(files.html);
    out << h.str();
    if (!out)
        throw Error("cannot write " + files.html);
    return files;
}

} // namespace rtlab::report
