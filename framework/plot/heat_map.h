#pragma once
// A pass/fail heat map: rows (e.g. techniques) x columns (e.g. stress cases), each cell coloured
// by its state, and passing cells with a closed form shaded by how much of their tolerance they
// used. Written as <path>.png and <path>.pdf like the other figures.

#include <limits>
#include <string>
#include <vector>

namespace rtlab::plot {

struct HeatCell {
    enum class State { NotRun, Pass, Fail };
    State state = State::NotRun;
    //! deviation / tolerance of a passing closed-form case, in [0, 1]; NaN: no closed form
    double ratio = std::numeric_limits<double>::quiet_NaN();
};

struct HeatMapSpec {
    std::string title;
    std::vector<std::string> rowLabels;    //!< drawn left of the rows
    std::vector<std::string> columnLabels; //!< drawn above the columns, rotated
    std::vector<std::vector<HeatCell>> cells; //!< [row][column]
};

//! The colour of a cell: grey (not run), green to yellow-green for a pass (darker the closer its
//! deviation came to its tolerance), red for a failure.
struct HeatColor {
    unsigned char r, g, b;
};
HeatColor getHeatColor(const HeatCell& cell);

//! Writes <pathWithoutExtension>.png and .pdf. Throws rtlab::Error when the cells do not match
//! the labels or a file cannot be written.
void writeHeatMap(const HeatMapSpec& spec, const std::string& pathWithoutExtension);

} // namespace rtlab::plot
