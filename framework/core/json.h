#pragma once
// Minimal JSON output for results rows and manifests (reading goes through yaml-cpp, which
// parses JSON). Non-finite numbers are written as null.

#include <cstdint>
#include <string>
#include <vector>

namespace rtlab {

std::string jsonEscape(const std::string& text);  //!< quoted JSON string literal

class JsonObject {
public:
    JsonObject& add(const std::string& key, const std::string& value);
    JsonObject& add(const std::string& key, const char* value) { return add(key, std::string(value)); }
    JsonObject& add(const std::string& key, double value);
    JsonObject& add(const std::string& key, std::int64_t value);
    JsonObject& add(const std::string& key, int value) { return add(key, std::int64_t(value)); }
    JsonObject& add(const std::string& key, std::size_t value) { return add(key, std::int64_t(value)); }
    JsonObject& add(const std::string& key, bool value);
    //! `json` must already be valid JSON (an object, array, ...).
    JsonObject& addRaw(const std::string& key, const std::string& json);
    std::string str() const { return "{" + mBody + "}"; }

private:
    void addKey(const std::string& key);
    std::string mBody;
};

//! "[a,b,c]" from already-encoded JSON values.
std::string jsonArray(const std::vector<std::string>& encodedValues);
//! Shortest round-trip text of a double, "null" when not finite.
std::string jsonNumber(double value);

} // namespace rtlab
