#include "experiment/analysis.h"

#include "experiment/results.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rtlab::experiment {

std::vector<Row> loadResults(const std::string& directory)
{
    std::vector<Row> rows;
    for (auto& cells : ResultsStore(directory).readRows())
        rows.emplace_back(cells.begin(), cells.end());
    return rows;
}

double getNumber(const Row& row, const std::string& column)
{
    const auto it = row.find(column);
    if (it == row.end() || it->second.empty())
        return std::numeric_limits<double>::quiet_NaN();
    double v = 0;
    const char* b = it->second.data();
    const char* e = b + it->second.size();
    auto [p, ec] = std::from_chars(b, e, v);
    return (ec == std::errc() && p == e) ? v : std::numeric_limits<double>::quiet_NaN();
}

std::vector<std::size_t> findParetoFront(const std::vector<Row>& rows,
                                         const std::string& costColumn,
                                         const std::string& errorColumn)
{
    std::vector<std::size_t> candidates;
    for (std::size_t i = 0; i < rows.size(); ++i)
        if (std::isfinite(getNumber(rows[i], costColumn)) &&
            std::isfinite(getNumber(rows[i], errorColumn)))
            candidates.push_back(i);
    // Sweep by increasing cost (ties: lower error first); keep rows that lower the best error.
    std::sort(candidates.begin(), candidates.end(), [&](std::size_t a, std::size_t b) {
        const double ca = getNumber(rows[a], costColumn), cb = getNumber(rows[b], costColumn);
        if (ca != cb)
            return ca < cb;
        return getNumber(rows[a], errorColumn) < getNumber(rows[b], errorColumn);
    });
    std::vector<std::size_t> front;
    double bestError = std::numeric_limits<double>::infinity();
    for (std::size_t i : candidates) {
        const double e = getNumber(rows[i], errorColumn);
        if (e < bestError) {
            front.push_back(i);
            bestError = e;
        }
    }
    return front;
}

} // namespace rtlab::experiment

namespace rtlab::experiment {

long findBest(const std::vector<Row>& rows, const BestQuery& query)
{
    long best = -1;
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const auto status = rows[i].find("status");
        if (status == rows[i].end() || status->second != "ok")
            continue;
        const double cost = getNumber(rows[i], query.costColumn);
        const double error = getNumber(rows[i], query.errorColumn);
        if (!std::isfinite(cost) || !std::isfinite(error))
            continue;
        if (query.maxCost >= 0.0 && cost > query.maxCost)
            continue;
        if (query.maxError >= 0.0 && error > query.maxError)
            continue;
        if (best < 0) {
            best = long(i);
            continue;
        }
        const double bestCost = getNumber(rows[best], query.costColumn);
        const double bestError = getNumber(rows[best], query.errorColumn);
        const bool better = query.maxError >= 0.0
                                ? (cost < bestCost || (cost == bestCost && error < bestError))
                                : (error < bestError || (error == bestError && cost < bestCost));
        if (better)
            best = long(i);
    }
    return best;
}

double parseDurationMs(const std::string& text)
{
    std::string s;
    for (char c : text)
        if (c != ' ')
            s += c;
    double scale = 1.0;
    for (const auto& [suffix, factor] :
         {std::pair<const char*, double>{"ms", 1.0}, {"us", 1e-3}, {"ns", 1e-6}, {"s", 1e3}}) {
        const std::string suf = suffix;
        if (s.size() > suf.size() && s.ends_with(suf)) {
            s.resize(s.size() - suf.size());
            scale = factor;
            break;
        }
    }
    double v = 0;
    auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || ec != std::errc() || p != s.data() + s.size() || !(v >= 0.0) ||
        !std::isfinite(v))
        throw std::invalid_argument("expected a duration like 5ms, 0.5s or 250us, found '" + text +
                                    "'");
    return v * scale;
}

} // namespace rtlab::experiment
