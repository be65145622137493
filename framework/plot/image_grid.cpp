// Image grids drawn as a VTK context item, so that the PNG and the PDF come from one painting.

#include "plot/image_grid.h"

#include "plot/figure.h"
#include "plot/image_grid_style.h"

#include <vtkBrush.h>
#include <vtkContext2D.h>
#include <vtkContextItem.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPen.h>
#include <vtkRect.h>
#include <vtkSmartPointer.h>
#include <vtkTextProperty.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace rtlab::plot {

namespace {

using namespace detail;

std::uint8_t encodeChannel(float v, bool srgb)
{
    v = std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
    if (srgb)
        v = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    return std::uint8_t(std::lround(v * 255.0f));
}

//! The displayed colours of a cell, 8-bit sRGB, row 0 at the top.
Image<Color> shadeCell(const GridCell& cell, const ImageGridSpec& spec, float lo, float hi)
{
    if (cell.isErrorMap()) {
        Image<Color> out(cell.error.width, cell.error.height);
        for (std::size_t i = 0; i < out.size(); ++i) {
            const float e = cell.error.pixels[i];
            out.pixels[i] = std::isfinite(e)
                                ? sampleColorMap(spec.errorColorMap, (e - lo) / (hi - lo))
                                : Color{128, 128, 128};
        }
        return out;
    }
    Image<Color> out(cell.color.width, cell.color.height);
    for (std::size_t i = 0; i < out.size(); ++i) {
        const glm::vec3 c = cell.color.pixels[i];
        out.pixels[i] = {encodeChannel(c.x, spec.encodeSrgb), encodeChannel(c.y, spec.encodeSrgb),
                         encodeChannel(c.z, spec.encodeSrgb)};
    }
    return out;
}

//! `region` of `image` magnified `zoom` times by pixel replication, as VTK image data (VTK's row 0
//! is at the bottom).
vtkSmartPointer<vtkImageData> makeVtkImage(const Image<Color>& image, PixelRect region, int zoom)
{
    auto data = vtkSmartPointer<vtkImageData>::New();
    const int w = region.width * zoom, h = region.height * zoom;
    data->SetDimensions(w, h, 1);
    data->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    auto* out = static_cast<std::uint8_t*>(data->GetScalarPointer());
    for (int y = 0; y < h; ++y) {
        const int sourceY = region.y + (h - 1 - y) / zoom;
        for (int x = 0; x < w; ++x) {
            const Color c = image.at(region.x + x / zoom, sourceY);
            std::uint8_t* p = out + 3 * (std::size_t(y) * w + x);
            p[0] = c.r;
            p[1] = c.g;
            p[2] = c.b;
        }
    }
    return data;
}

std::string formatTick(float v)
{
    char text[32];
    std::snprintf(text, sizeof(text), "%.3g", double(v));
    return text;
}

class ImageGridItem : public vtkContextItem {
public:
    static ImageGridItem* New();
    vtkTypeMacro(ImageGridItem, vtkContextItem);

    struct Picture {
        PixelRect where;
        vtkSmartPointer<vtkImageData> data;
        int outline = -1; //!< crop colour index framing the picture, -1 for none
    };
    using Text = detail::PixelText;

    int mWidth = 0;
    int mHeight = 0;
    std::vector<Picture> mPictures;
    std::vector<std::pair<PixelRect, int>> mOutlines; //!< crop rectangles on full images
    std::vector<Text> mTexts;
    PixelRect mColorBar;

    bool Paint(vtkContext2D* painter) override
    {
        for (const Picture& p : mPictures) {
            painter->DrawImage(toScene(p.where), p.data); // the data is already at display size
            if (p.outline >= 0)
                drawFrame(painter, p.where, getCropColor(p.outline), 2);
        }
        for (const auto& [rect, colour] : mOutlines)
            drawFrame(painter, rect, getCropColor(colour), 2);
        if (mColorBar.width > 0)
            drawFrame(painter, mColorBar, Color{40, 40, 40}, 1);
        detail::drawPixelTexts(painter, mTexts, mHeight);
        return true;
    }

private:
    //! Scene rectangle covering exactly the pixels of `r`. VTK's OpenGL context device maps
    //! scene [0.5, N - 0.5] onto the N pixels [0, N] of the viewport, i.e. scene 0.5 is the left
    //! (bottom) edge and each scene unit is N / (N - 1) pixels; this undoes that. (The PDF device
    //! maps scene units to points one to one, where the difference is invisible.)
    vtkRectf toScene(const PixelRect& r) const
    {
        auto mapX = [this](int p) { return float(p) * float(mWidth - 1) / float(mWidth) + 0.5f; };
        auto mapY = [this](int p) { return float(p) * float(mHeight - 1) / float(mHeight) + 0.5f; };
        const int bottom = mHeight - r.y - r.height; // pixels from the bottom edge
        const float x0 = mapX(r.x), y0 = mapY(bottom);
        return vtkRectf(x0, y0, mapX(r.x + r.width) - x0, mapY(bottom + r.height) - y0);
    }

    //! A frame `width` pixels wide just outside `rect`, as four filled pixel-aligned bands so
    //! that no edge blends into the picture.
    void drawFrame(vtkContext2D* painter, const PixelRect& rect, Color c, int width) const
    {
        painter->GetPen()->SetLineType(vtkPen::NO_PEN);
        painter->GetBrush()->SetColor(c.r, c.g, c.b, 255);
        const int w = width;
        for (const PixelRect& band :
             {PixelRect{rect.x - w, rect.y - w, rect.width + 2 * w, w},
              PixelRect{rect.x - w, rect.y + rect.height, rect.width + 2 * w, w},
              PixelRect{rect.x - w, rect.y, w, rect.height},
              PixelRect{rect.x + rect.width, rect.y, w, rect.height}}) {
            const vtkRectf r = toScene(band);
            painter->DrawRect(r.GetX(), r.GetY(), r.GetWidth(), r.GetHeight());
        }
        painter->GetPen()->SetLineType(vtkPen::SOLID_LINE);
    }

    static Color getCropColor(int index)
    {
        return kCropColors[std::size_t(index) % kCropColors.size()];
    }
};

vtkStandardNewMacro(ImageGridItem);

} // namespace

void writeImageGrid(const ImageGridSpec& spec, const std::string& pathWithoutExtension)
{
    const ImageGridLayout layout = computeImageGridLayout(spec);

    float lo = spec.errorMin, hi = spec.errorMax;
    if (hi <= lo) {
        hi = -std::numeric_limits<float>::infinity();
        for (const auto& row : spec.rows)
            for (const auto& cell : row)
                for (float e : cell.error.pixels)
                    hi = std::isfinite(e) ? std::max(hi, e) : hi;
        if (!(hi > lo))
            hi = lo + 1.0f;
    }

    auto lock = detail::lockRendering();
    detail::Figure figure(layout.width, layout.height);
    vtkNew<ImageGridItem> item;
    item->mWidth = layout.width;
    item->mHeight = layout.height;
    for (std::size_t r = 0; r < spec.rows.size(); ++r) {
        for (std::size_t c = 0; c < spec.rows[r].size(); ++c) {
            const auto& where = layout.cells[r][c];
            const Image<Color> shaded = shadeCell(spec.rows[r][c], spec, lo, hi);
            item->mPictures.push_back(
                {where.image,
                 makeVtkImage(shaded, {0, 0, shaded.width, shaded.height}, spec.imageScale)});
            for (std::size_t k = 0; k < spec.crops.size(); ++k) {
                item->mPictures.push_back(
                    {where.crops[k], makeVtkImage(shaded, spec.crops[k], spec.cropZoom), int(k)});
                const PixelRect& crop = spec.crops[k];
                item->mOutlines.push_back(
                    {{where.image.x + crop.x * spec.imageScale,
                      where.image.y + crop.y * spec.imageScale, crop.width * spec.imageScale,
                      crop.height * spec.imageScale},
                     int(k)});
            }
        }
    }

    const float ts = layout.textScale;
    const float headingY =
        float(layout.cells.front().front().image.y) - kColumnTitleHeight * ts / 2;
    if (!spec.title.empty())
        item->mTexts.push_back({layout.width / 2.0f, kMargin + kTitleHeight * ts / 2, spec.title,
                                kTitleFont * ts, true, VTK_TEXT_CENTERED, 0.0});
    for (std::size_t c = 0; c < spec.columnTitles.size(); ++c) {
        // Columns take the position of the first row that has them.
        for (std::size_t r = 0; r < layout.cells.size(); ++r) {
            if (c < layout.cells[r].size()) {
                const PixelRect& image = layout.cells[r][c].image;
                item->mTexts.push_back({image.x + image.width / 2.0f, headingY,
                                        spec.columnTitles[c], kHeadingFont * ts, false,
                                        VTK_TEXT_CENTERED, 0.0});
                break;
            }
        }
    }
    for (std::size_t r = 0; r < spec.rowTitles.size() && r < layout.cells.size(); ++r) {
        if (layout.cells[r].empty())
            continue;
        const PixelRect& image = layout.cells[r].front().image;
        item->mTexts.push_back({kMargin + kRowTitleWidth * ts / 2, image.y + image.height / 2.0f,
                                spec.rowTitles[r], kHeadingFont * ts, false, VTK_TEXT_CENTERED,
                                90.0});
    }

    if (layout.colorBar.width > 0) {
        const PixelRect& bar = layout.colorBar;
        Image<Color> ramp(bar.width, bar.height);
        for (int y = 0; y < bar.height; ++y)
            for (int x = 0; x < bar.width; ++x)
                ramp.at(x, y) = sampleColorMap(
                    spec.errorColorMap, 1.0f - float(y) / float(std::max(bar.height - 1, 1)));
        item->mPictures.push_back({bar, makeVtkImage(ramp, {0, 0, bar.width, bar.height}, 1)});
        item->mColorBar = bar;
        const float tickX = float(bar.x + bar.width) + 6 * ts;
        for (float f : {0.0f, 0.5f, 1.0f})
            item->mTexts.push_back({tickX, bar.y + bar.height * (1.0f - f),
                                    formatTick(lo + f * (hi - lo)), kTickFont * ts, false,
                                    VTK_TEXT_LEFT, 0.0});
        item->mTexts.push_back({float(bar.x), headingY, spec.errorLabel, kColorBarLabelFont * ts,
                                false, VTK_TEXT_LEFT, 0.0});
    }
    figure.addItem(item);
    figure.write(pathWithoutExtension, spec.title.empty() ? "Image comparison" : spec.title);
}

} // namespace rtlab::plot
