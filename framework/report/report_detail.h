#pragma once
// Internal to the report module: the study's rows grouped the way the figures need them.

#include "report/report.h"

#include "experiment/analysis.h"
#include "plot/color.h"

#include <map>
#include <string>
#include <vector>

namespace rtlab::plot {
struct StackedBarSpec;
}

namespace rtlab::report::detail {

//! `s` with &, <, >, " escaped for HTML text and attributes.
std::string escapeHtml(const std::string& s);
//! `v` with `precision` significant digits; empty for NaN and infinities (an empty table cell).
std::string formatNumber(double v, int precision = 4);
//! The doctype, head (title, the reports' style sheet) and the opening body tag of a page.
std::string getPageHead(const std::string& title);

//! One run: its rows (one per frame) averaged column by column where numeric.
struct RunSummary {
    std::string runId;
    std::string technique;
    std::map<std::string, std::string> text;  //!< non-numeric columns of the first frame
    std::map<std::string, double> number;     //!< numeric columns, mean over frames
    //! > 0 where the time columns (`*_ms`) average frames timeFromFrame and later only (the
    //! experiment's report.time_from_frame, for a run of more frames than that).
    int timeFromFrame = 0;
    std::vector<experiment::Row> frames;
    double get(const std::string& column) const;
};

//! Runs of one family on one scene (and image size): one figure each.
struct Group {
    std::string key;    //!< file-name friendly: "ao_testbed_320x180"
    std::string title;  //!< "ao_testbed, 320x180"
    std::string family;
    FamilyColumns columns; //!< what the family declares for its figures
    std::vector<RunSummary> runs;
    std::vector<std::string> varyingParams;  //!< param.* columns and "grid" with more than one value
    std::map<std::string, std::string> paramUnits; //!< param.* column -> its schema's unit, where it has one
};

std::vector<Group> groupRuns(const std::vector<experiment::Row>& rows, const plugin::Registry& registry);
//! "directions=36 steps=4" from the varying parameters of a run.
std::string describeRun(const RunSummary& run, const std::vector<std::string>& varyingParams);

//! The lines of one of `family`'s across-scenes figures: one per technique, split by the
//! figure's seriesBy columns where a run has them ("adaptive_voxel_tree (anti_leak=false)");
//! each line maps x to the mean y of its runs there (runs without finite x and y are left out).
std::map<std::string, std::map<double, double>>
collectAcrossScenesLines(const std::vector<Group>& groups, const std::string& family,
                         const plugin::AcrossScenesFigure& spec);

//! One line of an "error against a parameter" figure: a technique's runs that share every other
//! varying parameter (they differ in the plotted one alone), the mean error at each value.
struct MatchedLine {
    std::string technique;
    std::string label;   //!< the technique, then the other parameters that differ among its lines
    int variant = 0;     //!< 0, 1, ... within the technique (plot::Series::variant)
    std::map<double, double> points;
};
struct MatchedLines {
    std::vector<MatchedLine> lines;
    std::size_t leftOut = 0; //!< settings with two or more values beyond maxLinesPerTechnique
};
//! The matched lines of `param` against `errorColumn` for each technique of `runs` (in order):
//! settings of the other `varyingParams` with at least two finite values of `param`, those with
//! the most values first, at most maxLinesPerTechnique per technique.
MatchedLines collectMatchedLines(const std::vector<RunSummary>& runs, const std::string& param,
                                 const std::string& errorColumn, const std::vector<std::string>& varyingParams,
                                 std::size_t maxLinesPerTechnique);

//! A run against the family's sampling baseline (FamilyReport::baseline) at equal error: the
//! baseline's time at the run's error, from the baseline runs of the same group that measure
//! the same ground truth (equal `reference.*` settings: quantity, radius, bounces, ...).
struct EqualErrorRow {
    const RunSummary* run = nullptr;
    double time = 0.0, error = 0.0; //!< the run's cost and error columns
    //! The baseline's time at `error`: log time interpolated linearly in log error between the
    //! two runs of the baseline's Pareto front that bracket it; NaN outside the front.
    double baselineTime = 0.0;
    double speedup = 0.0; //!< baselineTime / time
    //! The cheapest baseline run whose error is at most `error` (null for none) and its time over
    //! the run's: a speed-up the discrete sample counts can only overstate.
    const RunSummary* cheapest = nullptr;
    double cheapestSpeedup = 0.0;
    std::string note; //!< why baselineTime is NaN, else empty
};
//! Every run of `group` that is not the baseline and has a finite, positive time and error,
//! fastest speed-up first (NaN speed-ups last); empty without baseline runs.
std::vector<EqualErrorRow> computeEqualError(const Group& group);
//! A run's varying parameters, with its camera path and frame count where the group's runs
//! differ in them (the equal-error table's "parameters").
std::string describeEqualErrorRun(const RunSummary& run, const Group& group);
//! directory/equal_error.csv: `equal[i]` (computeEqualError of groups[i]) for every group, one
//! line per row (a header only when no group has baseline runs). Returns its path.
std::string writeEqualErrorCsv(const std::string& directory, const std::vector<Group>& groups,
                               const std::vector<std::vector<EqualErrorRow>>& equal);

struct Figures {
    std::vector<std::string> plots;     //!< paths without extension
    std::vector<std::string> captions;  //!< one per plot
    std::vector<std::string> notes;     //!< one line per chart left out (no finite value to draw)
};

//! Writes every figure of `group` under directory/plots (with `equal`, its computeEqualError
//! rows, the speed-up chart); returns them with captions.
Figures writeGroupFigures(const Group& group, const std::vector<EqualErrorRow>& equal,
                          const std::string& directory, const std::vector<std::string>& techniques);

//! `s` with every character but letters, digits, '_' and '-' replaced by '_'.
std::string makeFileName(std::string s);

//! The lit frame's figures of `group` (runs with frame.rmse), or none.
//! Bar labels that do not fit under their bars become numbers; returns the key for the caption
//! (" Bars: 1 = ...; 2 = ..."), empty when they fit.
std::string numberBarsThatDoNotFit(plot::StackedBarSpec& bars);

Figures writeLitFrameFigures(const Group& group, const std::string& directory, const plot::ColorTable& colors);

//! technique.png, reference.png and error.png (|error| through viridis over [0, errorRange])
//! beside every run frame's EXRs that lacks them; returns how many frames were written.
int writeRunImages(const std::vector<experiment::Row>& rows, float errorRange);

//! A run frame's images: the technique's output, its reference and the signed error (EXR paths).
//! Families name them image.technique / image.reference / image.error, or, for a family that
//! measures a named quantity q, image.q / image.q_reference / image.q_error (voxel_gi:
//! image.indirect). All empty when the frame has no such triple.
struct RunImages {
    std::string technique, reference, error;
    bool valid() const { return !technique.empty(); }
};
RunImages findRunImages(const experiment::Row& row);

//! The HTML page; `equal[i]` and `figures[i]` belong to groups[i].
void writeHtml(const std::string& directory, const std::vector<Group>& groups,
               const std::vector<std::vector<EqualErrorRow>>& equal,
               const std::vector<Figures>& figures, const std::string& manifestJson);

} // namespace rtlab::report::detail
