// Markers and text labels at data coordinates of a chart, drawn after the chart has laid out its
// axes.

#include "plot/figure.h"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContext2D.h>
#include <vtkContextItem.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPen.h>
#include <vtkRect.h>
#include <vtkRenderingCoreEnums.h>
#include <vtkTextProperty.h>
#include <vtkWeakPointer.h>

#include <algorithm>
#include <map>
#include <array>
#include <cmath>

namespace rtlab::plot::detail {

namespace {

struct Box {
    float x0, y0, x1, y1;
    bool overlaps(const Box& o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
    bool inside(const Box& o) const { return x0 >= o.x0 && x1 <= o.x1 && y0 >= o.y0 && y1 <= o.y1; }
};

//! Scene coordinate of a data value on an axis that has been laid out.
float mapToScene(vtkAxis* axis, double value, bool horizontal)
{
    double range[2];
    axis->GetUnscaledRange(range);
    const bool log = axis->GetLogScaleActive();
    auto f = [log](double v) { return log ? std::log10(v) : v; };
    const vtkVector2f p1 = axis->GetPosition1();
    const vtkVector2f p2 = axis->GetPosition2();
    const float a = horizontal ? p1.GetX() : p1.GetY();
    const float b = horizontal ? p2.GetX() : p2.GetY();
    const double t = (f(value) - f(range[0])) / (f(range[1]) - f(range[0]));
    return a + float(t) * (b - a);
}

class ChartOverlayItem : public vtkContextItem {
public:
    static ChartOverlayItem* New();
    vtkTypeMacro(ChartOverlayItem, vtkContextItem);

    vtkWeakPointer<vtkChartXY> mChart;
    std::vector<DataMarker> mMarkers;
    float mMarkerSize = 9.0f;
    std::vector<DataLabel> mLabels;
    float mFontSize = 11.0f;

    bool Paint(vtkContext2D* painter) override
    {
        if (!mChart)
            return false;
        vtkAxis* xAxis = mChart->GetAxis(vtkAxis::BOTTOM);
        vtkAxis* yAxis = mChart->GetAxis(vtkAxis::LEFT);
        const Box plotArea{xAxis->GetPosition1().GetX(), yAxis->GetPosition1().GetY(),
                           xAxis->GetPosition2().GetX(), yAxis->GetPosition2().GetY()};
        std::vector<Box> taken;
        std::map<int, std::pair<std::vector<float>, std::vector<unsigned char>>> byStyle;
        for (const DataMarker& m : mMarkers) {
            const float px = mapToScene(xAxis, m.x, true);
            const float py = mapToScene(yAxis, m.y, false);
            if (!std::isfinite(px) || !std::isfinite(py))
                continue;
            auto& [points, colors] = byStyle[m.style];
            points.insert(points.end(), {px, py});
            colors.insert(colors.end(), {m.color.r, m.color.g, m.color.b, 255});
            const float r = mMarkerSize / 2;
            taken.push_back({px - r, py - r, px + r, py + r});
        }
        for (auto& [style, drawn] : byStyle) {
            painter->GetPen()->SetWidth(mMarkerSize);
            painter->GetPen()->SetLineType(vtkPen::SOLID_LINE);
            painter->DrawMarkers(style, false, drawn.first.data(), int(drawn.first.size() / 2),
                                 drawn.second.data(), 4);
        }
        const float kGap = std::max(5.0f, mMarkerSize / 2 + 1);
        for (const DataLabel& label : mLabels) {
            vtkTextProperty* text = painter->GetTextProp();
            text->SetFontFamilyToArial();
            text->SetFontSize(int(std::lround(mFontSize)));
            text->SetBold(label.bold);
            text->SetItalic(false);
            text->SetShadow(false);
            text->SetOrientation(0.0);
            text->SetJustificationToLeft();
            text->SetVerticalJustificationToBottom();
            text->SetColor(label.color.r / 255.0, label.color.g / 255.0, label.color.b / 255.0);
            float bounds[4];
            painter->ComputeStringBounds(label.text, bounds);
            const float w = bounds[2], h = bounds[3];
            const float px = mapToScene(xAxis, label.x, true);
            const float py = mapToScene(yAxis, label.y, false);
            if (!std::isfinite(px) || !std::isfinite(py))
                continue;
            std::vector<std::array<float, 2>> corners; // bottom-left corner candidates
            if (label.above)
                corners = {{px - w / 2, py + kGap}};
            else
                corners = {{px + kGap, py + kGap},     {px + kGap, py - kGap - h},
                           {px - kGap - w, py + kGap}, {px - kGap - w, py - kGap - h},
                           {px + kGap, py - h / 2},    {px - kGap - w, py - h / 2}};
            auto boxAt = [&](const std::array<float, 2>& c) {
                return Box{c[0], c[1], c[0] + w, c[1] + h};
            };
            auto isFree = [&](const Box& b) {
                return b.inside(plotArea) &&
                       std::none_of(taken.begin(), taken.end(),
                                    [&](const Box& t) { return b.overlaps(t); });
            };
            const auto place = std::find_if(corners.begin(), corners.end(),
                                            [&](const auto& c) { return isFree(boxAt(c)); });
            if (place == corners.end() && !label.always)
                continue;
            const Box box = boxAt(place != corners.end() ? *place : corners.front());
            taken.push_back(box);
            painter->DrawString(box.x0, box.y0, label.text.c_str());
        }
        return true;
    }
};

vtkStandardNewMacro(ChartOverlayItem);

} // namespace

void addChartOverlay(Figure& figure, vtkChartXY* chart, std::vector<DataMarker> markers,
                     float markerSize, std::vector<DataLabel> labels, float fontSize)
{
    vtkNew<ChartOverlayItem> item;
    item->mChart = chart;
    item->mMarkers = std::move(markers);
    item->mMarkerSize = markerSize;
    item->mLabels = std::move(labels);
    item->mFontSize = fontSize;
    figure.addItem(item);
}

} // namespace rtlab::plot::detail
