#pragma once
// YAML documents with positions. Every error names file:line:column, what was found and what is
// valid. Duplicate keys, empty files and text that is not a YAML mapping are errors, not surprises.

#include "config/param.h"
#include "core/error.h"

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace rtlab::config {

//! One parsed YAML file. Keeps its path so that every node can be located in error messages.
class YamlFile {
public:
    //! Reads and parses `path`. Throws InputError for unreadable, empty or malformed files, for
    //! duplicate keys anywhere in the document, and when the top level is not a mapping.
    static YamlFile load(const std::string& path);
    //! Same checks for in-memory text; `label` plays the role of the path in messages.
    static YamlFile parse(const std::string& text, const std::string& label);

    const std::string& path() const { return mPath; }
    const YAML::Node& root() const { return mRoot; }

    //! Where `node` starts (1-based line and column).
    SourceLocation where(const YAML::Node& node) const;
    //! Throws InputError at `node`.
    [[noreturn]] void fail(const YAML::Node& node, const std::string& message) const;

private:
    std::string mPath;
    YAML::Node mRoot;
};

//! "a mapping", "a sequence", "the scalar '12'", "nothing (null)".
std::string describeNode(const YAML::Node& node);

//! Requires `node` to be a mapping whose keys are all in `allowed` and that holds every key in
//! `required`. Unknown keys are reported with the closest valid names. `context` names the
//! section in messages ("experiment", "technique 'lsao'").
void checkKeys(const YamlFile& file, const YAML::Node& node, const std::vector<std::string>& allowed,
               const std::vector<std::string>& required, const std::string& context);

//! The key node of `key` inside mapping `map` (for positions), or an invalid node.
YAML::Node keyNode(const YAML::Node& map, const std::string& key);

//! Parses one scalar as a value of `spec` (type and range checked). `context` names the owner.
ParamValue parseValue(const YamlFile& file, const YAML::Node& node, const ParamSpec& spec,
                      const std::string& context);

//! Validates a mapping of parameters against `schema`: unknown keys (with suggestions), wrong
//! types and out-of-range values are errors. Missing keys take their defaults.
ParamSet parseParams(const YamlFile& file, const YAML::Node& map, const ParamSchema& schema,
                     const std::string& context);

//! Scalar helpers with type errors at the node.
std::string readString(const YamlFile& file, const YAML::Node& node, const std::string& what);
std::int64_t readInt(const YamlFile& file, const YAML::Node& node, const std::string& what,
                     std::int64_t min, std::int64_t max);
double readFloat(const YamlFile& file, const YAML::Node& node, const std::string& what);

//! Requires `name` to be one of `valid`; otherwise an error with the closest names.
void checkName(const YamlFile& file, const YAML::Node& node, const std::string& name,
               const std::vector<std::string>& valid, const std::string& what);

} // namespace rtlab::config
