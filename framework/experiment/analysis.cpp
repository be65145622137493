#include "experiment/analysis.h"

#include "experiment/results.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

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

std::vector<std::size_t> findParetoFront(const std::vector<Row>& rows, const std::string& costColumn,
                                         const std::string& errorColumn)
{
    std::vector<std::size_t> candidates;
    for (std::size_t i = 0; i < rows.size(); ++i)
        if (std::isfinite(getNumber(rows[i], costColumn)) && std::isfinite(getNumber(rows[i], errorColumn)))
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
