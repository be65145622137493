#include "plot/charts.h"
#include "plot/color.h"

#include "core/error.h"
#include "plot_test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

using namespace rtlab::plot;

namespace {

double luminance(Color c)
{
    auto linear = [](std::uint8_t v) {
        const double s = v / 255.0;
        return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
    };
    return 0.2126 * linear(c.r) + 0.7152 * linear(c.g) + 0.0722 * linear(c.b);
}

} // namespace

TEST(ColorTest, HexRoundTrips)
{
    EXPECT_EQ(Color::fromHex("#0072B2"), (Color{0, 114, 178}));
    EXPECT_EQ(Color::fromHex("d55e00").toHex(), "#d55e00");
    EXPECT_THROW(Color::fromHex("#12345"), rtlab::Error);
    EXPECT_THROW(Color::fromHex("#12345g"), rtlab::Error);
}

TEST(ColorTest, PaletteStartsWithOkabeItoThenTableau10)
{
    const auto& palette = getQualitativePalette();
    ASSERT_EQ(palette.size(), 18u);
    EXPECT_EQ(palette[0].toHex(), "#0072b2"); // Okabe-Ito blue
    EXPECT_EQ(palette[1].toHex(), "#d55e00"); // vermillion
    EXPECT_EQ(palette[7].toHex(), "#000000"); // black
    EXPECT_EQ(palette[8].toHex(), "#4e79a7"); // Tableau 10 blue
    for (std::size_t i = 0; i < palette.size(); ++i)
        for (std::size_t j = i + 1; j < palette.size(); ++j)
            EXPECT_NE(palette[i], palette[j]) << i << " " << j;
}

TEST(ColorTest, StudyTableGivesTheSameColourWhateverTheOrder)
{
    ColorTable a({"ssao", "hbao", "gtao", "rtao"});
    ColorTable b({"rtao", "gtao", "ssao", "hbao", "gtao"});
    for (const char* name : {"gtao", "hbao", "rtao", "ssao"})
        EXPECT_EQ(a.getColor(name), b.getColor(name)) << name;
    // Sorted order takes the palette in order.
    EXPECT_EQ(a.getColor("gtao"), getQualitativePalette()[0]);
    EXPECT_EQ(a.getColor("ssao"), getQualitativePalette()[3]);
}

TEST(ColorTest, SeriesOrderDoesNotChangeColours)
{
    const ColorTable study({"hbao", "ssao", "gtao"});
    const std::vector<Series> forward = {{"ssao", {}, {}, {}}, {"hbao", {}, {}, {}}};
    const std::vector<Series> backward = {
        {"hbao", {}, {}, {}}, {"gtao", {}, {}, {}}, {"ssao", {}, {}, {}}};
    const auto f = getSeriesColors(forward, study);
    const auto b = getSeriesColors(backward, study);
    EXPECT_EQ(f[0], b[2]); // ssao
    EXPECT_EQ(f[1], b[0]); // hbao
    EXPECT_NE(f[0], f[1]);
}

TEST(ColorTest, NewNamesTakeUnusedColoursInFirstSeenOrder)
{
    ColorTable table({"a", "b"});
    table.setColor("c", getQualitativePalette()[2]);
    EXPECT_EQ(table.getColor("z"), getQualitativePalette()[3]);
    EXPECT_EQ(table.getColor("y"), getQualitativePalette()[4]);
    EXPECT_EQ(table.getNames(), (std::vector<std::string>{"a", "b", "c", "z", "y"}));
}

TEST(ColorTest, SavedTableLoadsBackAndKeepsColoursWhenNamesAreAdded)
{
    const std::string path = test::makeTempDir("colors") + "/colors.tsv";
    ColorTable before({"mc", "dc", "sn"});
    before.save(path);
    ColorTable after = ColorTable::load(path);
    EXPECT_EQ(after.getNames(), before.getNames());
    for (const char* name : {"mc", "dc", "sn"})
        EXPECT_EQ(after.getColor(name), before.getColor(name));
    // A technique added later gets a new colour; the old ones stay.
    const Color added = after.getColor("aa");
    for (const char* name : {"mc", "dc", "sn"})
        EXPECT_NE(added, before.getColor(name));

    std::ofstream(path) << "ok\t#000000\nbroken line\n";
    try {
        ColorTable::load(path);
        FAIL() << "expected an InputError";
    } catch (const rtlab::InputError& e) {
        EXPECT_EQ(e.location().line, 2);
    }
}

TEST(ColorTest, ColourMapsHaveTheirPublishedEndsAndRiseInLuminance)
{
    EXPECT_EQ(sampleColorMap(ColorMap::Viridis, 0.0f).toHex(), "#440154");
    EXPECT_EQ(sampleColorMap(ColorMap::Viridis, 1.0f).toHex(), "#fde725");
    EXPECT_EQ(sampleColorMap(ColorMap::Magma, 0.0f).toHex(), "#000004");
    EXPECT_EQ(sampleColorMap(ColorMap::Magma, 1.0f).toHex(), "#fcfdbf");
    EXPECT_EQ(sampleColorMap(ColorMap::Magma, 0.5f).toHex(), "#b73779");
    EXPECT_EQ(sampleColorMap(ColorMap::Viridis, -3.0f), sampleColorMap(ColorMap::Viridis, 0.0f));
    EXPECT_EQ(sampleColorMap(ColorMap::Viridis, 7.0f), sampleColorMap(ColorMap::Viridis, 1.0f));
    for (ColorMap map : {ColorMap::Viridis, ColorMap::Magma}) {
        double previous = -1.0;
        for (int i = 0; i <= 20; ++i) {
            const double y = luminance(sampleColorMap(map, float(i) / 20.0f));
            EXPECT_GT(y, previous) << "sample " << i;
            previous = y;
        }
    }
}
