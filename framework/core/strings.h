#pragma once
// Small string helpers shared by config validation, the CLI and reports.

#include <string>
#include <string_view>
#include <vector>

namespace rtlab {

//! Levenshtein edit distance (insert, delete, substitute; each costs 1).
std::size_t editDistance(std::string_view a, std::string_view b);

//! The candidates closest to `name` by edit distance (at most `maxCount`, and only those within
//! a distance that makes them plausible typos: <= max(2, |name| / 3)). Best first.
std::vector<std::string> closestNames(std::string_view name, const std::vector<std::string>& candidates,
                                      std::size_t maxCount = 3);

//! "a, b, c" or "a, b or c" (conjunction = "or").
std::string joinList(const std::vector<std::string>& items, std::string_view conjunction = "");

//! A CSV field (RFC 4180): as it is, or in double quotes with inner quotes doubled where it holds
//! a comma, a quote or a newline.
std::string quoteCsvField(const std::string& text);

//! Read a whole file; throws rtlab::InputError naming the path when it cannot be read.
std::string readTextFile(const std::string& path);

//! Writes `text` to path + ".tmp" and renames it to `path`, so that a reader never sees a half
//! written file; throws rtlab::Error naming the path when it cannot be written.
void writeTextFileAtomically(const std::string& path, const std::string& text);

} // namespace rtlab
