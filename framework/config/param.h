#pragma once
// Declared parameters: each technique (and each experiment-level option) declares its parameters
// with name, type, default, range, unit and a one-line doc. Configs are validated against these
// declarations, sweeps iterate them, and `rtlab list` prints them.

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace rtlab::config {

enum class ParamType { Bool, Int, Float, String, Enum };

//! The value of one parameter. Enum values are stored as their string.
using ParamValue = std::variant<bool, std::int64_t, double, std::string>;

//! "bool", "int", "float", "string", "enum".
const char* toString(ParamType type);
//! Canonical text of a value: true/false, integers without a point, floats in shortest
//! round-trip form, strings as they are.
std::string formatValue(const ParamValue& value);

//! The declaration of one parameter.
struct ParamSpec {
    std::string name;                 //!< snake_case key used in configs
    ParamType type = ParamType::Float;
    ParamValue defaultValue;          //!< must satisfy the range / choices
    double min = -std::numeric_limits<double>::infinity();  //!< inclusive; Int and Float only
    double max = std::numeric_limits<double>::infinity();   //!< inclusive; Int and Float only
    std::vector<std::string> choices; //!< Enum only
    std::string unit;                 //!< "px", "world units", "cells", "" for dimensionless
    std::string doc;                  //!< one line

    //! "[0, 64]", "[1, inf)", "{a, b, c}" or "" when unconstrained.
    std::string describeRange() const;
    //! Empty when `value` is valid for this spec, else what is wrong ("expected ...").
    std::string checkValue(const ParamValue& value) const;
};

//! A parameter declaration list, in declaration order.
class ParamSchema {
public:
    ParamSchema& addBool(std::string name, bool defaultValue, std::string doc);
    ParamSchema& addInt(std::string name, std::int64_t defaultValue, std::int64_t min, std::int64_t max,
                        std::string unit, std::string doc);
    ParamSchema& addFloat(std::string name, double defaultValue, double min, double max, std::string unit,
                          std::string doc);
    ParamSchema& addEnum(std::string name, std::string defaultValue, std::vector<std::string> choices,
                         std::string doc);
    ParamSchema& addString(std::string name, std::string defaultValue, std::string doc);
    //! Adds a fully built spec; throws std::logic_error if the name repeats or the default is invalid.
    ParamSchema& add(ParamSpec spec);

    const ParamSpec* find(const std::string& name) const;
    const std::vector<ParamSpec>& specs() const { return mSpecs; }
    std::vector<std::string> names() const;
    bool empty() const { return mSpecs.empty(); }

private:
    std::vector<ParamSpec> mSpecs;
};

//! Concrete parameter values, keyed by name (sorted, so that text and hashes are canonical).
class ParamSet {
public:
    ParamSet() = default;
    //! Every parameter of `schema` at its default.
    static ParamSet defaultsOf(const ParamSchema& schema);

    void set(const std::string& name, ParamValue value) { mValues[name] = std::move(value); }
    bool has(const std::string& name) const { return mValues.count(name) != 0; }
    const ParamValue& get(const std::string& name) const;  //!< throws std::out_of_range

    bool getBool(const std::string& name) const;
    std::int64_t getInt(const std::string& name) const;
    double getFloat(const std::string& name) const;  //!< also accepts Int values
    const std::string& getString(const std::string& name) const;  //!< String and Enum

    const std::map<std::string, ParamValue>& values() const { return mValues; }
    //! "a=1 b=0.5 mode=fast"
    std::string toString() const;
    //! {"a":1,"b":0.5,"mode":"fast"}
    std::string toJson() const;

    bool operator==(const ParamSet&) const = default;

private:
    std::map<std::string, ParamValue> mValues;
};

} // namespace rtlab::config
