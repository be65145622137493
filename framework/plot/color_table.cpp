#include "plot/color.h"

#include "core/error.h"

#include <algorithm>
#include <charconv>
#include <fstream>

namespace rtlab::plot {

std::string Color::toHex() const
{
    static constexpr char kDigits[] = "0123456789abcdef";
    std::string hex = "#";
    for (std::uint8_t c : {r, g, b}) {
        hex += kDigits[c >> 4];
        hex += kDigits[c & 15];
    }
    return hex;
}

Color Color::fromHex(std::string_view hex)
{
    if (!hex.empty() && hex.front() == '#')
        hex.remove_prefix(1);
    std::uint8_t channels[3] = {};
    bool ok = hex.size() == 6;
    for (int i = 0; ok && i < 3; ++i) {
        const char* begin = hex.data() + 2 * i;
        auto [end, ec] = std::from_chars(begin, begin + 2, channels[i], 16);
        ok = ec == std::errc() && end == begin + 2;
    }
    if (!ok)
        throw Error("not a colour (expected #rrggbb): '" + std::string(hex) + "'");
    return {channels[0], channels[1], channels[2]};
}

const std::vector<Color>& getQualitativePalette()
{
    // Okabe & Ito (2008), "Color Universal Design", reordered so that the first colours are the
    // most distinct on white; then Tableau 10 (2016).
    static const std::vector<Color> kPalette = [] {
        std::vector<Color> palette;
        for (const char* hex : {"#0072b2", "#d55e00", "#009e73", "#cc79a7", "#e69f00", "#56b4e9",
                                "#f0e442", "#000000", "#4e79a7", "#f28e2b", "#e15759", "#76b7b2",
                                "#59a14f", "#edc948", "#b07aa1", "#ff9da7", "#9c755f", "#bab0ac"})
            palette.push_back(Color::fromHex(hex));
        return palette;
    }();
    return kPalette;
}

ColorTable::ColorTable(std::vector<std::string> names)
{
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
    for (const auto& name : names)
        getColor(name);
}

Color ColorTable::getColor(const std::string& name)
{
    if (auto it = mColors.find(name); it != mColors.end())
        return it->second;
    const Color color = pickUnusedColor();
    mColors.emplace(name, color);
    mOrder.push_back(name);
    return color;
}

bool ColorTable::findColor(const std::string& name, Color& color) const
{
    const auto it = mColors.find(name);
    if (it == mColors.end())
        return false;
    color = it->second;
    return true;
}

void ColorTable::setColor(const std::string& name, Color color)
{
    if (mColors.insert_or_assign(name, color).second)
        mOrder.push_back(name);
}

Color ColorTable::pickUnusedColor() const
{
    const auto& palette = getQualitativePalette();
    for (const Color& candidate : palette) {
        const bool used = std::any_of(mColors.begin(), mColors.end(),
                                      [&](const auto& entry) { return entry.second == candidate; });
        if (!used)
            return candidate;
    }
    return palette[mOrder.size() % palette.size()];
}

void ColorTable::save(const std::string& path) const
{
    std::ofstream out(path);
    for (const auto& name : mOrder)
        out << name << '\t' << mColors.at(name).toHex() << '\n';
    if (!out)
        throw Error("cannot write the colour table " + path);
}

ColorTable ColorTable::load(const std::string& path)
{
    std::ifstream in(path);
    if (!in)
        throw InputError({path}, "cannot read the colour table");
    ColorTable table;
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (line.empty())
            continue;
        const auto tab = line.rfind('\t');
        if (tab == std::string::npos || tab == 0)
            throw InputError({path, number}, "expected '<name><TAB>#rrggbb'");
        try {
            table.setColor(line.substr(0, tab), Color::fromHex(line.substr(tab + 1)));
        } catch (const Error& e) {
            throw InputError({path, number, int(tab) + 2}, e.what());
        }
    }
    return table;
}

} // namespace rtlab::plot
