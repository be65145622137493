// The data side of the charts: Pareto fronts, colours, axis scales. No VTK here.

#include "plot/charts.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::plot {

std::vector<std::size_t> findParetoFront(const std::vector<double>& x, const std::vector<double>& y)
{
    std::vector<std::size_t> candidates;
    for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i)
        if (std::isfinite(x[i]) && std::isfinite(y[i]))
            candidates.push_back(i);
    std::sort(candidates.begin(), candidates.end(), [&](std::size_t a, std::size_t b) {
        return x[a] != x[b] ? x[a] < x[b] : y[a] < y[b];
    });
    std::vector<std::size_t> front;
    double bestY = std::numeric_limits<double>::infinity();
    for (std::size_t i : candidates) {
        if (y[i] < bestY) {
            front.push_back(i);
            bestY = y[i];
        }
    }
    return front;
}

VariantStyle getVariantStyle(int variant)
{
    // vtkPen line types and VTK marker styles, in the order a reader tells them apart best.
    static constexpr VariantStyle kStyles[] = {{1, 4}, {2, 3}, {3, 5}, {4, 1}, {5, 2}};
    constexpr int n = int(sizeof kStyles / sizeof kStyles[0]);
    return kStyles[((variant % n) + n) % n];
}

std::vector<Color> getSeriesColors(const std::vector<Series>& series, const ColorTable& colors)
{
    ColorTable table = colors;
    std::vector<Color> result;
    for (const auto& s : series)
        result.push_back(table.getColor(s.label));
    return result;
}

FigureSize widenForLegend(FigureSize size, const std::vector<Series>& series)
{
    // Figure::getFontScale; the legend's labels are 13 px at scale 1, about 0.56 em per character,
    // plus the line swatch and padding; the axes and their labels take about 110 px.
    const float scale = std::max(0.5f, std::min(float(size.width) / 1000.0f, float(size.height) / 700.0f));
    std::size_t longest = 0;
    for (const Series& s : series)
        longest = std::max(longest, s.label.size());
    const double legend = (60.0 + 0.56 * 13.0 * double(longest)) * scale;
    const int needed = int(std::ceil((110.0 + 600.0 + 20.0) * scale + legend));
    size.width = std::min(16384, std::max(size.width, needed));
    return size;
}

bool isLogAxis(AxisScale scale, const std::vector<double>& values)
{
    if (scale != AxisScale::Automatic)
        return scale == AxisScale::Log;
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (double v : values) {
        if (!std::isfinite(v))
            continue;
        if (v <= 0)
            return false;
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    return lo <= hi && hi / lo >= kAutoLogRatio;
}

std::vector<ParetoFrontLine> computeParetoFronts(const ScatterSpec& spec)
{
    std::vector<double> allX, allY;
    for (const auto& s : spec.series) {
        allX.insert(allX.end(), s.x.begin(), s.x.end());
        allY.insert(allY.end(), s.y.begin(), s.y.end());
    }
    const bool logX = isLogAxis(spec.xScale, allX);
    const bool logY = isLogAxis(spec.yScale, allY);
    const auto colors = getSeriesColors(spec.series, spec.colors);

    std::vector<ParetoFrontLine> fronts;
    for (std::size_t s = 0; s < spec.series.size(); ++s) {
        const Series& series = spec.series[s];
        // What the axes cannot show does not take part.
        std::vector<double> x = series.x, y = series.y;
        y.resize(x.size(), std::numeric_limits<double>::quiet_NaN());
        for (std::size_t i = 0; i < x.size(); ++i)
            if ((logX && !(x[i] > 0)) || (logY && !(y[i] > 0)))
                x[i] = std::numeric_limits<double>::quiet_NaN();
        ParetoFrontLine line{s, series.label, colors[s], findParetoFront(x, y), {}, {}};
        if (line.pointIndices.empty())
            continue;
        for (std::size_t k = 0; k < line.pointIndices.size(); ++k) {
            const std::size_t i = line.pointIndices[k];
            if (k > 0) { // horizontal to the next point's cost, then down to its error
                line.stepX.push_back(x[i]);
                line.stepY.push_back(line.stepY.back());
            }
            line.stepX.push_back(x[i]);
            line.stepY.push_back(y[i]);
        }
        fronts.push_back(std::move(line));
    }
    return fronts;
}

} // namespace rtlab::plot
