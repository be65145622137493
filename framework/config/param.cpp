#include "config/param.h"

#include "core/json.h"
#include "core/strings.h"

#include <charconv>
#include <cmath>
#include <stdexcept>

namespace rtlab::config {

const char* toString(ParamType type)
{
    switch (type) {
    case ParamType::Bool: return "bool";
    case ParamType::Int: return "int";
    case ParamType::Float: return "float";
    case ParamType::String: return "string";
    case ParamType::Enum: return "enum";
    }
    return "?";
}

static std::string formatNumber(double v)
{
    if (std::isinf(v))
        return v > 0 ? "inf" : "-inf";
    char buf[64];
    auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
    (void)ec;
    return std::string(buf, end);
}

std::string formatValue(const ParamValue& value)
{
    struct Visitor {
        std::string operator()(bool b) const { return b ? "true" : "false"; }
        std::string operator()(std::int64_t i) const { return std::to_string(i); }
        std::string operator()(double d) const { return formatNumber(d); }
        std::string operator()(const std::string& s) const { return s; }
    };
    return std::visit(Visitor{}, value);
}

std::string ParamSpec::describeRange() const
{
    if (type == ParamType::Enum)
        return "{" + joinList(choices) + "}";
    if (type != ParamType::Int && type != ParamType::Float)
        return "";
    if (std::isinf(min) && std::isinf(max))
        return "";
    return (std::isinf(min) ? "(-inf" : "[" + formatNumber(min)) + ", " +
           (std::isinf(max) ? "inf)" : formatNumber(max) + "]");
}

std::string ParamSpec::checkValue(const ParamValue& value) const
{
    switch (type) {
    case ParamType::Bool:
        if (!std::holds_alternative<bool>(value))
            return "expected a bool (true or false)";
        return "";
    case ParamType::Int: {
        if (!std::holds_alternative<std::int64_t>(value))
            return "expected an integer";
        const auto v = double(std::get<std::int64_t>(value));
        if (v < min || v > max)
            return "expected an integer in " + describeRange();
        return "";
    }
    case ParamType::Float: {
        double v;
        if (std::holds_alternative<double>(value))
            v = std::get<double>(value);
        else if (std::holds_alternative<std::int64_t>(value))
            v = double(std::get<std::int64_t>(value));
        else
            return "expected a number";
        if (!std::isfinite(v))
            return "expected a finite number";
        if (v < min || v > max)
            return "expected a number in " + describeRange();
        return "";
    }
    case ParamType::String:
        if (!std::holds_alternative<std::string>(value))
            return "expected a string";
        return "";
    case ParamType::Enum:
        if (!std::holds_alternative<std::string>(value))
            return "expected one of " + joinList(choices, "or");
        for (const auto& c : choices)
            if (c == std::get<std::string>(value))
                return "";
        return "expected one of " + joinList(choices, "or");
    }
    return "unknown type";
}

ParamSchema& ParamSchema::add(ParamSpec spec)
{
    if (find(spec.name))
        throw std::logic_error("parameter '" + spec.name + "' declared twice");
    if (const auto problem = spec.checkValue(spec.defaultValue); !problem.empty())
        throw std::logic_error("default of parameter '" + spec.name + "' is invalid: " + problem);
    mSpecs.push_back(std::move(spec));
    return *this;
}

ParamSchema& ParamSchema::addBool(std::string name, bool defaultValue, std::string doc)
{
    return add({.name = std::move(name), .type = ParamType::Bool, .defaultValue = defaultValue,
                .doc = std::move(doc)});
}

ParamSchema& ParamSchema::addInt(std::string name, std::int64_t defaultValue, std::int64_t min,
                                 std::int64_t max, std::string unit, std::string doc)
{
    return add({.name = std::move(name), .type = ParamType::Int, .defaultValue = defaultValue,
                .min = double(min), .max = double(max), .unit = std::move(unit), .doc = std::move(doc)});
}

ParamSchema& ParamSchema::addFloat(std::string name, double defaultValue, double min, double max,
                                   std::string unit, std::string doc)
{
    return add({.name = std::move(name), .type = ParamType::Float, .defaultValue = defaultValue,
                .min = min, .max = max, .unit = std::move(unit), .doc = std::move(doc)});
}

ParamSchema& ParamSchema::addEnum(std::string name, std::string defaultValue,
                                  std::vector<std::string> choices, std::string doc)
{
    return add({.name = std::move(name), .type = ParamType::Enum, .defaultValue = std::move(defaultValue),
                .choices = std::move(choices), .doc = std::move(doc)});
}

ParamSchema& ParamSchema::addString(std::string name, std::string defaultValue, std::string doc)
{
    return add({.name = std::move(name), .type = ParamType::String,
                .defaultValue = std::move(defaultValue), .doc = std::move(doc)});
}

const ParamSpec* ParamSchema::find(const std::string& name) const
{
    for (const auto& s : mSpecs)
        if (s.name == name)
            return &s;
    return nullptr;
}

std::vector<std::string> ParamSchema::names() const
{
    std::vector<std::string> n;
    for (const auto& s : mSpecs)
        n.push_back(s.name);
    return n;
}

ParamSet ParamSet::defaultsOf(const ParamSchema& schema)
{
    ParamSet set;
    for (const auto& s : schema.specs())
        set.set(s.name, s.defaultValue);
    return set;
}

const ParamValue& ParamSet::get(const std::string& name) const
{
    auto it = mValues.find(name);
    if (it == mValues.end())
        throw std::out_of_range("parameter '" + name + "' is not set");
    return it->second;
}

bool ParamSet::getBool(const std::string& name) const
{
    return std::get<bool>(get(name));
}

std::int64_t ParamSet::getInt(const std::string& name) const
{
    return std::get<std::int64_t>(get(name));
}

double ParamSet::getFloat(const std::string& name) const
{
    const auto& v = get(name);
    if (std::holds_alternative<std::int64_t>(v))
        return double(std::get<std::int64_t>(v));
    return std::get<double>(v);
}

const std::string& ParamSet::getString(const std::string& name) const
{
    return std::get<std::string>(get(name));
}

std::string ParamSet::toString() const
{
    std::string s;
    for (const auto& [k, v] : mValues) {
        if (!s.empty())
            s += ' ';
        s += k + "=" + formatValue(v);
    }
    return s;
}

std::string ParamSet::toJson() const
{
    std::string s = "{";
    for (const auto& [k, v] : mValues) {
        if (s.size() > 1)
            s += ',';
        s += jsonEscape(k) + ":";
        if (std::holds_alternative<std::string>(v))
            s += jsonEscape(std::get<std::string>(v));
        else if (std::holds_alternative<double>(v))
            s += jsonNumber(std::get<double>(v));
        else
            s += formatValue(v);
    }
    return s + "}";
}

} // namespace rtlab::config
