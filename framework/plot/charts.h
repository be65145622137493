#pragma once
// Charts of a study's results: time against error with Pareto fronts, error against one
// parameter, and per-pass time as stacked bars. Inputs are plain data; callers pick the columns.
// Every writer produces <path>.png (raster) and <path>.pdf (vector: text as text, lines as paths)
// and works headless (see plot/headless_display.h).

#include "plot/color.h"

#include <cstddef>
#include <string>
#include <vector>

namespace rtlab::plot {

//! How an axis maps values to positions.
enum class AxisScale {
    Linear,
    Log,       //!< base 10; values <= 0 are left out
    Automatic, //!< Log when every value is positive and they span kAutoLogRatio or more
};

//! max / min at and above which an Automatic axis becomes logarithmic (a decade).
inline constexpr double kAutoLogRatio = 10.0;

//! Pixel size of the PNG; the PDF page has the same size in points.
struct FigureSize {
    int width = 1000;
    int height = 700;
};

//! One technique's points. x and y have the same length; pointLabels is empty or as long.
//! Points where x or y is not finite are left out.
struct Series {
    std::string label;
    std::vector<double> x;
    std::vector<double> y;
    std::vector<std::string> pointLabels;
    //! Which configuration of its technique this series is (0 = the first): series that share a
    //! colour (one technique) are told apart by the line pattern and marker shape of their variant
    //! (getVariantStyle). Line charts only.
    int variant = 0;
};

//! The line pattern and marker of a variant: solid + circle, dashed + square, dotted + diamond,
//! dash-dot + cross, dash-dot-dot + plus, then repeating.
struct VariantStyle {
    int lineType = 1; //!< vtkPen line type (1 solid, 2 dash, 3 dot, 4 dash-dot, 5 dash-dot-dot)
    int marker = 4;   //!< VTK marker style (4 circle, 3 square, 5 diamond, 1 cross, 2 plus)
};
VariantStyle getVariantStyle(int variant);

//! Run time against error, one colour per series. Both axes are minimised.
struct ScatterSpec {
    std::string title;
    std::string xLabel; //!< with units, e.g. "GPU time (ms)"
    std::string yLabel; //!< with units, e.g. "RMSE (AO, unitless)"
    AxisScale xScale = AxisScale::Automatic;
    AxisScale yScale = AxisScale::Automatic;
    std::vector<Series> series;
    //! Each series' Pareto front as a step line labelled with the series name; front points
    //! are drawn opaque and labelled with their pointLabels, the others faded.
    bool drawParetoFronts = true;
    ColorTable colors; //!< series label -> colour; fill it with every technique of the study
    FigureSize size;
};

//! Error (or anything) against one parameter, one line per series, points joined in x order.
//! Series::pointLabels are not drawn.
struct LineSpec {
    std::string title;
    std::string xLabel;
    std::string yLabel;
    AxisScale xScale = AxisScale::Automatic;
    AxisScale yScale = AxisScale::Automatic;
    std::vector<Series> series;
    bool drawMarkers = true;
    ColorTable colors;
    FigureSize size;
};

//! Per-pass time of each bar (technique or configuration), stacked, with the total on top.
struct StackedBarSpec {
    std::string title;
    std::string xLabel;
    std::string yLabel = "GPU time (ms)";
    std::vector<std::string> bars;
    std::vector<std::string> passes;
    std::vector<std::vector<double>> values; //!< values[bar][pass]; NaN counts as 0
    ColorTable colors;                       //!< pass name -> colour
    int totalDecimals = 2;                   //!< digits after the point of the totals
    FigureSize size;
};

//! Whether every line of every bar label fits under its bar (12 px text, about 0.55 em per
//! character, in the plot width the figure leaves the bars). When not, callers number the bars and
//! give the labels in a key.
bool barLabelsFit(const StackedBarSpec& spec);

//! Writes <pathWithoutExtension>.png and .pdf, creating the folder if needed. Throws rtlab::Error
//! when the input is inconsistent or a file cannot be written.
void writeScatter(const ScatterSpec& spec, const std::string& pathWithoutExtension);
void writeLineChart(const LineSpec& spec, const std::string& pathWithoutExtension);
void writeStackedBars(const StackedBarSpec& spec, const std::string& pathWithoutExtension);

//! Indices of the points on the Pareto front of (x, y), both minimised, ordered by x. Same rule
//! as experiment::findParetoFront: non-finite points are ignored; sweep by increasing x (ties:
//! lower y first) keeping each point that lowers the best y so far.
std::vector<std::size_t> findParetoFront(const std::vector<double>& x,
                                         const std::vector<double>& y);

//! A series' front as writeScatter draws it.
struct ParetoFrontLine {
    std::size_t seriesIndex = 0; //!< into ScatterSpec::series
    std::string label;
    Color color;
    std::vector<std::size_t> pointIndices; //!< into the series' x / y, ordered by x
    std::vector<double> stepX;             //!< the staircase through the front points
    std::vector<double> stepY;
};

//! The fronts writeScatter draws for `spec` (one per series with at least one finite point).
//! Points an axis cannot show (<= 0 on a log axis) are left out before the front is found.
std::vector<ParetoFrontLine> computeParetoFronts(const ScatterSpec& spec);

//! The colour each series gets, in series order (assigning new labels in first-seen order on a
//! copy of `colors`).
std::vector<Color> getSeriesColors(const std::vector<Series>& series, const ColorTable& colors);

//! The figure size a chart with these series' legend is drawn at: `size`, widened where the
//! legend (right of the plot, as wide as its longest label) would leave the plot area narrower
//! than 600 pixels at the figure's font scale, so that a legend never squeezes the plot.
FigureSize widenForLegend(FigureSize size, const std::vector<Series>& series);

//! Whether an axis over `values` is drawn logarithmic: Log, Linear, or for Automatic every finite
//! value > 0 and max / min >= kAutoLogRatio.
bool isLogAxis(AxisScale scale, const std::vector<double>& values);

} // namespace rtlab::plot
