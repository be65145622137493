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
std::vector<std::size_t> findParetoFront(const std::vector<Row>& rows, const std::string& costColumn,
                                         const std::string& errorColumn);

} // namespace rtlab::experiment
