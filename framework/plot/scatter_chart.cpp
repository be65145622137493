// Time against error: every run as a point, each series' Pareto front as a labelled staircase.

#include "plot/charts.h"

#include "plot/chart_tables.h"
#include "plot/figure.h"

#include <vtkChartXY.h>
#include <vtkPlotLine.h>
#include <vtkPlotPoints.h>
#include <vtkSmartPointer.h>
#include <vtkTable.h>

#include <cmath>

namespace rtlab::plot {

using detail::DataLabel;
using detail::DataMarker;

namespace {

constexpr float kMarkerSize = 9.0f;

//! Points off the front: the series colour mixed with white, opaque (so that PNG and PDF agree).
Color fadeColor(Color c)
{
    auto mix = [](std::uint8_t v) { return std::uint8_t(std::lround(v * 0.4 + 255 * 0.6)); };
    return {mix(c.r), mix(c.g), mix(c.b)};
}

} // namespace

void writeScatter(const ScatterSpec& spec, const std::string& pathWithoutExtension)
{
    detail::AxisSetup xAxis, yAxis;
    detail::setUpXyAxes("scatter", spec.series, spec.xLabel, spec.xScale, spec.yLabel, spec.yScale, xAxis,
                        yAxis);
    const auto colors = getSeriesColors(spec.series, spec.colors);
    const auto fronts =
        spec.drawParetoFronts ? computeParetoFronts(spec) : std::vector<ParetoFrontLine>{};

    auto lock = detail::lockRendering();
    const FigureSize size = widenForLegend(spec.size, spec.series);
    detail::Figure figure(size.width, size.height);
    const float scale = figure.getFontScale();
    vtkChartXY* chart = detail::addChart(figure, spec.title, xAxis, yAxis);

    auto visible = [&](double x, double y) {
        return std::isfinite(x) && std::isfinite(y) && (!xAxis.log || x > 0) &&
               (!yAxis.log || y > 0);
    };
    // A point plot without points: it only gives the legend entry (markers are in the overlay).
    auto addLegendEntry = [&](Color color, const std::string& label) {
        vtkSmartPointer<vtkTable> table;
        table.TakeReference(detail::makeXyTable({}, {}));
        auto* plot = vtkPlotPoints::SafeDownCast(chart->AddPlot(vtkChart::POINTS));
        plot->SetInputData(table, 0, 1);
        detail::setPlotColor(plot, color);
        plot->SetMarkerStyle(vtkPlotPoints::CIRCLE);
        plot->SetMarkerSize(kMarkerSize * scale);
        plot->SetLabel(label.empty() ? " " : label);
    };

    std::vector<DataMarker> faded, markers;
    std::vector<DataLabel> frontLabels, pointLabels;
    for (std::size_t s = 0; s < spec.series.size(); ++s) {
        const Series& series = spec.series[s];
        const ParetoFrontLine* front = nullptr;
        for (const auto& f : fronts)
            front = f.seriesIndex == s ? &f : front;
        std::vector<bool> onFront(series.x.size(), !spec.drawParetoFronts);
        if (front)
            for (std::size_t i : front->pointIndices)
                onFront[i] = true;
        for (std::size_t i = 0; i < series.x.size(); ++i)
            if (visible(series.x[i], series.y[i]))
                (onFront[i] ? markers : faded)
                    .push_back(
                        {series.x[i], series.y[i], onFront[i] ? colors[s] : fadeColor(colors[s])});
        if (front) {
            // A front of one point has no staircase to draw (VTK refuses lines of < 2 points).
            if (front->stepX.size() >= 2) {
                vtkSmartPointer<vtkTable> table;
                table.TakeReference(detail::makeXyTable(front->stepX, front->stepY));
                auto* line = vtkPlotLine::SafeDownCast(chart->AddPlot(vtkChart::LINE));
                line->SetInputData(table, 0, 1);
                detail::setLineColor(line, colors[s]);
                line->SetWidth(2.0f * scale);
                line->SetMarkerStyle(vtkPlotPoints::NONE);
                line->SetLegendVisibility(false);
            }
            const std::size_t last = front->pointIndices.back();
            frontLabels.push_back(
                {series.x[last], series.y[last], series.label, colors[s], true, false, true});
            if (!series.pointLabels.empty())
                for (std::size_t i : front->pointIndices)
                    pointLabels.push_back(
                        {series.x[i], series.y[i], series.pointLabels[i], colors[s]});
        }
        addLegendEntry(colors[s], series.label);
    }
    // Faded points under the emphasised ones; series names first: they are drawn whatever
    // overlaps, point labels fill the free space.
    faded.insert(faded.end(), markers.begin(), markers.end());
    frontLabels.insert(frontLabels.end(), pointLabels.begin(), pointLabels.end());
    detail::addChartOverlay(figure, chart, std::move(faded), kMarkerSize * scale,
                            std::move(frontLabels), 12.0f * scale);
    figure.write(pathWithoutExtension, spec.title);
}

} // namespace rtlab::plot
