// Error against one parameter: one line per series, points joined in order of x.

#include "plot/charts.h"

#include "plot/chart_tables.h"
#include "plot/figure.h"

#include <vtkChartXY.h>
#include <vtkPen.h>
#include <vtkPlotLine.h>
#include <vtkSmartPointer.h>
#include <vtkTable.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace rtlab::plot {

void writeLineChart(const LineSpec& spec, const std::string& pathWithoutExtension)
{
    detail::AxisSetup xAxis, yAxis;
    detail::setUpXyAxes("line chart", spec.series, spec.xLabel, spec.xScale, spec.yLabel, spec.yScale, xAxis,
                        yAxis);
    const auto colors = getSeriesColors(spec.series, spec.colors);

    auto lock = detail::lockRendering();
    const FigureSize size = widenForLegend(spec.size, spec.series);
    detail::Figure figure(size.width, size.height);
    const float scale = figure.getFontScale();
    vtkChartXY* chart = detail::addChart(figure, spec.title, xAxis, yAxis);
    std::vector<detail::DataMarker> markers;
    for (std::size_t s = 0; s < spec.series.size(); ++s) {
        const Series& series = spec.series[s];
        std::vector<std::size_t> order(series.x.size());
        std::iota(order.begin(), order.end(), std::size_t(0));
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return series.x[a] < series.x[b]; });
        std::vector<double> x, y;
        for (std::size_t i : order) {
            const double u = series.x[i], v = series.y[i];
            if (std::isfinite(u) && std::isfinite(v) && (!xAxis.log || u > 0) &&
                (!yAxis.log || v > 0)) {
                x.push_back(u);
                y.push_back(v);
            }
        }
        if (x.empty())
            continue;
        vtkSmartPointer<vtkTable> table;
        table.TakeReference(detail::makeXyTable(x, y));
        auto* line = vtkPlotLine::SafeDownCast(chart->AddPlot(vtkChart::LINE));
        line->SetInputData(table, 0, 1);
        detail::setLineColor(line, colors[s]);
        const VariantStyle style = getVariantStyle(series.variant);
        line->GetPen()->SetLineType(style.lineType);
        line->SetWidth(2.0f * scale);
        line->SetMarkerStyle(vtkPlotPoints::NONE); // markers are in the overlay
        line->SetLabel(series.label.empty() ? " " : series.label);
        if (spec.drawMarkers)
            for (std::size_t i = 0; i < x.size(); ++i)
                markers.push_back({x[i], y[i], colors[s], style.marker});
    }
    detail::addChartOverlay(figure, chart, std::move(markers), 8.0f * scale, {}, 12.0f * scale);
    figure.write(pathWithoutExtension, spec.title);
}

} // namespace rtlab::plot
