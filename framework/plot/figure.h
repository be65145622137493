#pragma once
// What the plot writers share: an off-screen VTK view, PNG + PDF export, chart styling and text
// labels at data coordinates. Internal to rtlab_plot; VTK classes are only forward-declared here.

#include "plot/color.h"

#include <memory>
#include <mutex>
#include <string>
#include <vector>

class vtkChartXY;
class vtkContext2D;
class vtkContextItem;
class vtkPlot;

namespace rtlab::plot::detail {

//! Serialises the writers: one VTK render window at a time per process.
std::unique_lock<std::mutex> lockRendering();

//! A white off-screen VTK context view on the display ensureDisplay() gives.
class Figure {
public:
    Figure(int width, int height);
    ~Figure();
    Figure(const Figure&) = delete;
    Figure& operator=(const Figure&) = delete;

    int getWidth() const { return mWidth; }
    int getHeight() const { return mHeight; }
    //! Font sizes are given for a 1000 x 700 figure and scaled by this.
    float getFontScale() const;

    //! Adds an item to the scene; items paint in the order they were added.
    void addItem(vtkContextItem* item);
    //! Renders and writes <path>.png and <path>.pdf (the PDF titled `title`). Throws rtlab::Error
    //! when a file was not written.
    void write(const std::string& pathWithoutExtension, const std::string& title);

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
    int mWidth;
    int mHeight;
};

//! One axis of a chart.
struct AxisSetup {
    std::string label;
    bool log = false;
    double min = 0.0; //!< data units (not log10)
    double max = 1.0;
};

//! The range of the values an axis shows (finite, and positive on a log axis), padded by a few
//! percent (of the decades on a log axis) so that markers at the ends are not cut.
void computeAxisRange(const std::vector<double>& values, bool log, double& min, double& max);

//! Adds a styled XY chart filling the figure: title, axis titles and fixed ranges, light grid,
//! legend to the right of the plot area.
vtkChartXY* addChart(Figure& figure, const std::string& title, const AxisSetup& x,
                     const AxisSetup& y);

//! Colour of a plot's pen and brush.
void setPlotColor(vtkPlot* plot, Color color, unsigned char alpha = 255);
//! Colour of a line plot's pen, with no fill (the PDF device fills polylines with the brush).
void setLineColor(vtkPlot* plot, Color color);

//! `text` with its spaces turned into line breaks where a line would pass maxChars characters
//! (a word longer than that stays whole on its own line).
std::string wrapText(const std::string& text, std::size_t maxChars);

//! A marker at a data position of a chart.
struct DataMarker {
    double x = 0.0;
    double y = 0.0;
    Color color;
    int style = 4; //!< VTK marker style (VTK_MARKER_CIRCLE = 4)
};

//! Text at a data position of a chart.
struct DataLabel {
    double x = 0.0;
    double y = 0.0;
    std::string text;
    Color color;
    bool bold = false;
    bool above = false;  //!< centred above the point; otherwise the first free side of it
    bool always = false; //!< drawn even where it overlaps other labels or markers
};

//! Adds an item that draws circle `markers` (of `markerSize` pixels) and then `labels` over
//! `chart`, mapping data to the chart's laid-out axes itself. Markers are drawn here rather than
//! by VTK's point plots because VTK's PDF device sizes plot markers in data units. Labels that
//! would overlap a marker, an earlier label or leave the plot area are left out unless `always`.
void addChartOverlay(Figure& figure, vtkChartXY* chart, std::vector<DataMarker> markers,
                     float markerSize, std::vector<DataLabel> labels, float fontSize);

//! Text anchored at a pixel of a figure (row 0 at the top), for items that lay out in pixels.
struct PixelText {
    float x = 0.0f;
    float y = 0.0f;
    std::string text;
    float size = 12.0f; //!< font size
    bool bold = false;
    int justification = 0; //!< VTK_TEXT_LEFT / CENTERED / RIGHT
    double orientation = 0.0; //!< degrees, counter-clockwise
};
//! Draws `texts` (dark grey Arial, vertically centred on their anchors) on a figure `height`
//! pixels tall.
void drawPixelTexts(vtkContext2D* painter, const std::vector<PixelText>& texts, int height);

} // namespace rtlab::plot::detail
