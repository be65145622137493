#include "core/json.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace rtlab {

std::string jsonEscape(const std::string& text)
{
    std::string s = "\"";
    for (char c : text) {
        switch (c) {
        case '"': s += "\\\""; break;
        case '\\': s += "\\\\"; break;
        case '\n': s += "\\n"; break;
        case '\t': s += "\\t"; break;
        case '\r': s += "\\r"; break;
        default:
            if (static_cast<unsigned char>(c) < 0x20) {
                char buf[8];
                std::snprintf(buf, sizeof buf, "\\u%04x", c);
                s += buf;
            } else {
                s += c;
            }
        }
    }
    return s + "\"";
}

std::string jsonNumber(double value)
{
    if (!std::isfinite(value))
        return "null";
    char buf[64];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, value);
    (void)ec;
    return std::string(buf, end);
}

void JsonObject::addKey(const std::string& key)
{
    if (!mBody.empty())
        mBody += ',';
    mBody += jsonEscape(key) + ":";
}

JsonObject& JsonObject::add(const std::string& key, const std::string& value)
{
    addKey(key);
    mBody += jsonEscape(value);
    return *this;
}

JsonObject& JsonObject::add(const std::string& key, double value)
{
    addKey(key);
    mBody += jsonNumber(value);
    return *this;
}

JsonObject& JsonObject::add(const std::string& key, std::int64_t value)
{
    addKey(key);
    mBody += std::to_string(value);
    return *this;
}

JsonObject& JsonObject::add(const std::string& key, bool value)
{
    addKey(key);
    mBody += value ? "true" : "false";
    return *this;
}

JsonObject& JsonObject::addRaw(const std::string& key, const std::string& json)
{
    addKey(key);
    mBody += json;
    return *this;
}

std::string jsonArray(const std::vector<std::string>& encodedValues)
{
    std::string s = "[";
    for (std::size_t i = 0; i < encodedValues.size(); ++i)
        s += (i ? "," : "") + encodedValues[i];
    return s + "]";
}

} // namespace rtlab
