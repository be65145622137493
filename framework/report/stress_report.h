#pragma once
// The output of `rtlab stress`: the table, a heat map per family and a page.

#include "experiment/stress.h"

#include <string>
#include <vector>

namespace rtlab::report {

struct StressReportFiles {
    std::string csv;                   //!< <dir>/results.csv (and results.jsonl beside it)
    std::string html;                  //!< <dir>/stress.html
    std::vector<std::string> heatMaps; //!< <dir>/heatmap_<family>.png (and .pdf)
};

//! Writes `records` into `directory`, replacing an earlier stress table there: results.jsonl and
//! results.csv (experiment::makeStressRow), heatmap_<family>.png/.pdf (techniques x cases) and
//! stress.html (summary, heat maps, each family's case x technique table, the failures).
StressReportFiles writeStressReport(const std::vector<experiment::StressRecord>& records,
                                    const std::string& directory, const std::string& commandLine);

} // namespace rtlab::report
