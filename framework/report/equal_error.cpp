// The equal-error comparison of a study's runs with their family's sampling baseline
// (report_detail.h computeEqualError): the question "at the same error, how much longer does
// path tracing take?" answered from the runs alone, so that `rtlab report` reproduces it.

#include "report/report_detail.h"

#include "core/strings.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace rtlab::report::detail {

namespace {

// reference.* columns that describe how a ground truth was measured, not what it is.
bool isMeasurementColumn(const std::string& column)
{
    static const char* const kMeasured[] = {
        "reference.seconds",     "reference.from_cache", "reference.samples_mean",
        "reference.stderr_mean", "reference.stderr_max", "reference.matches_technique"};
    const bool time =
        column.size() > 3 && column.compare(column.size() - 3, 3, "_ms") == 0; // its pass's time
    return time || std::any_of(std::begin(kMeasured), std::end(kMeasured),
                               [&](const char* m) { return column == m; });
}

// The settings that define a run's ground truth (quantity, radius, bounces, ...), as text.
std::map<std::string, std::string> getTruthDefinition(const RunSummary& run)
{
    std::map<std::string, std::string> out;
    for (const auto& [column, value] : run.frames.front())
        if (column.rfind("reference.", 0) == 0 && !isMeasurementColumn(column))
            out[column] = value;
    return out;
}

struct Point {
    const RunSummary* run;
    double time, error;
};

} // namespace

// A run's parameters, and its camera path and frame count where the group's runs differ in them
// (a still frame and a camera path of the same settings are different rows of the comparison).
std::string describeEqualErrorRun(const RunSummary& run, const Group& group)
{
    std::string s = describeRun(run, group.varyingParams);
    const auto varies = [&](const auto& get) {
        return std::any_of(group.runs.begin(), group.runs.end(), [&](const RunSummary& other) {
            return get(other) != get(group.runs.front());
        });
    };
    const auto cameraPath = [](const RunSummary& r) {
        auto it = r.frames.front().find("camera_path");
        return it == r.frames.front().end() ? std::string() : it->second;
    };
    const auto frames = [](const RunSummary& r) { return r.frames.size(); };
    if (varies(cameraPath))
        s += (s.empty() ? "" : " ") + std::string("camera_path=") + cameraPath(run);
    if (varies(frames))
        s += (s.empty() ? "" : " ") + std::string("frames=") + std::to_string(run.frames.size());
    return s;
}

std::vector<EqualErrorRow> computeEqualError(const Group& group)
{
    std::vector<EqualErrorRow> rows;
    const std::string& baseline = group.columns.baseline;
    if (baseline.empty())
        return rows;
    const auto measure = [&](const RunSummary& run, double& time, double& error) {
        time = run.get(group.columns.cost);
        error = run.get(group.columns.error);
        return std::isfinite(time) && std::isfinite(error) && time > 0.0 && error > 0.0;
    };
    for (const RunSummary& run : group.runs) {
        EqualErrorRow row;
        if (run.technique == baseline || !measure(run, row.time, row.error))
            continue;
        // The baseline runs of the same ground truth, and their Pareto front: by time, each
        // strictly more accurate than every cheaper one.
        const auto definition = getTruthDefinition(run);
        std::vector<Point> points;
        for (const RunSummary& b : group.runs) {
            Point p{&b, 0.0, 0.0};
            if (b.technique == baseline && getTruthDefinition(b) == definition &&
                measure(b, p.time, p.error))
                points.push_back(p);
        }
        if (points.empty())
            continue;
        std::sort(points.begin(), points.end(), [](const Point& a, const Point& b) {
            return a.time != b.time ? a.time < b.time : a.error < b.error;
        });
        std::vector<Point> front;
        for (const Point& p : points)
            if (front.empty() || p.error < front.back().error)
                front.push_back(p);
        row.run = &run;
        row.baselineTime = std::numeric_limits<double>::quiet_NaN();
        row.speedup = row.baselineTime;
        row.cheapestSpeedup = row.baselineTime;
        // The front is sorted by time and error falls along it: the first point at or below the
        // error is the cheapest baseline run reaching it.
        for (const Point& p : front)
            if (p.error <= row.error) {
                row.cheapest = p.run;
                row.cheapestSpeedup = p.time / row.time;
                break;
            }
        if (row.error > front.front().error) {
            row.note = "less accurate than the cheapest baseline run (" +
                       formatNumber(front.front().time) + " ms" + ")";
        } else if (row.error < front.back().error) {
            row.note = "more accurate than every baseline run (the best takes " +
                       formatNumber(front.back().time) + " ms" + ")";
        } else {
            for (std::size_t i = 0; i < front.size(); ++i) {
                const Point& a = front[i];
                if (row.error == a.error) {
                    row.baselineTime = a.time;
                    break;
                }
                if (i + 1 < front.size() && row.error < a.error && row.error > front[i + 1].error) {
                    // Error falls about as a power of the time (1 / sqrt(samples) for Monte
                    // Carlo): a straight line in log-log between the two runs around it.
                    const Point& b = front[i + 1];
                    const double f = std::log(row.error / a.error) / std::log(b.error / a.error);
                    row.baselineTime = a.time * std::pow(b.time / a.time, f);
                    break;
                }
            }
            row.speedup = row.baselineTime / row.time;
        }
        rows.push_back(std::move(row));
    }
    std::stable_sort(rows.begin(), rows.end(), [](const EqualErrorRow& a, const EqualErrorRow& b) {
        const bool fa = std::isfinite(a.speedup), fb = std::isfinite(b.speedup);
        return fa != fb ? fa : (fa && a.speedup > b.speedup);
    });
    return rows;
}

std::string writeEqualErrorCsv(const std::string& directory, const std::vector<Group>& groups,
                               const std::vector<std::vector<EqualErrorRow>>& equal)
{
    std::ostringstream csv;
    csv << "group,run_id,technique,parameters,time_ms,error_column,error,baseline,baseline_ms,"
           "speedup,"
           "cheapest_run_id,cheapest_parameters,cheapest_ms,cheapest_speedup,note\n";
    for (std::size_t i = 0; i < groups.size() && i < equal.size(); ++i) {
        const Group& g = groups[i];
        for (const EqualErrorRow& e : equal[i])
            csv << quoteCsvField(g.key) << ',' << quoteCsvField(e.run->runId) << ','
                << quoteCsvField(e.run->technique) << ','
                << quoteCsvField(describeEqualErrorRun(*e.run, g)) << ',' << formatNumber(e.time, 6)
                << ',' << quoteCsvField(g.columns.error) << ',' << formatNumber(e.error, 6) << ','
                << quoteCsvField(g.columns.baseline) << ',' << formatNumber(e.baselineTime, 6)
                << ',' << formatNumber(e.speedup, 6) << ','
                << (e.cheapest ? quoteCsvField(e.cheapest->runId) : "") << ','
                << (e.cheapest ? quoteCsvField(describeEqualErrorRun(*e.cheapest, g)) : "") << ','
                << (e.cheapest ? formatNumber(e.cheapest->get(g.columns.cost), 6) : "") << ','
                << formatNumber(e.cheapestSpeedup, 6) << ',' << quoteCsvField(e.note) << '\n';
    }
    const std::string path = directory + "/equal_error.csv";
    writeTextFileAtomically(path, csv.str());
    return path;
}

} // namespace rtlab::report::detail
