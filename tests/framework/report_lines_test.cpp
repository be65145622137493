// The lines of a family's across-scenes figure (report_detail.h collectAcrossScenesLines): one
// per technique, split by the figure's seriesBy columns, runs at the same x averaged, runs of
// other families and runs without finite x or y left out.

#include "report/report_detail.h"

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

} // namespace
