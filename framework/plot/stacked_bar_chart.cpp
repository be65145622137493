// Per-pass time as stacked bars, one bar per technique or configuration, totals on top.

#include "plot/charts.h"

#include "core/error.h"
#include "plot/figure.h"

#include <vtkAxis.h>
#include <vtkChartXY.h>
#include <vtkColor.h>
#include <vtkColorSeries.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlotBar.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include <cmath>
#include <cstdio>

namespace rtlab::plot {

bool barLabelsFit(const StackedBarSpec& spec)
{
    if (spec.bars.empty())
        return true;
    const float scale = std::max(0.5f, std::min(float(spec.size.width) / 1000.0f, float(spec.size.height) / 700.0f));
    // The plot spans the figure less the y axis and the pass legend (about 250 px at scale 1).
    const double perBar = (double(spec.size.width) - 250.0 * scale) / double(spec.bars.size());
    std::size_t longest = 0;
    for (const std::string& label : spec.bars) {
        std::size_t start = 0;
        while (start <= label.size()) {
            const std::size_t end = std::min(label.find('\n', start), label.size());
            longest = std::max(longest, end - start);
            start = end + 1;
        }
    }
    return double(longest) * 0.55 * 12.0 * scale <= 0.9 * perBar;
}

void writeStackedBars(const StackedBarSpec& spec, const std::string& pathWithoutExtension)
{
    if (spec.values.size() != spec.bars.size())
        throw Error("stacked bars: " + std::to_string(spec.bars.size()) + " bars but " +
                    std::to_string(spec.values.size()) + " rows of values");
    for (std::size_t b = 0; b < spec.bars.size(); ++b)
        if (spec.values[b].size() != spec.passes.size())
            throw Error("stacked bars: bar '" + spec.bars[b] + "' has " +
                        std::to_string(spec.values[b].size()) + " values for " +
                        std::to_string(spec.passes.size()) + " passes");
    auto valueAt = [&](std::size_t b, std::size_t p) {
        const double v = spec.values[b][p];
        return std::isfinite(v) ? v : 0.0;
    };
    std::vector<double> totals(spec.bars.size(), 0.0);
    for (std::size_t b = 0; b < spec.bars.size(); ++b)
        for (std::size_t p = 0; p < spec.passes.size(); ++p)
            totals[b] += valueAt(b, p);
    double highest = 0.0;
    for (double t : totals)
        highest = std::max(highest, t);

    const double barCount = double(std::max<std::size_t>(spec.bars.size(), 1));
    detail::AxisSetup xAxis{spec.xLabel, false, 0.4, barCount + 0.6};
    detail::AxisSetup yAxis{spec.yLabel, false, 0.0, highest > 0 ? highest * 1.12 : 1.0};

    auto lock = detail::lockRendering();
    detail::Figure figure(spec.size.width, spec.size.height);
    const float scale = figure.getFontScale();
    vtkChartXY* chart = detail::addChart(figure, spec.title, xAxis, yAxis);
    chart->SetBarWidthFraction(0.6f);

    vtkNew<vtkDoubleArray> positions;
    vtkNew<vtkStringArray> names;
    for (std::size_t b = 0; b < spec.bars.size(); ++b) {
        positions->InsertNextValue(double(b + 1));
        names->InsertNextValue(spec.bars[b]);
    }
    vtkAxis* bottom = chart->GetAxis(vtkAxis::BOTTOM);
    bottom->SetCustomTickPositions(positions, names);
    bottom->SetGridVisible(false);

    if (!spec.bars.empty() && !spec.passes.empty()) {
        vtkNew<vtkTable> table;
        vtkNew<vtkDoubleArray> xs;
        xs->SetName("bar");
        for (std::size_t b = 0; b < spec.bars.size(); ++b)
            xs->InsertNextValue(double(b + 1));
        table->AddColumn(xs);
        vtkNew<vtkStringArray> passNames;
        vtkNew<vtkColorSeries> palette;
        palette->ClearColors();
        ColorTable colors = spec.colors;
        for (std::size_t p = 0; p < spec.passes.size(); ++p) {
            vtkNew<vtkDoubleArray> column;
            column->SetName(("pass " + std::to_string(p)).c_str());
            for (std::size_t b = 0; b < spec.bars.size(); ++b)
                column->InsertNextValue(valueAt(b, p));
            table->AddColumn(column);
            passNames->InsertNextValue(spec.passes[p]);
            const Color c = colors.getColor(spec.passes[p]);
            palette->AddColor(vtkColor3ub(c.r, c.g, c.b));
        }
        auto* bars = vtkPlotBar::SafeDownCast(chart->AddPlot(vtkChart::BAR));
        bars->SetInputData(table, 0, 1);
        for (std::size_t p = 1; p < spec.passes.size(); ++p)
            bars->SetInputArray(int(p + 1), table->GetColumn(vtkIdType(p + 1))->GetName());
        bars->SetColorSeries(palette);
        bars->GetPen()->SetColor(255, 255, 255, 255); // thin white gaps between segments
        bars->GetPen()->SetWidth(1.0f);
        bars->SetLabels(passNames);
    }

    std::vector<detail::DataLabel> labels;
    for (std::size_t b = 0; b < spec.bars.size(); ++b) {
        char text[64];
        std::snprintf(text, sizeof(text), "%.*f", std::max(0, spec.totalDecimals), totals[b]);
        labels.push_back({double(b + 1), totals[b], text, Color{40, 40, 40}, false, true, true});
    }
    detail::addChartOverlay(figure, chart, {}, 0.0f, std::move(labels), 12.0f * scale);
    figure.write(pathWithoutExtension, spec.title);
}

} // namespace rtlab::plot
