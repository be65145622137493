// The lines of a family's across-scenes figure (report_detail.h collectAcrossScenesLines): one
// per technique, split by the figure's seriesBy columns, runs at the same x averaged, runs of
// other families and runs without finite x or y left out.

#include "report/report_detail.h"

#include "plugin/technique.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace rtlab;
using namespace rtlab::report;

namespace {

detail::RunSummary makeRun(const std::string& technique, double x, double y,
                           const std::string& antiLeak = "")
{
    detail::RunSummary run;
    run.technique = technique;
    run.number = {{"scene.wall_voxels", x}, {"indirect.mean_signed_error", y}};
    experiment::Row row{{"scene.wall_voxels", std::to_string(x)}};
    if (!antiLeak.empty())
        row["param.anti_leak"] = antiLeak;
    run.frames = {row};
    return run;
}

TEST(ReportLines, SplitByTheDeclaredColumnsAndAveraged)
{
    detail::Group voxel;
    voxel.family = "voxel_gi";
    voxel.runs = {makeRun("cascades", 1, 1.2), makeRun("cascades", 1, 1.0), makeRun("cascades", 2, 0.6),
                  makeRun("tree", 1, 0.02, "true"), makeRun("tree", 1, 0.09, "false"),
                  makeRun("tree", 2, 0.0, "true"), makeRun("tree", 2, NAN, "false")};
    detail::Group other;
    other.family = "occlusion";
    other.runs = {makeRun("gtao", 1, 5.0)};
    plugin::AcrossScenesFigure spec{.x = "scene.wall_voxels", .y = "indirect.mean_signed_error"};
    spec.seriesBy = {"param.anti_leak"};

    const auto lines = detail::collectAcrossScenesLines({voxel, other}, "voxel_gi", spec);
    ASSERT_EQ(lines.size(), 3u);
    EXPECT_DOUBLE_EQ(lines.at("cascades").at(1.0), 1.1);
    EXPECT_DOUBLE_EQ(lines.at("cascades").at(2.0), 0.6);
    EXPECT_DOUBLE_EQ(lines.at("tree (anti_leak=true)").at(1.0), 0.02);
    EXPECT_DOUBLE_EQ(lines.at("tree (anti_leak=true)").at(2.0), 0.0);
    EXPECT_EQ(lines.at("tree (anti_leak=false)").size(), 1u); // the NaN run is left out

    spec.seriesBy.clear(); // without a split the tree's runs at one x are averaged
    const auto merged = detail::collectAcrossScenesLines({voxel}, "voxel_gi", spec);
    ASSERT_EQ(merged.size(), 2u);
    EXPECT_DOUBLE_EQ(merged.at("tree").at(1.0), 0.055);
}

detail::RunSummary makeSweepRun(const std::string& technique, double levels, double noise, double rmse)
{
    detail::RunSummary run;
    run.technique = technique;
    run.number = {{"param.levels", levels}, {"param.noise", noise}, {"rmse", rmse}};
    run.frames = {experiment::Row{{"param.levels", std::to_string(int(levels))},
                                  {"param.noise", std::to_string(noise)}}};
    return run;
}

// "Error against a parameter" lines compare runs that differ in that parameter alone: a value swept
// in one variant only is not set against the mean of every other run.
TEST(ReportLines, ErrorAgainstAParameterUsesMatchedRunsOnly)
{
    const std::vector<std::string> varying = {"param.levels", "param.noise"};
    // levels swept at noise 0; noise swept (0.1, 0.2) at levels 6 only, where its 0 is the run
    // (levels 6, noise 0). The runs at levels 4 and 8 must not enter the noise = 0 point.
    const std::vector<detail::RunSummary> runs = {
        makeSweepRun("cascades", 4, 0.0, 0.30), makeSweepRun("cascades", 6, 0.0, 0.12),
        makeSweepRun("cascades", 8, 0.0, 0.10), makeSweepRun("cascades", 6, 0.1, 0.11),
        makeSweepRun("cascades", 6, 0.2, 0.13), makeSweepRun("svo", 4, 0.0, 0.2),
        makeSweepRun("svo", 4, 0.1, NAN)};
    const detail::MatchedLines noise = detail::collectMatchedLines(runs, "param.noise", "rmse", varying, 5);
    ASSERT_EQ(noise.lines.size(), 1u); // svo has one finite noise value: no line
    EXPECT_EQ(noise.lines[0].label, "cascades");
    ASSERT_EQ(noise.lines[0].points.size(), 3u);
    EXPECT_DOUBLE_EQ(noise.lines[0].points.at(0.0), 0.12); // not (0.30 + 0.12 + 0.10) / 3
    EXPECT_DOUBLE_EQ(noise.lines[0].points.at(0.2), 0.13);

    // levels: one line at noise 0 (three values); the noise 0.1 and 0.2 settings have one value each.
    const detail::MatchedLines levels = detail::collectMatchedLines(runs, "param.levels", "rmse", varying, 5);
    ASSERT_EQ(levels.lines.size(), 1u);
    EXPECT_EQ(levels.lines[0].points.size(), 3u);

    // Two settings with two or more values: two lines, told apart by label and variant; with room
    // for one line only the one with more values stays and the other is counted as left out.
    std::vector<detail::RunSummary> more = runs;
    more.push_back(makeSweepRun("cascades", 4, 0.1, 0.25));
    const detail::MatchedLines two = detail::collectMatchedLines(more, "param.levels", "rmse", varying, 5);
    ASSERT_EQ(two.lines.size(), 2u);
    EXPECT_EQ(two.lines[0].label, "cascades noise=0.000000");
    EXPECT_EQ(two.lines[0].variant, 0);
    EXPECT_EQ(two.lines[1].label, "cascades noise=0.100000");
    EXPECT_EQ(two.lines[1].variant, 1);
    const detail::MatchedLines one = detail::collectMatchedLines(more, "param.levels", "rmse", varying, 1);
    ASSERT_EQ(one.lines.size(), 1u);
    EXPECT_EQ(one.lines[0].points.size(), 3u);
    EXPECT_EQ(one.leftOut, 1u);
}

// A further error column without a finite value in the group (edge-Chamfer on a sphere) gives no
// empty chart but a one-line note; a column with values gives its chart.
TEST(ReportLines, AnErrorColumnWithoutValuesIsANoteNotAnEmptyChart)
{
    detail::Group group;
    group.key = "sphere_64";
    group.title = "sphere, 64";
    group.family = "isosurface";
    group.columns.cost = "t";
    group.columns.costLabel = "time (ms)";
    group.columns.error = "chamfer";
    group.columns.errorLabel = "Chamfer distance (world units)";
    group.columns.extraErrors = {{"edge", "edge-Chamfer distance (world units)"},
                                 {"hausdorff", "Hausdorff distance (world units)"}};
    for (int i = 0; i < 3; ++i) {
        detail::RunSummary run;
        run.runId = "run" + std::to_string(i);
        run.technique = "marching_cubes";
        run.number = {{"t", 1.0 + i}, {"chamfer", 0.1 / (1 + i)}, {"edge", NAN}, {"hausdorff", 0.3 / (1 + i)}};
        run.frames = {experiment::Row{{"t", "1"}}};
        group.runs.push_back(run);
    }
    const std::string directory = ::testing::TempDir() + "/report_notes";
    const detail::Figures figures =
        detail::writeGroupFigures(group, {}, directory, {"marching_cubes"});
    ASSERT_EQ(figures.notes.size(), 1u);
    EXPECT_NE(figures.notes[0].find("edge-Chamfer"), std::string::npos) << figures.notes[0];
    bool edgeChart = false, hausdorffChart = false;
    for (const std::string& plot : figures.plots) {
        edgeChart = edgeChart || plot.find("time_vs_edge") != std::string::npos;
        hausdorffChart = hausdorffChart || plot.find("time_vs_hausdorff") != std::string::npos;
    }
    EXPECT_FALSE(edgeChart);
    EXPECT_TRUE(hausdorffChart);
}

TEST(ReportRuns, TimeColumnsLeaveOutTheFramesBeforeTheExperimentsTimeFromFrame)
{
    // report: {time_from_frame: 1}: a run of 3 frames averages its *_ms columns over frames 1
    // and 2 (frame 0 built everything), its errors over all three; a run of one frame keeps it.
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    const auto row = [](const std::string& id, int frame, double ms, double rmse, bool setting) {
        experiment::Row r{{"status", "ok"},
                          {"run_id", id},
                          {"family", "voxel_gi"},
                          {"technique", "cascades"},
                          {"scene", "room"},
                          {"width", "32"},
                          {"height", "18"},
                          {"frame", std::to_string(frame)},
                          {"technique_ms", std::to_string(ms)},
                          {"voxelize.cpu_ms", frame == 0 ? "800" : ""},
                          {"indirect.rmse", std::to_string(rmse)}};
        if (setting)
            r["report.time_from_frame"] = "1";
        return r;
    };
    const std::vector<experiment::Row> rows = {
        row("moving", 0, 900, 0.2, true), row("moving", 1, 10, 0.1, true),
        row("moving", 2, 20, 0.3, true),  row("single", 0, 50, 0.4, true),
        row("plain", 0, 900, 0.2, false), row("plain", 1, 10, 0.1, false)};
    const std::vector<detail::Group> groups = detail::groupRuns(rows, registry);
    ASSERT_EQ(groups.size(), 1u);
    const auto& runs = groups[0].runs;
    ASSERT_EQ(runs.size(), 3u);
    EXPECT_DOUBLE_EQ(runs[0].get("technique_ms"), 15.0);
    EXPECT_TRUE(std::isnan(runs[0].get("voxelize.cpu_ms"))) << "the pass ran in frame 0 only";
    EXPECT_NEAR(runs[0].get("indirect.rmse"), 0.2, 1e-12);
    EXPECT_EQ(runs[0].timeFromFrame, 1);
    EXPECT_DOUBLE_EQ(runs[1].get("technique_ms"), 50.0) << "a run of one frame keeps it";
    EXPECT_EQ(runs[1].timeFromFrame, 0);
    EXPECT_DOUBLE_EQ(runs[2].get("technique_ms"), 455.0)
        << "without the setting every frame counts";
    EXPECT_NE(groups[0].columns.costLabel.find("frames 1 and later"), std::string::npos)
        << groups[0].columns.costLabel;
}

} // namespace
