#include "plot/color.h"

#include <algorithm>
#include <cmath>

namespace rtlab::plot {

namespace {

// Evenly spaced control points of matplotlib's colour maps, interpolated linearly in sRGB:
// viridis at t = i / 9 and magma at t = i / 10 (the values viridisLite and d3 publish).
const std::vector<Color>& getControlPoints(ColorMap map)
{
    auto parse = [](std::initializer_list<const char*> hexes) {
        std::vector<Color> colors;
        for (const char* hex : hexes)
            colors.push_back(Color::fromHex(hex));
        return colors;
    };
    static const std::vector<Color> kViridis =
        parse({"#440154", "#482878", "#3e4a89", "#31688e", "#26828e", "#1f9e89", "#35b779",
               "#6dcd59", "#b4de2c", "#fde725"});
    static const std::vector<Color> kMagma =
        parse({"#000004", "#140e36", "#3b0f70", "#641a80", "#8c2981", "#b73779", "#de4968",
               "#f7705c", "#fe9f6d", "#fecf92", "#fcfdbf"});
    return map == ColorMap::Magma ? kMagma : kViridis;
}

} // namespace

Color sampleColorMap(ColorMap map, float t)
{
    const std::vector<Color>& points = getControlPoints(map);
    t = std::isnan(t) ? 0.0f : std::clamp(t, 0.0f, 1.0f);
    const float position = t * float(points.size() - 1);
    const std::size_t i = std::min(std::size_t(position), points.size() - 2);
    const float f = position - float(i);
    const Color a = points[i], b = points[i + 1];
    auto mix = [f](std::uint8_t u, std::uint8_t v) {
        return std::uint8_t(std::lround(float(u) + (float(v) - float(u)) * f));
    };
    return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

} // namespace rtlab::plot
