#pragma once
// Questions a researcher asks of a results table: which runs are Pareto-optimal in time and
// error, which is the most accurate under a time budget.

#include <map>
#include <string>
#include <vector>

namespace rtlab::experiment {

//! One row of a results table as column -> text (what ResultsStore::readRows gives).
using Row = std::map<std::string, std::string>;

//! Rows of results.jsonl in `directory` as maps (torn lines skipped).
std::vector<Row> loadResults(const std::string& directory);

//! The number in `column`, or NaN when the row lacks it or it is not a number.
double getNumber(const Row& row, const std::string& column);

//! Indices of the rows on the Pareto front of (cost, error), both minimised, ordered by cost.
//! Rows where either value is not finite are ignored. A row is on the front when no other row
//! is at least as good in both and strictly better in one.
std::vector<std::size_t> findParetoFront(const std::vector<Row>& rows,
                                         const std::string& costColumn,
                                         const std::string& errorColumn);

} // namespace rtlab::experiment

namespace rtlab::experiment {

//! The answer to "which run is best under a constraint".
struct BestQuery {
    std::string costColumn = "extract.cpu_ms"; //!< minimised under --max-error
    std::string errorColumn = "rms_deviation"; //!< minimised under --max-time
    double maxCost = -1.0;                     //!< >= 0: lowest error with cost <= maxCost
    double maxError = -1.0;                    //!< >= 0: lowest cost with error <= maxError
};

//! Index of the best ok row for the query, or -1 when no row satisfies the bound. Ties go to
//! the other column (lower error among equal cost, and the reverse).
long findBest(const std::vector<Row>& rows, const BestQuery& query);

//! "5ms", "0.5 s", "250us", "2" (milliseconds when no unit) -> milliseconds; throws
//! std::invalid_argument with the accepted forms otherwise.
double parseDurationMs(const std::string& text);

} // namespace rtlab::experiment
