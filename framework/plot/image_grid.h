#pragma once
// Image comparison figures: a grid of renders (reference | each technique | error maps) with
// zoomed crops under every image and a colour bar for the error maps.

#include "core/image.h"
#include "plot/color.h"

#include <glm/vec3.hpp>

#include <string>
#include <vector>

namespace rtlab::plot {

//! A rectangle in pixels: x, y of the top-left corner (row 0 at the top), width, height.
struct PixelRect {
    int x = 0;
    int y = 0;
    int width = 0;
    int height = 0;

    bool operator==(const PixelRect&) const = default;
};

//! One image of the grid: a colour image, or a per-pixel error map shown through the colour map.
struct GridCell {
    Image<glm::vec3> color; //!< linear RGB; used when `error` is empty
    Image<float> error;     //!< when not empty the cell is an error map

    bool isErrorMap() const { return error.width > 0; }
};

//! A colour image cell.
GridCell makeColorCell(Image<glm::vec3> image);
//! An error map cell.
GridCell makeErrorCell(Image<float> error);
//! Per-pixel mean over channels of |image - reference|; both must have the same size.
Image<float> computeAbsoluteErrorMap(const Image<glm::vec3>& image,
                                     const Image<glm::vec3>& reference);

//! What to show. All images must have the same size; rows may be shorter than the longest row.
struct ImageGridSpec {
    std::string title;
    std::vector<std::string> columnTitles; //!< drawn above the first row
    std::vector<std::string> rowTitles;    //!< optional, drawn left of each row
    std::vector<std::vector<GridCell>> rows;
    std::vector<PixelRect> crops; //!< image pixels, outlined on every image and shown zoomed below
    int cropZoom = 4;             //!< integer magnification of crops, nearest neighbour
    int imageScale = 1;           //!< integer magnification of the full images
    bool encodeSrgb = true;       //!< colour cells: clamp to [0, 1] then apply the sRGB curve
    ColorMap errorColorMap = ColorMap::Viridis;
    float errorMin = 0.0f;
    float errorMax = -1.0f; //!< <= errorMin: the largest finite value of all error maps
    std::string errorLabel = "absolute error (unitless)";
};

//! Where things land in the output image, in PNG pixels (row 0 at the top).
struct ImageGridLayout {
    int width = 0;
    int height = 0;
    struct Cell {
        PixelRect image;              //!< the full image (imageScale applied)
        std::vector<PixelRect> crops; //!< each zoomed crop, in spec.crops order
    };
    std::vector<std::vector<Cell>> cells; //!< [row][column], for the cells present
    PixelRect colorBar;                   //!< empty when there is no error map
    float textScale = 1.0f; //!< fonts and text bands grow with the images (1 up to 320 pixels)
};

//! The layout writeImageGrid uses. Throws rtlab::Error on inconsistent input (sizes differ, a crop
//! outside the image, zoom < 1).
ImageGridLayout computeImageGridLayout(const ImageGridSpec& spec);

//! Writes <pathWithoutExtension>.png and .pdf (images embedded as rasters, text as text).
void writeImageGrid(const ImageGridSpec& spec, const std::string& pathWithoutExtension);

} // namespace rtlab::plot
