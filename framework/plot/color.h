#pragma once
// Colours for plots: a fixed qualitative palette with stable per-technique assignment, and the
// perceptual colour maps used for error images.

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace rtlab::plot {

//! An 8-bit sRGB colour.
struct Color {
    std::uint8_t r = 0;
    std::uint8_t g = 0;
    std::uint8_t b = 0;

    bool operator==(const Color&) const = default;

    //! "#rrggbb".
    std::string toHex() const;
    //! Parses "#rrggbb" or "rrggbb"; throws rtlab::Error on anything else.
    static Color fromHex(std::string_view hex);
};

//! The qualitative palette, in assignment order: the eight Okabe-Ito colours (blue, vermillion,
//! bluish green, reddish purple, orange, sky blue, yellow, black), then the ten Tableau 10 colours.
//! Past 18 names colours repeat.
const std::vector<Color>& getQualitativePalette();

//! Stable colours per name (technique, pass, ...).
//!
//! Construct it from every name of a study: the names are sorted and deduplicated and take the
//! palette in that order, so a name gets the same colour in every plot of the study whatever order
//! its series come in. Names not known yet get the first unused palette colour when first seen.
//! save()/load() keep a table with a study so that names added later do not reshuffle the others.
class ColorTable {
public:
    ColorTable() = default;
    //! Assigns the palette to the sorted, deduplicated `names`.
    explicit ColorTable(std::vector<std::string> names);

    //! The colour of `name`, assigning the next free palette colour if it is new.
    Color getColor(const std::string& name);
    //! The colour of `name` if it has one.
    bool findColor(const std::string& name, Color& color) const;
    //! Gives `name` a colour of the caller's choosing.
    void setColor(const std::string& name, Color color);
    //! Names in assignment order.
    const std::vector<std::string>& getNames() const { return mOrder; }

    //! Writes one "name<TAB>#rrggbb" line per name, in assignment order.
    void save(const std::string& path) const;
    //! Reads what save() wrote; throws rtlab::InputError naming the file and line on bad input.
    static ColorTable load(const std::string& path);

private:
    Color pickUnusedColor() const;

    std::map<std::string, Color> mColors;
    std::vector<std::string> mOrder;
};

//! Perceptually uniform colour maps (matplotlib's, by van der Walt and Smith).
enum class ColorMap { Viridis, Magma };

//! The colour of `map` at t in [0, 1] (clamped; NaN gives the colour at 0).
Color sampleColorMap(ColorMap map, float t);

} // namespace rtlab::plot
