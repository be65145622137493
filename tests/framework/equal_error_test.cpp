// The report's equal-error comparison (report_detail.h computeEqualError, writeEqualErrorCsv):
// a run against its family's sampling baseline at the same error, on baselines whose error
// falls exactly as 1 / sqrt(time) (Monte Carlo), so the interpolated time has a closed form.

#include "report/report_detail.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace rtlab;
using namespace rtlab::report;

namespace {

detail::RunSummary makeRun(const std::string& id, const std::string& technique, double ms,
                           double rmse, const std::string& bounces = "2",
                           const std::string& spp = "")
{
    detail::RunSummary run;
    run.runId = id;
    run.technique = technique;
    run.number = {{"technique_ms", ms}, {"indirect.rmse", rmse}};
    experiment::Row row{{"reference.quantity", "indirect"},
                        {"reference.bounces", bounces},
                        {"reference.seconds", std::to_string(ms)}, // measured, not compared
                        {"reference.cpu_ms", std::to_string(2 * ms)}};
    if (!spp.empty())
        row["param.samples_per_pixel"] = spp;
    run.frames = {row};
    return run;
}

detail::Group makeGroup()
{
    detail::Group g;
    g.key = "voxel_gi_scene_320x180";
    g.family = "voxel_gi";
    g.columns.cost = "technique_ms";
    g.columns.error = "indirect.rmse";
    g.columns.baseline = "path_traced";
    g.varyingParams = {"param.samples_per_pixel"};
    // Path tracing at 1, 2, 4, 8 samples: 10 ms per sample, RMSE 0.4 / sqrt(samples).
    for (int spp : {1, 2, 4, 8})
        g.runs.push_back(makeRun("pt" + std::to_string(spp), "path_traced", 10.0 * spp,
                                 0.4 / std::sqrt(double(spp)), "2", std::to_string(spp)));
    // A dominated one (slower and less accurate than the 4-sample run): not on the front.
    g.runs.push_back(makeRun("pt_slow", "path_traced", 45.0, 0.25, "2", "4"));
    return g;
}

TEST(EqualError, InterpolatesTheBaselinesTimeInLogLogAndFindsTheCheapestRunReachingIt)
{
    detail::Group g = makeGroup();
    g.runs.push_back(
        makeRun("fast", "cascades", 2.0, 0.15)); // between 4 (0.2) and 8 (0.141) samples
    g.runs.push_back(makeRun("slow", "cascades", 20.0, 0.3)); // between 1 and 2 samples
    const auto rows = detail::computeEqualError(g);
    ASSERT_EQ(rows.size(), 2u);
    // Fastest speed-up first. The baseline's time at RMSE e: 10 ms (0.4 / e)^2.
    EXPECT_EQ(rows[0].run->runId, "fast");
    EXPECT_NEAR(rows[0].baselineTime, 10.0 * std::pow(0.4 / 0.15, 2.0), 1e-9);
    EXPECT_NEAR(rows[0].speedup, rows[0].baselineTime / 2.0, 1e-9);
    ASSERT_NE(rows[0].cheapest, nullptr);
    EXPECT_EQ(rows[0].cheapest->runId, "pt8");
    EXPECT_DOUBLE_EQ(rows[0].cheapestSpeedup, 40.0);
    EXPECT_TRUE(rows[0].note.empty());
    EXPECT_EQ(rows[1].run->runId, "slow");
    EXPECT_NEAR(rows[1].baselineTime, 10.0 * std::pow(0.4 / 0.3, 2.0), 1e-9);
    EXPECT_EQ(rows[1].cheapest->runId, "pt2");
}

TEST(EqualError, ARunAtABaselinesErrorTakesItsTime)
{
    detail::Group g = makeGroup();
    g.runs.push_back(makeRun("same", "cascades", 4.0, 0.2)); // exactly the 4-sample run's error
    const auto rows = detail::computeEqualError(g);
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_DOUBLE_EQ(rows[0].baselineTime, 40.0);
    EXPECT_DOUBLE_EQ(rows[0].speedup, 10.0);
    EXPECT_EQ(rows[0].cheapest->runId, "pt4");
}

TEST(EqualError, OutsideTheBaselinesRangeNothingIsExtrapolated)
{
    detail::Group g = makeGroup();
    g.runs.push_back(makeRun("worse", "cascades", 1.0, 0.5));   // above the 1-sample run's 0.4
    g.runs.push_back(makeRun("better", "cascades", 1.0, 0.05)); // below the 8-sample run's 0.141
    const auto rows = detail::computeEqualError(g);
    ASSERT_EQ(rows.size(), 2u);
    for (const auto& row : rows) {
        EXPECT_TRUE(std::isnan(row.baselineTime)) << row.run->runId;
        EXPECT_TRUE(std::isnan(row.speedup)) << row.run->runId;
        EXPECT_FALSE(row.note.empty()) << row.run->runId;
    }
    const auto& worse = rows[0].run->runId == "worse" ? rows[0] : rows[1];
    const auto& better = rows[0].run->runId == "worse" ? rows[1] : rows[0];
    ASSERT_NE(worse.cheapest, nullptr); // the 1-sample run already reaches 0.5
    EXPECT_EQ(worse.cheapest->runId, "pt1");
    EXPECT_DOUBLE_EQ(worse.cheapestSpeedup, 10.0);
    EXPECT_EQ(better.cheapest, nullptr);
    EXPECT_TRUE(std::isnan(better.cheapestSpeedup));
}

TEST(EqualError, OnlyBaselineRunsOfTheSameGroundTruthCount)
{
    detail::Group g = makeGroup();
    g.runs.push_back(makeRun("three_bounces", "cascades", 2.0, 0.15, "3"));
    g.runs.push_back(makeRun("no_error", "cascades", 2.0, NAN));
    EXPECT_TRUE(detail::computeEqualError(g).empty());
    g.columns.baseline.clear(); // a family without a baseline
    g.runs.push_back(makeRun("fast", "cascades", 2.0, 0.15));
    EXPECT_TRUE(detail::computeEqualError(g).empty());
}

TEST(EqualError, TheCsvHasARowPerRun)
{
    detail::Group g = makeGroup();
    g.runs.push_back(makeRun("fast", "cascades", 2.0, 0.15));
    g.runs.push_back(makeRun("worse", "cascades", 1.0, 0.5));
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_equal_error_test";
    std::filesystem::create_directories(dir);
    const std::string path =
        detail::writeEqualErrorCsv(dir.string(), {g}, {detail::computeEqualError(g)});
    std::ifstream in(path);
    std::string header, first, second, extra;
    std::getline(in, header);
    std::getline(in, first);
    std::getline(in, second);
    EXPECT_FALSE(std::getline(in, extra));
    EXPECT_EQ(header.rfind("group,run_id,technique,", 0), 0u);
    EXPECT_EQ(
        first.rfind("voxel_gi_scene_320x180,fast,cascades,,2,indirect.rmse,0.15,path_traced,", 0),
        0u)
        << first;
    EXPECT_NE(first.find(",pt8,samples_per_pixel=8,80,40,"), std::string::npos) << first;
    // The run outside the range: no interpolated time, a quoted note if it has a comma.
    EXPECT_NE(second.find("worse,cascades,,1,indirect.rmse,0.5,path_traced,,,pt1,"),
              std::string::npos)
        << second;
    std::filesystem::remove_all(dir);
}

} // namespace
