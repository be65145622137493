#pragma once
// The figures and the HTML report of a study, made from its results folder alone (results.jsonl,
// manifest.json, the run images), so they can be remade at any time: `rtlab report <dir>`.
//
//   <dir>/plots/time_vs_error_<scene>.png|pdf   run time against error, Pareto front per technique
//   <dir>/plots/error_vs_<param>_<scene>.png|pdf error against each swept numeric parameter
//   <dir>/plots/time_vs_<error>_<scene>.png|pdf  the same for each further error column
//   <dir>/plots/convergence_<scene>.png|pdf     error against cell size with the fitted order
//                                               (isosurface studies sweeping the grid)
//   <dir>/plots/angles_<scene>.png|pdf          triangle-angle histogram per technique (isosurface)
//   <dir>/plots/pass_times_<scene>.png|pdf      stacked per-pass time of the front runs
//   <dir>/plots/images_<scene>.png|pdf          reference | each technique's best run | error maps,
//                                               with zoomed crops (screen-space families)
//   <dir>/runs/<id>/frame<k>/*.png               each run's output, reference and error heat map
//   <dir>/report.html                           one page: plots, image grids, tables, manifest

#include <string>
#include <utility>
#include <vector>

namespace rtlab::report {

//! Which columns a family's figures use.
struct FamilyColumns {
    std::string cost;       //!< e.g. "occlusion.gpu_ms"
    std::string costLabel;  //!< axis label with unit
    std::string error;      //!< e.g. "ao.rmse"
    std::string errorLabel;
    std::vector<std::string> passes;  //!< per-pass time columns, stacked in this order
    //! More error columns, each with its own time-against-error plot when the study has it.
    std::vector<std::pair<std::string, std::string>> extraErrors;  //!< (column, axis label)
    //! Further columns of the report's run tables (topology counts, masked errors, ...).
    std::vector<std::string> tableColumns;
};

//! The columns of a family ("occlusion", "isosurface", ...); throws rtlab::Error for a family
//! without report columns.
FamilyColumns getFamilyColumns(const std::string& family);

struct ReportSummary {
    std::vector<std::string> plots;  //!< PNG paths written
    std::string html;                //!< the report's path
};

//! Writes the plots and report.html of the study in `directory`. Throws rtlab::Error when the
//! folder has no results.
ReportSummary writeStudyReport(const std::string& directory);

} // namespace rtlab::report
