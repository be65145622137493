#include "plot/image_grid.h"

#include "core/error.h"
#include "plot_test_support.h"

#include <gtest/gtest.h>

#include <cstdlib>

using namespace rtlab;
using namespace rtlab::plot;

namespace {

constexpr int kWidth = 64;
constexpr int kHeight = 48;
const PixelRect kCrop{10, 12, 4, 3};

//! Pure colours that the display transform maps to 0 or 255 exactly.
glm::vec3 patternColor(int i, int j)
{
    const int k = (i + 3 * j) % 6;
    const glm::vec3 colours[6] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 1, 1}};
    return colours[k];
}

Color toColor(glm::vec3 c)
{
    return {std::uint8_t(c.x * 255), std::uint8_t(c.y * 255), std::uint8_t(c.z * 255)};
}

//! A dark grey image with a pattern of pure colours inside kCrop.
Image<glm::vec3> makeTestImage(float grey)
{
    Image<glm::vec3> image(kWidth, kHeight, glm::vec3(grey));
    for (int j = 0; j < kCrop.height; ++j)
        for (int i = 0; i < kCrop.width; ++i)
            image.at(kCrop.x + i, kCrop.y + j) = patternColor(i, j);
    return image;
}

ImageGridSpec makeSpec(int zoom)
{
    const Image<glm::vec3> reference = makeTestImage(0.0f);
    Image<glm::vec3> noisy = makeTestImage(0.0f);
    noisy.at(40, 30) = glm::vec3(0.5f);
    ImageGridSpec spec;
    spec.title = "Ambient occlusion, cornell_box";
    spec.columnTitles = {"reference", "ssao", "ssao error"};
    spec.rowTitles = {"frame 0"};
    spec.rows = {{makeColorCell(reference), makeColorCell(noisy),
                  makeErrorCell(computeAbsoluteErrorMap(noisy, reference))}};
    spec.crops = {kCrop, {36, 26, 8, 8}};
    spec.cropZoom = zoom;
    spec.errorLabel = "absolute error (AO, unitless)";
    return spec;
}

class ImageGridTest : public ::testing::Test {
protected:
    void SetUp() override { ::unsetenv("DISPLAY"); }
};

} // namespace

TEST(ImageGridLayoutTest, CropsAreMagnifiedAndPlacedUnderTheirImage)
{
    const ImageGridSpec spec = makeSpec(5);
    const ImageGridLayout layout = computeImageGridLayout(spec);
    ASSERT_EQ(layout.cells.size(), 1u);
    ASSERT_EQ(layout.cells[0].size(), 3u);
    for (const auto& cell : layout.cells[0]) {
        EXPECT_EQ(cell.image.width, kWidth);
        EXPECT_EQ(cell.image.height, kHeight);
        ASSERT_EQ(cell.crops.size(), 2u);
        EXPECT_EQ(cell.crops[0].width, kCrop.width * 5);
        EXPECT_EQ(cell.crops[0].height, kCrop.height * 5);
        EXPECT_EQ(cell.crops[1].width, 40);
        EXPECT_GT(cell.crops[0].y, cell.image.y + cell.image.height);
        EXPECT_LE(cell.crops[1].x + cell.crops[1].width, layout.width);
        EXPECT_LE(cell.crops[1].y + cell.crops[1].height, layout.height);
    }
    EXPECT_GT(layout.colorBar.width, 0);
    EXPECT_GT(layout.colorBar.x, layout.cells[0][2].image.x + kWidth);
}

TEST(ImageGridLayoutTest, InconsistentInputIsRejected)
{
    ImageGridSpec spec = makeSpec(4);
    spec.crops = {{60, 40, 8, 8}};
    EXPECT_THROW(computeImageGridLayout(spec), Error);
    spec = makeSpec(0);
    EXPECT_THROW(computeImageGridLayout(spec), Error);
    spec = makeSpec(4);
    spec.rows[0].push_back(makeColorCell(Image<glm::vec3>(8, 8)));
    EXPECT_THROW(computeImageGridLayout(spec), Error);
    EXPECT_THROW(computeAbsoluteErrorMap(Image<glm::vec3>(2, 2), Image<glm::vec3>(3, 2)), Error);
}

TEST_F(ImageGridTest, ZoomedCropShowsThePatternMagnifiedAtItsPlace)
{
    for (int zoom : {3, 5}) {
        const ImageGridSpec spec = makeSpec(zoom);
        const ImageGridLayout layout = computeImageGridLayout(spec);
        const std::string base = test::makeTempDir("zoom" + std::to_string(zoom)) + "/grid";
        writeImageGrid(spec, base);
        const test::Pixels png = test::readPng(base + ".png");
        ASSERT_EQ(png.width, layout.width);
        ASSERT_EQ(png.height, layout.height);
        for (std::size_t column = 0; column < 2; ++column) {
            const auto& cell = layout.cells[0][column];
            // Every pixel of every magnified block has the pattern's colour.
            const PixelRect& crop = cell.crops[0];
            for (int y = 0; y < crop.height; ++y)
                for (int x = 0; x < crop.width; ++x)
                    ASSERT_EQ(png.at(crop.x + x, crop.y + y),
                              toColor(patternColor(x / zoom, y / zoom)))
                        << "zoom " << zoom << ", column " << column << ", crop pixel " << x << ", "
                        << y;
            // The full image is shown 1:1: every pixel but those under the crop outlines, which
            // are drawn in the two pixels around each crop rectangle.
            const Image<glm::vec3>& shown = spec.rows[0][column].color;
            int compared = 0;
            for (int y = 0; y < kHeight; ++y) {
                for (int x = 0; x < kWidth; ++x) {
                    bool underOutline = false;
                    for (const PixelRect& c : spec.crops)
                        underOutline =
                            underOutline ||
                            (x >= c.x - 2 && x < c.x + c.width + 2 && y >= c.y - 2 &&
                             y < c.y + c.height + 2 &&
                             !(x >= c.x && x < c.x + c.width && y >= c.y && y < c.y + c.height));
                    if (underOutline)
                        continue;
                    const glm::vec3 v = shown.at(x, y);
                    // 0.5 encodes to 188 in sRGB.
                    const Color expected = v.x == 0.5f ? Color{188, 188, 188} : toColor(v);
                    ASSERT_EQ(png.at(cell.image.x + x, cell.image.y + y), expected)
                        << "column " << column << ", image pixel " << x << ", " << y;
                    ++compared;
                }
            }
            EXPECT_GT(compared, kWidth * kHeight * 9 / 10);
        }
        // The crop outline colour frames the zoomed crop just outside it.
        const PixelRect& zoomed = layout.cells[0][0].crops[0];
        EXPECT_EQ(png.at(zoomed.x - 1, zoomed.y + 2), (Color{255, 208, 0}));
        // The error map: zero error shows the colour map's low end, the one noisy pixel (error
        // 0.5, the maximum) its high end, 1:1.
        const auto& errorCell = layout.cells[0][2];
        EXPECT_EQ(png.at(errorCell.image.x + 2, errorCell.image.y + 2),
                  sampleColorMap(ColorMap::Viridis, 0.0f));
        EXPECT_EQ(png.at(errorCell.image.x + 40, errorCell.image.y + 30),
                  sampleColorMap(ColorMap::Viridis, 1.0f));
        // The colour bar runs from the high end at the top to the low end at the bottom.
        const PixelRect& bar = layout.colorBar;
        EXPECT_EQ(png.at(bar.x + bar.width / 2, bar.y), sampleColorMap(ColorMap::Viridis, 1.0f));
        EXPECT_EQ(png.at(bar.x + bar.width / 2, bar.y + bar.height - 1),
                  sampleColorMap(ColorMap::Viridis, 0.0f));
    }
}

TEST_F(ImageGridTest, PdfCarriesTheImagesAndTheTitlesAsText)
{
    const ImageGridSpec spec = makeSpec(4);
    const std::string base = test::makeTempDir("pdf") + "/grid";
    writeImageGrid(spec, base);
    const std::string pdf = test::readBytes(base + ".pdf");
    ASSERT_GE(pdf.size(), 5u);
    EXPECT_EQ(pdf.substr(0, 5), "%PDF-");
    EXPECT_NE(pdf.find("/Subtype /Image"), std::string::npos);
    const auto strings = test::extractPdfStrings(test::readPdfContent(base + ".pdf"));
    for (const std::string& text : {spec.title, spec.columnTitles[0], spec.columnTitles[2],
                                    spec.rowTitles[0], spec.errorLabel, std::string("0.5")}) {
        bool found = false;
        for (const auto& s : strings)
            found = found || s == text;
        EXPECT_TRUE(found) << "'" << text << "' is not text in the PDF";
    }
}
