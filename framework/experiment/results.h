#pragma once
// The tidy results table: one row per run, flat columns, stored as JSON lines (appended one
// complete line per run, so a crash loses at most the run in progress) and rewritten as CSV.

#include <cstdint>
#include <set>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace rtlab::experiment {

using Cell = std::variant<std::string, double, std::int64_t, bool>;

//! One row: ordered (column, value) pairs.
class ResultRow {
public:
    ResultRow& set(const std::string& column, Cell value);
    const std::vector<std::pair<std::string, Cell>>& cells() const { return mCells; }
    const Cell* find(const std::string& column) const;
    std::string toJson() const;

private:
    std::vector<std::pair<std::string, Cell>> mCells;
};

//! results.jsonl + results.csv in one folder.
class ResultsStore {
public:
    explicit ResultsStore(std::string directory);

    const std::string& directory() const { return mDirectory; }
    std::string jsonlPath() const { return mDirectory + "/results.jsonl"; }
    std::string csvPath() const { return mDirectory + "/results.csv"; }

    //! Config hashes of the rows whose status is "ok" (those runs are not recomputed).
    std::set<std::string> completedHashes() const;
    //! Appends one row as a single line and flushes it to disk before returning.
    void append(const ResultRow& row);
    //! Appends rows (e.g. every frame of a run) in one write, so a crash keeps all or none of
    //! them (up to a torn last line, which readers skip).
    void append(const std::vector<ResultRow>& rows);
    //! Rewrites results.csv from results.jsonl (union of columns in first-seen order), through a
    //! temporary file and a rename so that a reader never sees half a table. Returns row count.
    std::size_t writeCsv() const;
    //! Rows of results.jsonl as (column, text) pairs; lines that are not complete JSON objects
    //! (a crash mid-write) are skipped and counted in `skippedLines`.
    std::vector<std::vector<std::pair<std::string, std::string>>>
    readRows(std::size_t* skippedLines = nullptr) const;

private:
    std::string mDirectory;
};

} // namespace rtlab::experiment
