#include "plot/chart_tables.h"

#include "core/error.h"

#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkTable.h>

namespace rtlab::plot::detail {

vtkTable* makeXyTable(const std::vector<double>& x, const std::vector<double>& y)
{
    vtkTable* table = vtkTable::New();
    vtkNew<vtkDoubleArray> xs, ys;
    xs->SetName("x");
    ys->SetName("y");
    for (std::size_t i = 0; i < x.size() && i < y.size(); ++i) {
        xs->InsertNextValue(x[i]);
        ys->InsertNextValue(y[i]);
    }
    table->AddColumn(xs);
    table->AddColumn(ys);
    return table;
}

void checkSeriesLengths(const std::string& what, const std::string& label, std::size_t x,
                        std::size_t y, std::size_t labels)
{
    if (x != y || (labels != 0 && labels != x))
        throw Error(what + " series '" + label + "': " + std::to_string(x) + " x values, " +
                    std::to_string(y) + " y values and " + std::to_string(labels) +
                    " point labels (expected as many x as y, and no labels or one per point)");
}

void setUpXyAxes(const std::string& what, const std::vector<Series>& series, const std::string& xLabel,
                 AxisScale xScale, const std::string& yLabel, AxisScale yScale, AxisSetup& xAxis,
                 AxisSetup& yAxis)
{
    std::vector<double> allX, allY;
    for (const auto& s : series) {
        checkSeriesLengths(what, s.label, s.x.size(), s.y.size(), s.pointLabels.size());
        allX.insert(allX.end(), s.x.begin(), s.x.end());
        allY.insert(allY.end(), s.y.begin(), s.y.end());
    }
    xAxis = AxisSetup{xLabel, isLogAxis(xScale, allX)};
    yAxis = AxisSetup{yLabel, isLogAxis(yScale, allY)};
    computeAxisRange(allX, xAxis.log, xAxis.min, xAxis.max);
    computeAxisRange(allY, yAxis.log, yAxis.min, yAxis.max);
}

} // namespace rtlab::plot::detail
