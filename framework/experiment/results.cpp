#include "experiment/results.h"

#include "core/error.h"
#include "core/json.h"
#include "core/strings.h"

#include <yaml-cpp/yaml.h>

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

namespace rtlab::experiment {

namespace {

std::string encodeCell(const Cell& cell)
{
    struct Visitor {
        std::string operator()(const std::string& s) const { return jsonEscape(s); }
        std::string operator()(double d) const { return jsonNumber(d); }
        std::string operator()(std::int64_t i) const { return std::to_string(i); }
        std::string operator()(bool b) const { return b ? "true" : "false"; }
    };
    return std::visit(Visitor{}, cell);
}

} // namespace

ResultRow& ResultRow::set(const std::string& column, Cell value)
{
    for (auto& [c, v] : mCells)
        if (c == column) {
            v = std::move(value);
            return *this;
        }
    mCells.emplace_back(column, std::move(value));
    return *this;
}

const Cell* ResultRow::find(const std::string& column) const
{
    for (const auto& [c, v] : mCells)
        if (c == column)
            return &v;
    return nullptr;
}

std::string ResultRow::toJson() const
{
    std::string s = "{";
    for (std::size_t i = 0; i < mCells.size(); ++i)
        s += (i ? "," : "") + jsonEscape(mCells[i].first) + ":" + encodeCell(mCells[i].second);
    return s + "}";
}

ResultsStore::ResultsStore(std::string directory) : mDirectory(std::move(directory))
{
    std::error_code ec;
    std::filesystem::create_directories(mDirectory, ec);
    if (ec)
        throw Error(mDirectory + ": cannot create output folder: " + ec.message());
}

std::vector<std::vector<std::pair<std::string, std::string>>>
ResultsStore::readRows(std::size_t* skippedLines) const
{
    std::vector<std::vector<std::pair<std::string, std::string>>> rows;
    std::size_t skipped = 0;
    std::ifstream in(jsonlPath());
    std::string line;
    while (std::getline(in, line)) {
        if (line.empty())
            continue;
        // A complete row is one JSON object on one line; a crash mid-write leaves a prefix.
        if (line.front() != '{' || line.back() != '}') {
            ++skipped;
            continue;
        }
        try {
            const YAML::Node node = YAML::Load(line);
            if (!node.IsMap()) {
                ++skipped;
                continue;
            }
            std::vector<std::pair<std::string, std::string>> row;
            for (const auto& kv : node)
                row.emplace_back(kv.first.Scalar(),
                                 kv.second.IsNull() ? std::string() : kv.second.Scalar());
            rows.push_back(std::move(row));
        } catch (const YAML::Exception&) {
            ++skipped;
        }
    }
    if (skippedLines)
        *skippedLines = skipped;
    return rows;
}

std::set<std::string> ResultsStore::completedHashes() const
{
    std::set<std::string> done;
    for (const auto& row : readRows()) {
        std::string hash, status;
        for (const auto& [k, v] : row) {
            if (k == "config_hash")
                hash = v;
            else if (k == "status")
                status = v;
        }
        if (status == "ok" && !hash.empty())
            done.insert(hash);
    }
    return done;
}

void ResultsStore::append(const ResultRow& row)
{
    append(std::vector<ResultRow>{row});
}

void ResultsStore::append(const std::vector<ResultRow>& rows)
{
    std::string line;
    for (const auto& row : rows)
        line += row.toJson() + "\n";
    const int fd = ::open(jsonlPath().c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
        throw Error(jsonlPath() + ": cannot open for appending");
    // A run killed mid-write leaves a torn last line without its newline: start on a new line so
    // the torn fragment stays a separate (ignored) line instead of corrupting this row.
    if (const off_t size = ::lseek(fd, 0, SEEK_END); size > 0) {
        char last = '\n';
        if (::pread(fd, &last, 1, size - 1) == 1 && last != '\n')
            line.insert(line.begin(), '\n');
    }
    // One write() of the whole line: concurrent or interrupted writers never interleave rows.
    const ssize_t written = ::write(fd, line.data(), line.size());
    ::fsync(fd);
    ::close(fd);
    if (written != ssize_t(line.size()))
        throw Error(jsonlPath() + ": short write");
}

std::size_t ResultsStore::writeCsv() const
{
    const auto rows = readRows();
    std::vector<std::string> columns;
    std::map<std::string, std::size_t> index;
    for (const auto& row : rows)
        for (const auto& [k, v] : row)
            if (index.emplace(k, columns.size()).second)
                columns.push_back(k);
    const std::string tmp = csvPath() + ".tmp";
    {
        std::ofstream out(tmp, std::ios::trunc);
        if (!out)
            throw Error(tmp + ": cannot open for writing");
        for (std::size_t i = 0; i < columns.size(); ++i)
            out << (i ? "," : "") << quoteCsvField(columns[i]);
        out << "\n";
        for (const auto& row : rows) {
            std::vector<std::string> cells(columns.size());
            for (const auto& [k, v] : row)
                cells[index[k]] = v;
            for (std::size_t i = 0; i < cells.size(); ++i)
                out << (i ? "," : "") << quoteCsvField(cells[i]);
            out << "\n";
        }
        if (!out)
            throw Error(tmp + ": write failed");
    }
    std::filesystem::rename(tmp, csvPath());
    return rows.size();
}

} // namespace rtlab::experiment
