#pragma once
// Internal: building VTK tables for chart plots. VTK classes are only forward-declared here.

#include "plot/charts.h"
#include "plot/figure.h"

#include <string>
#include <vector>

class vtkTable;

namespace rtlab::plot::detail {

//! A new table with double columns "x" and "y" (the caller owns the reference).
vtkTable* makeXyTable(const std::vector<double>& x, const std::vector<double>& y);

//! Throws rtlab::Error when a series' x, y and pointLabels lengths disagree.
void checkSeriesLengths(const std::string& what, const std::string& label, std::size_t x,
                        std::size_t y, std::size_t labels);

//! Checks every series and sets up both axes of an x-y chart from all their values: log or
//! linear per `xScale` / `yScale`, and the padded ranges.
void setUpXyAxes(const std::string& what, const std::vector<Series>& series, const std::string& xLabel,
                 AxisScale xScale, const std::string& yLabel, AxisScale yScale, AxisSetup& xAxis,
                 AxisSetup& yAxis);

} // namespace rtlab::plot::detail
