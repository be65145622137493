#include "config/yaml_file.h"

#include "core/strings.h"

#include <charconv>
#include <cmath>
#include <set>

namespace rtlab::config {

namespace {

SourceLocation locationOf(const std::string& path, const YAML::Mark& mark)
{
    if (mark.is_null())
        return {path, 0, 0};
    return {path, mark.line + 1, mark.column + 1};
}

// Recursively rejects mappings that repeat a key. yaml-cpp keeps both entries, and a lookup would
// silently take the first: a typo'd sweep would then quietly do nothing.
void checkDuplicateKeys(const YamlFile& file, const YAML::Node& node)
{
    if (node.IsMap()) {
        std::map<std::string, YAML::Mark> seen;
        for (const auto& kv : node) {
            if (kv.first.IsScalar()) {
                const std::string key = kv.first.Scalar();
                auto [it, inserted] = seen.emplace(key, kv.first.Mark());
                if (!inserted)
                    file.fail(kv.first, "duplicate key '" + key + "' (first given at line " +
                                            std::to_string(it->second.line + 1) +
                                            "); each key may appear once");
            }
            checkDuplicateKeys(file, kv.second);
        }
    } else if (node.IsSequence()) {
        for (const auto& item : node)
            checkDuplicateKeys(file, item);
    }
}

bool isBlank(const std::string& text)
{
    // Only whitespace and comments?
    bool inComment = false;
    for (char c : text) {
        if (inComment) {
            if (c == '\n')
                inComment = false;
            continue;
        }
        if (c == '#')
            inComment = true;
        else if (!std::isspace(static_cast<unsigned char>(c)))
            return false;
    }
    return true;
}

// A YAML plain scalar or a quoted one? Quoted scalars are strings, never numbers or booleans.
bool isQuoted(const YAML::Node& node)
{
    return node.Tag() == "!";
}

} // namespace

YamlFile YamlFile::load(const std::string& path)
{
    return parse(readTextFile(path), path);
}

YamlFile YamlFile::parse(const std::string& text, const std::string& label)
{
    YamlFile file;
    file.mPath = label;
    if (isBlank(text))
        throw InputError({label, 1, 1}, "the file is empty; expected a YAML mapping (key: value lines)");
    if (text.find('\0') != std::string::npos)
        throw InputError({label, 1, 1}, "the file is binary, not YAML text");
    try {
        file.mRoot = YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw InputError(locationOf(label, e.mark), "not valid YAML: " + e.msg);
    }
    if (!file.mRoot.IsMap())
        file.fail(file.mRoot, "expected a YAML mapping (key: value lines) at the top level, found " +
                                  describeNode(file.mRoot));
    checkDuplicateKeys(file, file.mRoot);
    return file;
}

SourceLocation YamlFile::where(const YAML::Node& node) const
{
    if (!node.IsDefined())
        return {mPath, 0, 0};
    return locationOf(mPath, node.Mark());
}

void YamlFile::fail(const YAML::Node& node, const std::string& message) const
{
    throw InputError(where(node), message);
}

std::string describeNode(const YAML::Node& node)
{
    if (!node.IsDefined() || node.IsNull())
        return "nothing (null)";
    if (node.IsMap())
        return "a mapping";
    if (node.IsSequence())
        return "a sequence";
    std::string s = node.Scalar();
    if (s.size() > 40)
        s = s.substr(0, 37) + "...";
    return "'" + s + "'";
}

YAML::Node keyNode(const YAML::Node& map, const std::string& key)
{
    for (const auto& kv : map)
        if (kv.first.IsScalar() && kv.first.Scalar() == key)
            return kv.first;
    return YAML::Node(YAML::NodeType::Undefined);
}

void checkKeys(const YamlFile& file, const YAML::Node& node, const std::vector<std::string>& allowed,
               const std::vector<std::string>& required, const std::string& context)
{
    if (!node.IsMap())
        file.fail(node, context + ": expected a mapping, found " + describeNode(node));
    for (const auto& kv : node) {
        if (!kv.first.IsScalar())
            file.fail(kv.first, context + ": keys must be plain names");
        const std::string key = kv.first.Scalar();
        if (std::find(allowed.begin(), allowed.end(), key) != allowed.end())
            continue;
        std::string msg = context + ": unknown key '" + key + "'";
        const auto close = closestNames(key, allowed);
        if (!close.empty())
            msg += "; did you mean " + joinList(close, "or") + "?";
        msg += " Valid keys: " + (allowed.empty() ? std::string("none") : joinList(allowed)) + ".";
        file.fail(kv.first, msg);
    }
    for (const auto& key : required)
        if (!node[key])
            file.fail(node, context + ": missing required key '" + key + "'");
}

std::string readString(const YamlFile& file, const YAML::Node& node, const std::string& what)
{
    if (!node.IsScalar())
        file.fail(node, what + ": expected a string, found " + describeNode(node));
    return node.Scalar();
}

static bool parseInt(const std::string& s, std::int64_t& out)
{
    const char* b = s.data();
    const char* e = b + s.size();
    if (b != e && *b == '+')
        ++b;
    auto [p, ec] = std::from_chars(b, e, out);
    return ec == std::errc() && p == e && b != e;
}

static bool parseFloat(const std::string& s, double& out)
{
    const char* b = s.data();
    const char* e = b + s.size();
    if (b != e && *b == '+')
        ++b;
    auto [p, ec] = std::from_chars(b, e, out);
    return ec == std::errc() && p == e && b != e;
}

std::int64_t readInt(const YamlFile& file, const YAML::Node& node, const std::string& what,
                     std::int64_t min, std::int64_t max)
{
    std::int64_t v = 0;
    if (!node.IsScalar() || isQuoted(node) || !parseInt(node.Scalar(), v))
        file.fail(node, what + ": expected an integer, found " + describeNode(node));
    if (v < min || v > max)
        file.fail(node, what + ": " + std::to_string(v) + " is out of range; expected an integer in [" +
                            std::to_string(min) + ", " + std::to_string(max) + "]");
    return v;
}

double readFloat(const YamlFile& file, const YAML::Node& node, const std::string& what)
{
    double v = 0;
    if (!node.IsScalar() || isQuoted(node) || !parseFloat(node.Scalar(), v) || !std::isfinite(v))
        file.fail(node, what + ": expected a finite number, found " + describeNode(node));
    return v;
}

void checkName(const YamlFile& file, const YAML::Node& node, const std::string& name,
               const std::vector<std::string>& valid, const std::string& what)
{
    if (std::find(valid.begin(), valid.end(), name) != valid.end())
        return;
    std::string msg = "unknown " + what + " '" + name + "'";
    const auto close = closestNames(name, valid);
    msg += close.empty() ? std::string(".") : "; did you mean " + joinList(close, "or") + "?";
    msg += " Valid: " + (valid.empty() ? std::string("none") : joinList(valid)) + ".";
    file.fail(node, msg);
}

ParamValue parseValue(const YamlFile& file, const YAML::Node& node, const ParamSpec& spec,
                      const std::string& context)
{
    const std::string what = context + ": parameter '" + spec.name + "'";
    const std::string expected = std::string(toString(spec.type)) +
                                 (spec.describeRange().empty() ? "" : " in " + spec.describeRange()) +
                                 (spec.unit.empty() ? "" : " (" + spec.unit + ")");
    if (!node.IsScalar())
        file.fail(node, what + ": expected " + expected + ", found " + describeNode(node));
    const std::string& text = node.Scalar();
    ParamValue value;
    bool ok = true;
    switch (spec.type) {
    case ParamType::Bool:
        if (!isQuoted(node) && (text == "true" || text == "True" || text == "TRUE"))
            value = true;
        else if (!isQuoted(node) && (text == "false" || text == "False" || text == "FALSE"))
            value = false;
        else
            ok = false;
        break;
    case ParamType::Int: {
        std::int64_t i = 0;
        ok = !isQuoted(node) && parseInt(text, i);
        value = i;
        break;
    }
    case ParamType::Float: {
        double d = 0;
        ok = !isQuoted(node) && parseFloat(text, d);
        value = d;
        break;
    }
    case ParamType::String:
    case ParamType::Enum:
        value = text;
        break;
    }
    if (!ok)
        file.fail(node, what + ": expected " + expected + ", found " + describeNode(node));
    if (const auto problem = spec.checkValue(value); !problem.empty()) {
        std::string msg = what + ": " + describeNode(node) + " is not valid; " + problem +
                          (spec.unit.empty() ? "" : " (" + spec.unit + ")");
        if (spec.type == ParamType::Enum) {
            const auto close = closestNames(text, spec.choices);
            if (!close.empty())
                msg += "; did you mean " + joinList(close, "or") + "?";
        }
        file.fail(node, msg);
    }
    return value;
}

ParamSet parseParams(const YamlFile& file, const YAML::Node& map, const ParamSchema& schema,
                     const std::string& context)
{
    ParamSet set = ParamSet::defaultsOf(schema);
    if (!map.IsDefined() || map.IsNull())
        return set;
    checkKeys(file, map, schema.names(), {}, context);
    for (const auto& kv : map) {
        const ParamSpec* spec = schema.find(kv.first.Scalar());
        set.set(spec->name, parseValue(file, kv.second, *spec, context));
    }
    return set;
}

} // namespace rtlab::config
