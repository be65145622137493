#include "plot/charts.h"
#include "plot/figure.h"

#include "core/error.h"
#include "experiment/analysis.h"
#include "plot_test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>

using namespace rtlab::plot;
namespace experiment = rtlab::experiment;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::vector<experiment::Row> makeRows(const std::vector<double>& x, const std::vector<double>& y)
{
    std::vector<experiment::Row> rows;
    for (std::size_t i = 0; i < x.size(); ++i) {
        experiment::Row row;
        if (std::isfinite(x[i]))
            row["gpu_ms"] = std::to_string(x[i]);
        if (std::isfinite(y[i]))
            row["rmse"] = std::to_string(y[i]);
        rows.push_back(row);
    }
    return rows;
}

//! Values that print and parse back exactly through std::to_string (6 decimals).
double roundTo6(double v)
{
    return std::round(v * 1e6) / 1e6;
}

bool contains(const std::vector<std::string>& strings, const std::string& s)
{
    for (const auto& t : strings)
        if (t.find(s) != std::string::npos)
            return true;
    return false;
}

//! The checks every chart writer must pass: a PNG of the requested size with content, and a
//! vector PDF whose text carries `labels`.
void expectChartFiles(const std::string& base, const FigureSize& size,
                      const std::vector<std::string>& labels)
{
    const test::Pixels png = test::readPng(base + ".png");
    EXPECT_EQ(png.width, size.width);
    EXPECT_EQ(png.height, size.height);
    EXPECT_GT(png.countDistinct(), 10u) << "the PNG is (nearly) one colour";

    const std::string pdf = test::readBytes(base + ".pdf");
    ASSERT_GE(pdf.size(), 5u);
    EXPECT_EQ(pdf.substr(0, 5), "%PDF-");
    EXPECT_EQ(pdf.find("/Subtype /Image"), std::string::npos) << "a chart PDF holds no raster";
    const std::string content = test::readPdfContent(base + ".pdf");
    EXPECT_NE(content.find(" re"), std::string::npos) << "no rectangles drawn as paths";
    EXPECT_NE(content.find(" l\n"), std::string::npos) << "no lines drawn as paths";
    const auto strings = test::extractPdfStrings(content);
    for (const auto& label : labels)
        EXPECT_TRUE(contains(strings, label)) << "'" << label << "' is not text in the PDF";
}

class ChartTest : public ::testing::Test {
protected:
    void SetUp() override { ::unsetenv("DISPLAY"); } // the writers must start their own Xvfb
};

ScatterSpec makeAoScatter()
{
    ScatterSpec spec;
    spec.title = "Ambient occlusion: time against error";
    spec.xLabel = "GPU time (ms)";
    spec.yLabel = "RMSE (AO, unitless)";
    spec.series = {
        {"ssao",
         {0.4, 0.7, 1.1, 1.6, 0.9},
         {0.11, 0.08, 0.065, 0.06, 0.09},
         {"4 spp", "8 spp", "16 spp", "32 spp", "8 spp blur"}},
        {"hbao",
         {0.6, 1.0, 1.9, 1.2},
         {0.07, 0.05, 0.041, 0.06},
         {"4 dirs", "8 dirs", "16 dirs", "8 dirs wide"}},
        {"rtao", {3.0, 6.5, 14.0}, {0.03, 0.015, 0.008}, {"1 spp", "4 spp", "16 spp"}},
    };
    spec.colors = ColorTable({"hbao", "rtao", "ssao"});
    return spec;
}

} // namespace

TEST(ParetoTest, FrontMatchesTheResultsAnalysis)
{
    // Ties in cost, a duplicate, NaN on either side, a dominated point in between.
    const std::vector<double> x = {5, 1, 3, 3, 2, kNaN, 4, 1, 6, 2, 7};
    const std::vector<double> y = {0.5, 4, 2, 1, 3, 0.1, 1, 4, kNaN, 2.5, 0.5};
    const auto expected = experiment::findParetoFront(makeRows(x, y), "gpu_ms", "rmse");
    EXPECT_EQ(findParetoFront(x, y), expected);
    EXPECT_EQ(expected, (std::vector<std::size_t>{1, 9, 3, 0}));
}

TEST(ParetoTest, FrontMatchesTheResultsAnalysisOnRandomSets)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> value(0.01, 10.0);
    std::uniform_int_distribution<int> coarse(1, 5);
    for (int trial = 0; trial < 200; ++trial) {
        const std::size_t n = 1 + trial % 40;
        std::vector<double> x(n), y(n);
        for (std::size_t i = 0; i < n; ++i) {
            // Half the trials on a coarse grid, so that ties are common.
            x[i] = trial % 2 ? roundTo6(value(rng)) : coarse(rng);
            y[i] = trial % 2 ? roundTo6(value(rng)) : coarse(rng);
        }
        ASSERT_EQ(findParetoFront(x, y),
                  experiment::findParetoFront(makeRows(x, y), "gpu_ms", "rmse"))
            << "trial " << trial;
    }
}

TEST(ParetoTest, DrawnFrontsAreTheAnalysisFrontsAsStaircases)
{
    const ScatterSpec spec = makeAoScatter();
    const auto fronts = computeParetoFronts(spec);
    ASSERT_EQ(fronts.size(), spec.series.size());
    for (const auto& front : fronts) {
        const Series& series = spec.series[front.seriesIndex];
        EXPECT_EQ(front.label, series.label);
        EXPECT_EQ(front.pointIndices,
                  experiment::findParetoFront(makeRows(series.x, series.y), "gpu_ms", "rmse"));
        // Staircase: point, then alternately across to the next cost and down to its error.
        ASSERT_EQ(front.stepX.size(), 2 * front.pointIndices.size() - 1);
        for (std::size_t k = 0; k < front.pointIndices.size(); ++k) {
            EXPECT_EQ(front.stepX[2 * k], series.x[front.pointIndices[k]]);
            EXPECT_EQ(front.stepY[2 * k], series.y[front.pointIndices[k]]);
            if (k > 0) {
                EXPECT_EQ(front.stepX[2 * k - 1], front.stepX[2 * k]);
                EXPECT_EQ(front.stepY[2 * k - 1], front.stepY[2 * k - 2]);
            }
        }
    }
    EXPECT_EQ(fronts[0].pointIndices, (std::vector<std::size_t>{0, 1, 2, 3})); // ssao, not 4
    EXPECT_EQ(fronts[1].pointIndices, (std::vector<std::size_t>{0, 1, 2}));    // hbao, not 3
}

TEST(ParetoTest, PointsALogAxisCannotShowAreNotOnTheFront)
{
    ScatterSpec spec;
    spec.xScale = AxisScale::Log;
    spec.series = {{"a", {0.0, 1.0, 2.0}, {0.1, 0.5, 0.2}, {}}};
    const auto fronts = computeParetoFronts(spec);
    ASSERT_EQ(fronts.size(), 1u);
    EXPECT_EQ(fronts[0].pointIndices, (std::vector<std::size_t>{1, 2}));
    spec.xScale = AxisScale::Linear;
    EXPECT_EQ(computeParetoFronts(spec)[0].pointIndices, (std::vector<std::size_t>{0}));
}

TEST(AxisTest, AutomaticScaleIsLogWhenValuesSpanADecade)
{
    EXPECT_TRUE(isLogAxis(AxisScale::Automatic, {0.1, 0.3, 1.0}));
    EXPECT_FALSE(isLogAxis(AxisScale::Automatic, {0.2, 0.3, 1.9}));
    EXPECT_FALSE(isLogAxis(AxisScale::Automatic, {0.0, 0.001, 10.0})); // zero cannot be shown
    EXPECT_TRUE(isLogAxis(AxisScale::Automatic, {kNaN, 0.01, 1.0}));
    EXPECT_TRUE(isLogAxis(AxisScale::Log, {1.0, 2.0}));
    EXPECT_FALSE(isLogAxis(AxisScale::Linear, {0.001, 1000.0}));
}

TEST_F(ChartTest, ScatterWritesPngAndVectorPdf)
{
    const ScatterSpec spec = makeAoScatter();
    const std::string base = test::makeTempDir("scatter") + "/time_vs_error";
    writeScatter(spec, base);
    expectChartFiles(base, spec.size,
                     {spec.title, spec.xLabel, spec.yLabel, "ssao", "hbao", "rtao", "16 spp"});
}

TEST_F(ChartTest, ScatterColoursAreStableAcrossSeriesOrders)
{
    ScatterSpec forward = makeAoScatter();
    ScatterSpec backward = forward;
    std::reverse(backward.series.begin(), backward.series.end());
    const std::string dir = test::makeTempDir("order");
    writeScatter(forward, dir + "/forward");
    writeScatter(backward, dir + "/backward");
    const test::Pixels a = test::readPng(dir + "/forward.png");
    const test::Pixels b = test::readPng(dir + "/backward.png");
    ColorTable table = forward.colors;
    for (const char* name : {"hbao", "rtao", "ssao"}) {
        const Color c = table.getColor(name);
        // Opaque markers and the legend swatch show the exact colour.
        EXPECT_GT(a.count(c), 30u) << name << " " << c.toHex();
        EXPECT_GT(b.count(c), 30u) << name << " " << c.toHex();
    }
    EXPECT_EQ(getSeriesColors(forward.series, forward.colors)[0],
              getSeriesColors(backward.series, backward.colors)[2]);
}

TEST_F(ChartTest, LineChartWritesPngAndVectorPdf)
{
    LineSpec spec;
    spec.title = "Error against sample count";
    spec.xLabel = "samples per pixel";
    spec.yLabel = "RMSE (AO, unitless)";
    spec.series = {{"ssao", {32, 4, 8, 16}, {0.06, 0.11, 0.08, 0.065}, {}},
                   {"rtao", {1, 4, 16, 64}, {0.03, 0.015, 0.008, 0.004}, {}}};
    spec.size = {800, 500};
    const std::string base = test::makeTempDir("line") + "/error_vs_spp";
    writeLineChart(spec, base);
    expectChartFiles(base, spec.size, {spec.title, spec.xLabel, spec.yLabel, "ssao", "rtao"});
}

// Two configurations of one technique share its colour; the second is dashed with square markers.
TEST_F(ChartTest, ConfigurationsOfOneTechniqueDifferInLineAndMarker)
{
    EXPECT_EQ(getVariantStyle(0).lineType, 1); // solid
    for (int a = 0; a < 5; ++a)
        for (int b = a + 1; b < 5; ++b) {
            EXPECT_NE(getVariantStyle(a).lineType, getVariantStyle(b).lineType) << a << " " << b;
            EXPECT_NE(getVariantStyle(a).marker, getVariantStyle(b).marker) << a << " " << b;
        }
    LineSpec spec;
    spec.title = "Convergence";
    spec.xLabel = "cell size h (world units)";
    spec.yLabel = "Chamfer distance (world units)";
    spec.series = {{"dc linear", {0.1, 0.05, 0.025}, {0.01, 0.005, 0.0025}, {}, 0},
                   {"dc midpoint", {0.1, 0.05, 0.025}, {0.02, 0.01, 0.005}, {}, 1}};
    spec.colors.setColor("dc linear", Color{200, 30, 30});
    spec.colors.setColor("dc midpoint", Color{200, 30, 30});
    const std::string dir = test::makeTempDir("variants");
    writeLineChart(spec, dir + "/two");
    expectChartFiles(dir + "/two", spec.size, {"dc linear", "dc midpoint"});
    // The PDF sets a dash pattern (operator d with a non-empty array) only for the second line.
    const std::string withDash = test::readPdfContent(dir + "/two.pdf");
    spec.series[1].variant = 0;
    writeLineChart(spec, dir + "/same");
    const std::string withoutDash = test::readPdfContent(dir + "/same.pdf");
    const auto countDashes = [](const std::string& content) {
        std::size_t n = 0;
        for (std::size_t at = content.find("] "); at != std::string::npos; at = content.find("] ", at + 1)) {
            const std::size_t open = content.rfind('[', at);
            const std::size_t end = content.find('d', at);
            if (open != std::string::npos && at > open + 1 && end != std::string::npos && end < at + 12 &&
                content.find_first_not_of("0123456789. ", at + 2) == end)
                ++n;
        }
        return n;
    };
    EXPECT_GT(countDashes(withDash), countDashes(withoutDash));
}

// A legend with long labels widens the figure instead of squeezing the plot area.
TEST_F(ChartTest, LongLegendLabelsWidenTheFigure)
{
    LineSpec spec;
    spec.title = "voxel_gi: tomorrow_town, 320x180: error against resolution, over runs that differ in "
                 "resolution alone, one line per setting of the other swept parameters";
    spec.xLabel = "resolution (voxels per axis)";
    spec.yLabel = "RMSE (unitless)";
    const std::string longLabel =
        "cascades inject_device=cpu levels=6 supersampling=4 voxelize_device=cpu schedule=one_pass";
    spec.series = {{longLabel, {16, 32, 64}, {0.14, 0.12, 0.13}, {}}, {"svo", {64, 128}, {0.12, 0.15}, {}}};
    const FigureSize widened = widenForLegend(spec.size, spec.series);
    EXPECT_GT(widened.width, spec.size.width);
    EXPECT_EQ(widened.height, spec.size.height);
    // Short labels keep the requested size.
    EXPECT_EQ(widenForLegend(spec.size, {{"svo", {1}, {1}, {}}}).width, spec.size.width);
    const std::string base = test::makeTempDir("legend") + "/long";
    writeLineChart(spec, base);
    expectChartFiles(base, widened, {"svo"});
}

TEST(FigureText, LongTitlesWrapAtSpaces)
{
    EXPECT_EQ(detail::wrapText("short title", 40), "short title");
    EXPECT_EQ(detail::wrapText("voxel_gi: tomorrow_town, 320x180: time per pass of the runs", 30),
              "voxel_gi: tomorrow_town,\n320x180: time per pass of the\nruns");
    EXPECT_EQ(detail::wrapText("averyveryverylongword fits", 10), "averyveryverylongword\nfits");
    const std::string wrapped = detail::wrapText(std::string(200, 'a') + " b c d e f g", 12);
    EXPECT_EQ(wrapped.substr(0, 200), std::string(200, 'a'));
}

TEST(BarLabels, LongLabelsUnderManyBarsDoNotFit)
{
    StackedBarSpec spec;
    spec.bars = {"gtao", "lsao", "ssdo"};
    EXPECT_TRUE(barLabelsFit(spec));
    spec.bars = {"gtao\nslices=2", "lsao\ndirections=36"}; // each line counts, not the whole label
    EXPECT_TRUE(barLabelsFit(spec));
    spec.bars.assign(16, "adaptive_voxel_tree_cones\nresolution=64 depth=3 inner_layers=4");
    EXPECT_FALSE(barLabelsFit(spec));
    spec.bars.assign(16, "12");
    EXPECT_TRUE(barLabelsFit(spec));
}

TEST_F(ChartTest, StackedBarsWritePngAndVectorPdf)
{
    StackedBarSpec spec;
    spec.title = "Per-pass GPU time";
    spec.xLabel = "technique";
    spec.bars = {"ssao", "hbao", "rtao"};
    spec.passes = {"g-buffer", "occlusion", "blur"};
    spec.values = {{0.8, 0.6, 0.2}, {0.8, 1.0, 0.2}, {0.8, 6.5, kNaN}};
    spec.size = {900, 600};
    const std::string base = test::makeTempDir("bars") + "/passes";
    writeStackedBars(spec, base);
    expectChartFiles(base, spec.size,
                     {spec.title, spec.yLabel, "g-buffer", "occlusion", "blur", "hbao", "7.30"});
    // Each pass colour fills a bar segment.
    const test::Pixels png = test::readPng(base + ".png");
    ColorTable colors = spec.colors;
    for (const auto& pass : spec.passes)
        EXPECT_GT(png.count(colors.getColor(pass)), 500u) << pass;
}

TEST_F(ChartTest, InconsistentInputIsRejected)
{
    ScatterSpec scatter;
    scatter.series = {{"a", {1, 2}, {1}, {}}};
    EXPECT_THROW(writeScatter(scatter, test::makeTempDir("bad") + "/s"), rtlab::Error);
    StackedBarSpec bars;
    bars.bars = {"a"};
    bars.passes = {"p", "q"};
    bars.values = {{1.0}};
    EXPECT_THROW(writeStackedBars(bars, test::makeTempDir("bad") + "/b"), rtlab::Error);
}
