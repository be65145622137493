#include "plot/heat_map.h"

#include "core/error.h"
#include "plot/figure.h"

#include <vtkBrush.h>
#include <vtkContext2D.h>
#include <vtkContextItem.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPen.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>

namespace rtlab::plot {
namespace {

constexpr int kMargin = 16;
constexpr int kCell = 22;        //!< cell size, pixels
constexpr int kTitleHeight = 40;
constexpr int kKeyHeight = 44;
constexpr float kFont = 13.0f;
constexpr float kTitleFont = 17.0f;
constexpr float kGlyph = 0.6f; //!< average glyph width of the font size (Arial-like)

int estimateWidth(const std::string& s, float font) { return int(std::ceil(s.size() * font * kGlyph)); }

class HeatMapItem : public vtkContextItem {
public:
    static HeatMapItem* New();
    vtkTypeMacro(HeatMapItem, vtkContextItem);

    struct Rect {
        int x, y, w, h; //!< PNG pixels, row 0 at the top
        HeatColor color;
    };
    using Text = detail::PixelText;
    int mHeight = 0;
    std::vector<Rect> mRects;
    std::vector<Text> mTexts;

    bool Paint(vtkContext2D* painter) override
    {
        painter->GetPen()->SetColor(255, 255, 255, 255);
        painter->GetPen()->SetWidth(1.0f);
        for (const Rect& r : mRects) {
            painter->GetBrush()->SetColor(r.color.r, r.color.g, r.color.b, 255);
            painter->DrawRect(float(r.x), float(mHeight - r.y - r.h), float(r.w), float(r.h));
        }
        detail::drawPixelTexts(painter, mTexts, mHeight);
        return true;
    }
};

vtkStandardNewMacro(HeatMapItem);

} // namespace

HeatColor getHeatColor(const HeatCell& cell)
{
    switch (cell.state) {
    case HeatCell::State::NotRun:
        return {215, 215, 215};
    case HeatCell::State::Fail:
        return {214, 39, 40};
    case HeatCell::State::Pass:
        break;
    }
    if (!std::isfinite(cell.ratio))
        return {44, 160, 44};
    // Closed form: from bright green (deviation 0) to olive (the whole tolerance used).
    const double t = std::clamp(cell.ratio, 0.0, 1.0);
    auto mix = [t](int a, int b) { return static_cast<unsigned char>(std::lround(a + (b - a) * t)); };
    return {mix(116, 188), mix(196, 170), mix(118, 40)};
}

void writeHeatMap(const HeatMapSpec& spec, const std::string& pathWithoutExtension)
{
    if (spec.cells.size() != spec.rowLabels.size())
        throw Error("heat map '" + spec.title + "': " + std::to_string(spec.cells.size()) + " rows of cells for " +
                    std::to_string(spec.rowLabels.size()) + " row labels");
    for (const auto& row : spec.cells)
        if (row.size() != spec.columnLabels.size())
            throw Error("heat map '" + spec.title + "': a row has " + std::to_string(row.size()) + " cells for " +
                        std::to_string(spec.columnLabels.size()) + " columns");
    int rowLabelWidth = 0, columnLabelHeight = 0;
    for (const auto& s : spec.rowLabels)
        rowLabelWidth = std::max(rowLabelWidth, estimateWidth(s, kFont));
    for (const auto& s : spec.columnLabels)
        columnLabelHeight = std::max(columnLabelHeight, estimateWidth(s, kFont));
    const int left = kMargin + rowLabelWidth + 8;
    const int top = kMargin + kTitleHeight + columnLabelHeight + 8;
    const int gridWidth = kCell * int(spec.columnLabels.size());
    const int gridHeight = kCell * int(spec.rowLabels.size());
    const int keyWidth = 760;
    const int width = std::max({left + gridWidth + kMargin, keyWidth + 2 * kMargin,
                                estimateWidth(spec.title, kTitleFont) + 2 * kMargin});
    const int height = top + gridHeight + 12 + kKeyHeight + kMargin;

    auto lock = detail::lockRendering();
    detail::Figure figure(width, height);
    vtkNew<HeatMapItem> item;
    item->mHeight = height;
    item->mTexts.push_back({width / 2.0f, kMargin + kTitleHeight / 2.0f, spec.title, kTitleFont, true,
                            VTK_TEXT_CENTERED, 0.0});
    for (std::size_t r = 0; r < spec.rowLabels.size(); ++r) {
        const int y = top + kCell * int(r);
        item->mTexts.push_back({float(left - 8), y + kCell / 2.0f, spec.rowLabels[r], kFont, false, VTK_TEXT_RIGHT, 0.0});
        for (std::size_t c = 0; c < spec.columnLabels.size(); ++c)
            item->mRects.push_back({left + kCell * int(c), y, kCell, kCell, getHeatColor(spec.cells[r][c])});
    }
    for (std::size_t c = 0; c < spec.columnLabels.size(); ++c)
        item->mTexts.push_back({left + kCell * (c + 0.5f), float(top - 6), spec.columnLabels[c], kFont, false,
                                VTK_TEXT_LEFT, 90.0});
    // The key.
    const int keyY = top + gridHeight + 12;
    int x = kMargin;
    const auto addKey = [&](HeatCell cell, const std::string& text) {
        item->mRects.push_back({x, keyY + 4, kCell, kCell, getHeatColor(cell)});
        item->mTexts.push_back({float(x + kCell + 6), keyY + 4 + kCell / 2.0f, text, kFont, false, VTK_TEXT_LEFT, 0.0});
        x += kCell + 12 + estimateWidth(text, kFont) + 12;
    };
    addKey({HeatCell::State::Pass}, "pass");
    addKey({HeatCell::State::Pass, 0.0}, "0 %");
    addKey({HeatCell::State::Pass, 0.5}, "50 %");
    addKey({HeatCell::State::Pass, 1.0}, "100 % of its tolerance used (closed form)");
    addKey({HeatCell::State::Fail}, "fail");
    addKey({HeatCell::State::NotRun}, "not run");
    figure.addItem(item);
    figure.write(pathWithoutExtension, spec.title);
}

} // namespace rtlab::plot
