#include "plot_test_support.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace rtlab::plot::test {

Color Pixels::at(int x, int y) const
{
    const std::uint8_t* p = rgb.data() + 3 * (std::size_t(y) * width + x);
    return {p[0], p[1], p[2]};
}

std::size_t Pixels::count(Color c) const
{
    std::size_t n = 0;
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
        n += rgb[i] == c.r && rgb[i + 1] == c.g && rgb[i + 2] == c.b;
    return n;
}

std::size_t Pixels::countDistinct() const
{
    std::set<std::uint32_t> colours;
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
        colours.insert(std::uint32_t(rgb[i]) << 16 | std::uint32_t(rgb[i + 1]) << 8 | rgb[i + 2]);
    return colours.size();
}

Pixels readPng(const std::string& path)
{
    Pixels pixels;
    auto input = OIIO::ImageInput::open(path);
    if (!input) {
        ADD_FAILURE() << "cannot open " << path << ": " << OIIO::geterror();
        return pixels;
    }
    const OIIO::ImageSpec& spec = input->spec();
    pixels.width = spec.width;
    pixels.height = spec.height;
    std::vector<std::uint8_t> all(std::size_t(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, all.data()));
    pixels.rgb.resize(std::size_t(spec.width) * spec.height * 3);
    for (std::size_t i = 0; i < std::size_t(spec.width) * spec.height; ++i)
        for (int c = 0; c < 3; ++c)
            pixels.rgb[3 * i + c] = all[i * spec.nchannels + std::min(c, spec.nchannels - 1)];
    return pixels;
}

std::string readBytes(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

namespace {

std::string inflateBytes(const std::string& compressed)
{
    z_stream z{};
    if (inflateInit(&z) != Z_OK)
        return {};
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
    z.avail_in = uInt(compressed.size());
    std::string out;
    char buffer[16384];
    int status = Z_OK;
    while (status == Z_OK) {
        z.next_out = reinterpret_cast<Bytef*>(buffer);
        z.avail_out = sizeof(buffer);
        status = inflate(&z, Z_NO_FLUSH);
        out.append(buffer, sizeof(buffer) - z.avail_out);
    }
    inflateEnd(&z);
    return out;
}

} // namespace

std::string readPdfContent(const std::string& path)
{
    const std::string pdf = readBytes(path);
    std::string content;
    std::size_t at = 0;
    while ((at = pdf.find("stream", at)) != std::string::npos) {
        if (at >= 3 && pdf.compare(at - 3, 3, "end") == 0) {
            at += 6;
            continue;
        }
        const std::size_t dictionaryStart = pdf.rfind("obj", at);
        const std::string dictionary = pdf.substr(dictionaryStart, at - dictionaryStart);
        std::size_t begin = at + 6;
        if (pdf.compare(begin, 2, "\r\n") == 0)
            begin += 2;
        else if (pdf[begin] == '\n')
            begin += 1;
        const std::size_t end = pdf.find("endstream", begin);
        if (end == std::string::npos)
            break;
        const std::string raw = pdf.substr(begin, end - begin);
        if (dictionary.find("/Image") == std::string::npos) // content, not pixels
            content +=
                dictionary.find("/FlateDecode") != std::string::npos ? inflateBytes(raw) : raw;
        content += '\n';
        at = end + 9;
    }
    return content;
}

std::vector<std::string> extractPdfStrings(const std::string& content)
{
    std::vector<std::string> strings;
    std::string pending; // strings of a TJ array or awaiting their operator
    bool inArray = false;
    std::size_t i = 0;
    auto readLiteral = [&]() {
        std::string s;
        int depth = 1;
        for (++i; i < content.size(); ++i) {
            const char c = content[i];
            if (c == '\\' && i + 1 < content.size()) {
                const char e = content[++i];
                if (e >= '0' && e <= '7') {
                    int value = 0;
                    for (int k = 0;
                         k < 3 && i < content.size() && content[i] >= '0' && content[i] <= '7';
                         ++k, ++i)
                        value = value * 8 + (content[i] - '0');
                    --i;
                    s += char(value);
                } else {
                    s += e == 'n' ? '\n' : e == 'r' ? '\r' : e == 't' ? '\t' : e;
                }
            } else if (c == '(') {
                ++depth;
                s += c;
            } else if (c == ')') {
                if (--depth == 0)
                    break;
                s += c;
            } else {
                s += c;
            }
        }
        ++i;
        return s;
    };
    auto readHex = [&]() {
        std::string s, digits;
        for (++i; i < content.size() && content[i] != '>'; ++i)
            if (std::isxdigit(static_cast<unsigned char>(content[i])))
                digits += content[i];
        ++i;
        if (digits.size() % 2)
            digits += '0';
        for (std::size_t k = 0; k < digits.size(); k += 2)
            s += char(std::stoi(digits.substr(k, 2), nullptr, 16));
        return s;
    };
    while (i < content.size()) {
        const char c = content[i];
        if (c == '(') {
            pending += readLiteral();
        } else if (c == '<' && i + 1 < content.size() && content[i + 1] != '<') {
            pending += readHex();
        } else if (c == '[') {
            inArray = true;
            pending.clear();
            ++i;
        } else if (c == ']') {
            inArray = false;
            ++i;
        } else if (!inArray && (content.compare(i, 2, "Tj") == 0 ||
                                content.compare(i, 2, "TJ") == 0 || c == '\'' || c == '"')) {
            strings.push_back(pending);
            pending.clear();
            i += c == 'T' ? 2 : 1;
        } else if (!inArray && std::isalpha(static_cast<unsigned char>(c))) {
            pending.clear(); // another operator consumed the operands
            while (i < content.size() && std::isalpha(static_cast<unsigned char>(content[i])))
                ++i;
        } else {
            ++i;
        }
    }
    return strings;
}

std::string makeTempDir(const std::string& name)
{
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "rtlab_plot_test" /
                                      (std::string(info->test_suite_name()) + "." + info->name()) /
                                      name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir.string();
}

} // namespace rtlab::plot::test
