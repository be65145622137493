// report.html: one self-contained page (relative links only) that opens from disk.

#include "report/report_detail.h"

#include "core/error.h"
#include "core/strings.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace rtlab::report::detail {

std::string escapeHtml(const std::string& s)
{
    std::string out;
    for (char c : s) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        default: out += c;
        }
    }
    return out;
}

std::string getPageHead(const std::string& title)
{
    return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>" + escapeHtml(title) +
           "</title>\n<style>\n"
           "body{font-family:sans-serif;margin:2em auto;max-width:1200px;color:#222}\n"
           "img{max-width:100%;border:1px solid #ddd}\nfigure{margin:1.5em 0}\n"
           "figcaption{color:#555;font-size:0.9em}\n"
           "table{border-collapse:collapse;font-size:0.85em}td,th{border:1px solid #ccc;padding:2px 6px;"
           "text-align:right}th{background:#f3f3f3}\n.scroll{overflow-x:auto;max-height:30em}\n"
           "pre{background:#f7f7f7;padding:1em;overflow-x:auto;font-size:0.8em}\n</style></head><body>\n";
}

std::string formatNumber(double v, int precision)
{
    if (!std::isfinite(v))
        return "";
    std::ostringstream s;
    s.precision(precision);
    s << v;
    return s.str();
}

namespace {

std::string relativeTo(const std::string& path, const std::string& directory)
{
    return std::filesystem::relative(path, directory).generic_string();
}

} // namespace

void writeHtml(const std::string& directory, const std::vector<Group>& groups,
               const std::vector<std::vector<EqualErrorRow>>& equalRows,
               const std::vector<Figures>& figures, const std::string& manifestJson)
{
    std::ostringstream h;
    std::string title = std::filesystem::path(directory).filename().string();
    h << getPageHead(title + " - rtlab study");
    h << "<h1>Study " << escapeHtml(title) << "</h1>\n";
    h << "<p>Results table: <a href=\"results.csv\">results.csv</a> (and <a href=\"results.jsonl\">results.jsonl</a>); "
         "what produced it: <a href=\"manifest.json\">manifest.json</a>. Every figure is also a vector PDF beside its "
         "PNG.</p>\n";
    h << "<ul>\n";
    for (const auto& g : groups)
        h << "<li><a href=\"#" << escapeHtml(g.key) << "\">" << escapeHtml(g.title) << "</a> (" << g.runs.size()
          << " runs)</li>\n";
    h << "</ul>\n";

    for (std::size_t gi = 0; gi < groups.size(); ++gi) {
        const Group& g = groups[gi];
        const FamilyColumns& columns = g.columns;
        h << "<h2 id=\"" << escapeHtml(g.key) << "\">" << escapeHtml(g.title) << "</h2>\n";
        for (std::size_t i = 0; i < figures[gi].plots.size(); ++i) {
            const std::string rel = relativeTo(figures[gi].plots[i], directory);
            h << "<figure><img src=\"" << escapeHtml(rel) << ".png\" alt=\"" << escapeHtml(figures[gi].captions[i])
              << "\"><figcaption>" << escapeHtml(figures[gi].captions[i]) << " <a href=\"" << escapeHtml(rel)
              << ".pdf\">PDF</a></figcaption></figure>\n";
        }
        for (const std::string& note : figures[gi].notes)
            h << "<p class=\"note\">" << escapeHtml(note) << "</p>\n";
        // The runs, sorted by error, with the columns a reader compares.
        std::vector<const RunSummary*> runs;
        for (const auto& r : g.runs)
            runs.push_back(&r);
        std::sort(runs.begin(), runs.end(), [&](const RunSummary* a, const RunSummary* b) {
            return a->get(columns.error) < b->get(columns.error);
        });
        h << "<h3>Runs, most accurate first</h3>\n<div class=\"scroll\"><table><tr><th>run</th><th>technique</th>"
             "<th>parameters</th><th>"
          << escapeHtml(columns.cost) << "</th><th>" << escapeHtml(columns.error) << "</th>";
        // Further columns, those the study has.
        std::vector<std::string> extra;
        for (const auto& c : columns.tableColumns)
            if (std::any_of(runs.begin(), runs.end(),
                            [&](const RunSummary* r) { return r->number.count(c) || r->text.count(c); }))
                extra.push_back(c);
        for (const auto& c : extra)
            h << "<th>" << escapeHtml(c) << "</th>";
        h << "<th>frames</th></tr>\n";
        for (const RunSummary* r : runs) {
            h << "<tr><td>" << escapeHtml(r->runId) << "</td><td>" << escapeHtml(r->technique) << "</td><td>"
              << escapeHtml(describeRun(*r, g.varyingParams)) << "</td><td>" << formatNumber(r->get(columns.cost))
              << "</td><td>" << formatNumber(r->get(columns.error)) << "</td>";
            for (const auto& c : extra) {
                auto text = r->text.find(c);
                h << "<td>" << (r->number.count(c) ? formatNumber(r->get(c))
                                                   : escapeHtml(text == r->text.end() ? "" : text->second))
                  << "</td>";
            }
            h << "<td>" << r->frames.size() << "</td></tr>\n";
        }
        h << "</table></div>\n";
        // The family's sampling baseline at the same error as each run.
        const std::vector<EqualErrorRow>& equal = equalRows[gi];
        if (!equal.empty()) {
            h << "<h3>Equal-error speed-up against " << escapeHtml(columns.baseline)
              << "</h3>\n<p>The baseline's time at each run's " << escapeHtml(columns.error)
              << ": log time interpolated in log error between the two "
              << escapeHtml(columns.baseline)
              << " runs of its Pareto front around it (same ground truth), and the cheapest "
              << escapeHtml(columns.baseline)
              << " run whose error is at most the run's. Also in <a "
                 "href=\"equal_error.csv\">equal_error.csv</a>.</p>\n"
                 "<div "
                 "class=\"scroll\"><table><tr><th>run</th><th>technique</th><th>parameters</th><th>"
              << escapeHtml(columns.cost) << "</th><th>" << escapeHtml(columns.error)
              << "</th><th>baseline at equal error (ms)</th><th>speed-up</th><th>cheapest baseline "
                 "run "
                 "reaching it</th><th>its time (ms)</th><th>speed-up against "
                 "it</th><th>note</th></tr>\n";
            for (const EqualErrorRow& e : equal)
                h << "<tr><td>" << escapeHtml(e.run->runId) << "</td><td>"
                  << escapeHtml(e.run->technique) << "</td><td>"
                  << escapeHtml(describeEqualErrorRun(*e.run, g)) << "</td><td>"
                  << formatNumber(e.time) << "</td><td>" << formatNumber(e.error) << "</td><td>"
                  << formatNumber(e.baselineTime) << "</td><td>" << formatNumber(e.speedup)
                  << "</td><td>"
                  << (e.cheapest ? escapeHtml(describeEqualErrorRun(*e.cheapest, g)) : "")
                  << "</td><td>" << (e.cheapest ? formatNumber(e.cheapest->get(columns.cost)) : "")
                  << "</td><td>" << formatNumber(e.cheapestSpeedup) << "</td><td>"
                  << escapeHtml(e.note) << "</td></tr>\n";
            h << "</table></div>\n";
        }
    }
    h << "<h2>Manifest</h2>\n<pre>" << escapeHtml(manifestJson.substr(0, 20000)) << "</pre>\n</body></html>\n";

    writeTextFileAtomically(directory + "/report.html", h.str());
}

} // namespace rtlab::report::detail
