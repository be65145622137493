#pragma once
// The figures and the HTML report of a study, made from its results folder alone (results.jsonl,
// manifest.json, the run images), so they can be remade at any time: `rtlab report <dir>`.
//
//   <dir>/plots/time_vs_error_<scene>.png|pdf   run time against error, Pareto front per technique
//   <dir>/plots/error_vs_<param>_<scene>.png|pdf error against each swept numeric parameter
//   <dir>/plots/time_vs_<error>_<scene>.png|pdf  the same for each further error column
//   <dir>/plots/convergence_<scene>.png|pdf     error against cell size with the fitted order
//                                               (families that declare it, sweeping the grid)
//   <dir>/plots/<histogram>_<scene>.png|pdf     per-technique histograms a family declares
//   <dir>/plots/pass_times_<scene>.png|pdf      stacked per-pass time of the front runs
//   <dir>/plots/equal_error_<scene>.png|pdf     each run's speed-up against its family's sampling
//                                               baseline at the same error (equal_error.csv)
//   <dir>/plots/images_<scene>.png|pdf          reference | each technique's best run | error maps,
//                                               with zoomed crops (screen-space families)
//   <dir>/runs/<id>/frame<k>/*.png               each run's output, reference and error heat map
//   <dir>/equal_error.csv                       each run against its family's sampling baseline at
//                                               the same error (FamilyReport::baseline)
//   <dir>/report.html                           one page: plots, image grids, tables, manifest

#include "plugin/technique.h"

#include <string>
#include <utility>
#include <vector>

namespace rtlab::report {

//! Which columns a family's figures use: declared by the family (plugin::FamilyReport).
using FamilyColumns = plugin::FamilyReport;

//! The report columns of `family` (for a run of several families, "a+b", those of
//! the first that declares any); throws rtlab::Error for a family the registry does not know.
FamilyColumns getFamilyColumns(const plugin::Registry& registry, const std::string& family);

struct ReportSummary {
    std::vector<std::string> plots;  //!< PNG paths written
    std::string html;                //!< the report's path
    std::string equalError;          //!< equal_error.csv (the family baselines' speed-ups)
    int equalErrorRuns = 0;          //!< its rows: runs compared with a baseline
};

//! Writes the plots and report.html of the study in `directory`, with the figures and columns
//! each family of `registry` declares. Throws rtlab::Error when the folder has no results.
//! `timeFromFrame` > 0 overrides the experiment's report.time_from_frame for every run (the
//! time columns of a run of more frames average frames timeFromFrame and later only).
ReportSummary writeStudyReport(const std::string& directory, const plugin::Registry& registry,
                               int timeFromFrame = 0);

} // namespace rtlab::report
