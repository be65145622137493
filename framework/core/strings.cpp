#include "core/strings.h"

#include "core/error.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace rtlab {

std::size_t editDistance(std::string_view a, std::string_view b)
{
    std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j)
        prev[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        cur[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t subst = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
            cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, subst});
        }
        std::swap(prev, cur);
    }
    return prev[b.size()];
}

std::vector<std::string> closestNames(std::string_view name, const std::vector<std::string>& candidates,
                                      std::size_t maxCount)
{
    const std::size_t limit = std::max<std::size_t>(2, name.size() / 3);
    std::vector<std::pair<std::size_t, std::string>> scored;
    for (const auto& c : candidates) {
        const std::size_t d = editDistance(name, c);
        if (d <= limit)
            scored.emplace_back(d, c);
    }
    std::stable_sort(scored.begin(), scored.end(),
                     [](const auto& x, const auto& y) { return x.first < y.first; });
    std::vector<std::string> out;
    for (std::size_t i = 0; i < scored.size() && i < maxCount; ++i)
        out.push_back(scored[i].second);
    return out;
}

std::string joinList(const std::vector<std::string>& items, std::string_view conjunction)
{
    std::string s;
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (i > 0)
            s += (!conjunction.empty() && i + 1 == items.size()) ? " " + std::string(conjunction) + " "
                                                                 : std::string(", ");
        s += items[i];
    }
    return s;
}

std::string readTextFile(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw InputError({path, 0, 0}, "cannot open file for reading");
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void writeTextFileAtomically(const std::string& path, const std::string& text)
{
    {
        std::ofstream out(path + ".tmp", std::ios::binary | std::ios::trunc);
        out << text;
        out.close();
        if (!out)
            throw Error(path + ": cannot write");
    }
    std::filesystem::rename(path + ".tmp", path);
}

std::string quoteCsvField(const std::string& text)
{
    if (text.find_first_of(",\"\n") == std::string::npos)
        return text;
    std::string quoted = "\"";
    for (char c : text)
        quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

} // namespace rtlab
