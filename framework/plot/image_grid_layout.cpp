// Where the pieces of an image grid go. No VTK here, so that tests can check the layout.

#include "plot/image_grid.h"

#include "plot/image_grid_style.h"

#include "core/error.h"

#include <glm/common.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::plot {

GridCell makeColorCell(Image<glm::vec3> image)
{
    GridCell cell;
    cell.color = std::move(image);
    return cell;
}

GridCell makeErrorCell(Image<float> error)
{
    GridCell cell;
    cell.error = std::move(error);
    return cell;
}

Image<float> computeAbsoluteErrorMap(const Image<glm::vec3>& image,
                                     const Image<glm::vec3>& reference)
{
    if (image.width != reference.width || image.height != reference.height)
        throw Error("error map: image is " + std::to_string(image.width) + " x " +
                    std::to_string(image.height) + " but the reference is " +
                    std::to_string(reference.width) + " x " + std::to_string(reference.height));
    Image<float> error(image.width, image.height);
    for (std::size_t i = 0; i < image.size(); ++i) {
        const glm::vec3 d = glm::abs(image.pixels[i] - reference.pixels[i]);
        error.pixels[i] = (d.x + d.y + d.z) / 3.0f;
    }
    return error;
}

namespace detail {

int estimateTextWidth(const std::string& text, float fontSize)
{
    return int(std::ceil(float(text.size()) * fontSize * kAverageGlyphWidth));
}

} // namespace detail

ImageGridLayout computeImageGridLayout(const ImageGridSpec& spec)
{
    using namespace detail;
    if (spec.cropZoom < 1 || spec.imageScale < 1)
        throw Error("image grid: cropZoom and imageScale must be at least 1");
    int imageWidth = -1, imageHeight = -1;
    bool anyError = false;
    std::size_t columns = 0;
    for (const auto& row : spec.rows) {
        columns = std::max(columns, row.size());
        for (const auto& cell : row) {
            const int w = cell.isErrorMap() ? cell.error.width : cell.color.width;
            const int h = cell.isErrorMap() ? cell.error.height : cell.color.height;
            anyError = anyError || cell.isErrorMap();
            if (w <= 0 || h <= 0)
                throw Error("image grid: a cell has no image");
            if (imageWidth >= 0 && (w != imageWidth || h != imageHeight))
                throw Error("image grid: images differ in size (" + std::to_string(w) + " x " +
                            std::to_string(h) + " and " + std::to_string(imageWidth) + " x " +
                            std::to_string(imageHeight) + ")");
            imageWidth = w;
            imageHeight = h;
        }
    }
    if (columns == 0)
        throw Error("image grid: no images");
    for (const PixelRect& c : spec.crops)
        if (c.width <= 0 || c.height <= 0 || c.x < 0 || c.y < 0 || c.x + c.width > imageWidth ||
            c.y + c.height > imageHeight)
            throw Error("image grid: crop (" + std::to_string(c.x) + ", " + std::to_string(c.y) +
                        ", " + std::to_string(c.width) + " x " + std::to_string(c.height) +
                        ") is not inside the " + std::to_string(imageWidth) + " x " +
                        std::to_string(imageHeight) + " images");

    const int shownWidth = imageWidth * spec.imageScale;
    const int shownHeight = imageHeight * spec.imageScale;
    ImageGridLayout layout;
    layout.textScale = std::clamp(float(shownWidth) / kTextScaleWidth, 1.0f, kMaxTextScale);
    auto scaled = [&](int size) { return int(std::ceil(float(size) * layout.textScale)); };
    int stripWidth = 0, stripHeight = 0;
    for (const PixelRect& c : spec.crops) {
        stripWidth += c.width * spec.cropZoom + (stripWidth > 0 ? kGap : 0);
        stripHeight = std::max(stripHeight, c.height * spec.cropZoom);
    }
    const int cellWidth = std::max(shownWidth, stripWidth);
    const int rowHeight = shownHeight + (stripHeight > 0 ? kGap + stripHeight : 0);

    const int left = kMargin + (spec.rowTitles.empty() ? 0 : scaled(kRowTitleWidth));
    const int top = kMargin + (spec.title.empty() ? 0 : scaled(kTitleHeight)) +
                    (spec.columnTitles.empty() && !anyError ? 0 : scaled(kColumnTitleHeight));
    for (std::size_t r = 0; r < spec.rows.size(); ++r) {
        const int y = top + int(r) * (rowHeight + kRowGap);
        auto& cells = layout.cells.emplace_back();
        for (std::size_t c = 0; c < spec.rows[r].size(); ++c) {
            const int x = left + int(c) * (cellWidth + kColumnGap);
            ImageGridLayout::Cell cell;
            cell.image = {x + (cellWidth - shownWidth) / 2, y, shownWidth, shownHeight};
            int cropX = x + (cellWidth - stripWidth) / 2;
            for (const PixelRect& crop : spec.crops) {
                cell.crops.push_back({cropX, y + shownHeight + kGap, crop.width * spec.cropZoom,
                                      crop.height * spec.cropZoom});
                cropX += crop.width * spec.cropZoom + kGap;
            }
            cells.push_back(std::move(cell));
        }
    }
    int right = left + int(columns) * cellWidth + int(columns - 1) * kColumnGap;
    if (anyError) {
        layout.colorBar = {right + kColorBarGap, top, scaled(kColorBarWidth), shownHeight};
        const int labelWidth =
            estimateTextWidth(spec.errorLabel, kColorBarLabelFont * layout.textScale);
        right = layout.colorBar.x + std::max(scaled(kColorBarWidth + kTickLabelWidth), labelWidth);
    }
    layout.width = right + kMargin;
    layout.height = top + int(spec.rows.size()) * (rowHeight + kRowGap) - kRowGap + kMargin;
    return layout;
}

} // namespace rtlab::plot
