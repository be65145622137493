#include "experiment/experiment.h"

#include "config/yaml_file.h"
#include "core/hash.h"
#include "core/json.h"
#include "core/strings.h"
#include "plugin/technique.h"
#include "scene/sdf_shapes.h"

#include <filesystem>

namespace rtlab::experiment {

using config::YamlFile;

std::string RunConfig::toJson() const
{
    JsonObject techniquesJson;
    for (const auto& [family, choice] : techniques)
        techniquesJson.addRaw(family, JsonObject()
                                          .add("technique", choice.technique)
                                          .addRaw("params", choice.params.toJson())
                                          .str());
    return JsonObject()
        .add("scene", scene)
        .add("grid", grid)
        .addRaw("timing", JsonObject().add("warmup", timing.warmup).add("repeats", timing.repeats).str())
        .addRaw("techniques", techniquesJson.str())
        .str();
}

std::string RunConfig::hash() const
{
    return hashHex(toJson());
}

std::string RunConfig::id() const
{
    std::string s = scene + "-g" + std::to_string(grid);
    for (const auto& [family, choice] : techniques)
        s += "-" + choice.technique;
    return s + "-" + hash().substr(0, 8);
}

namespace {

constexpr const char* kTechniqueKey = "technique";

struct Loader {
    const YamlFile& file;
    const plugin::Registry& registry;

    const plugin::TechniqueEntry& findTechnique(const YAML::Node& where, const std::string& family,
                                                const std::string& name) const
    {
        config::checkName(file, where, family, registry.familyNames(), "technique family");
        config::checkName(file, where, name, registry.techniqueNames(family),
                          "technique in family '" + family + "'");
        return *registry.findTechnique(family, name);
    }

    void readScene(const YAML::Node& node, RunConfig& run) const
    {
        run.scene = config::readString(file, node, "scene");
        config::checkName(file, node, run.scene, scene::analyticShapeNames(), "scene");
    }

    void readGrid(const YAML::Node& node, RunConfig& run) const
    {
        run.grid = int(config::readInt(file, node, "grid (SDF samples per axis)", 2, 1024));
    }

    void readTiming(const YAML::Node& node, RunConfig& run) const
    {
        config::checkKeys(file, node, {"warmup", "repeats"}, {}, "timing");
        if (node["warmup"])
            run.timing.warmup = int(config::readInt(file, node["warmup"], "timing.warmup", 0, 100));
        if (node["repeats"])
            run.timing.repeats = int(config::readInt(file, node["repeats"], "timing.repeats", 1, 10000));
    }

    void readTechniques(const YAML::Node& node, RunConfig& run) const
    {
        if (!node.IsMap() || node.size() == 0)
            file.fail(node, "techniques: expected a mapping from family to {technique: name, params: {...}}, "
                            "found " + config::describeNode(node) + ". Families: " +
                                joinList(registry.familyNames()));
        for (const auto& kv : node) {
            const std::string family = kv.first.Scalar();
            config::checkName(file, kv.first, family, registry.familyNames(), "technique family");
            const YAML::Node& choiceNode = kv.second;
            config::checkKeys(file, choiceNode, {kTechniqueKey, "params"}, {kTechniqueKey},
                              "techniques." + family);
            const std::string name = config::readString(file, choiceNode[kTechniqueKey], "technique");
            const auto& entry = findTechnique(choiceNode[kTechniqueKey], family, name);
            TechniqueChoice choice{name, config::ParamSet::defaultsOf(entry.schema)};
            if (choiceNode["params"])
                choice.params = config::parseParams(file, choiceNode["params"], entry.schema,
                                                    "technique '" + name + "'");
            run.techniques[family] = std::move(choice);
        }
    }

    RunConfig readBase(const YAML::Node& node) const
    {
        config::checkKeys(file, node, {"scene", "grid", "timing", "techniques"}, {"scene", "techniques"},
                          "base");
        RunConfig run;
        readScene(node["scene"], run);
        if (node["grid"])
            readGrid(node["grid"], run);
        if (node["timing"])
            readTiming(node["timing"], run);
        readTechniques(node["techniques"], run);
        return run;
    }

    // Applies one sweep value to a run. A technique switch starts from that technique's defaults
    // (or from the base parameters when it switches to the base's technique); a swept parameter
    // must be declared by the technique it meets.
    void applyAxis(const std::string& key, const YAML::Node& keyNode, const YAML::Node& value,
                   const RunConfig& base, RunConfig& run) const
    {
        if (key == "scene")
            return readScene(value, run);
        if (key == "grid")
            return readGrid(value, run);
        const auto dot = key.find('.');
        if (dot == std::string::npos)
            file.fail(keyNode, "sweep: unknown axis '" + key + "'; valid axes: scene, grid, "
                               "<family>.technique, <family>.<parameter>");
        const std::string family = key.substr(0, dot);
        const std::string field = key.substr(dot + 1);
        config::checkName(file, keyNode, family, registry.familyNames(), "technique family");
        if (field == kTechniqueKey) {
            const std::string name = config::readString(file, value, "technique");
            const auto& entry = findTechnique(value, family, name);
            TechniqueChoice choice{name, config::ParamSet::defaultsOf(entry.schema)};
            if (auto it = base.techniques.find(family); it != base.techniques.end())
                for (const auto& [param, v] : it->second.params.values())
                    if (it->second.technique == name)
                        choice.params.set(param, v);
            run.techniques[family] = std::move(choice);
            return;
        }
        auto it = run.techniques.find(family);
        if (it == run.techniques.end())
            file.fail(keyNode, "sweep: axis '" + key + "' sets a parameter of family '" + family +
                                   "', but the run uses no technique of that family; add it under "
                                   "base.techniques or sweep " + family + ".technique");
        const auto& entry = *registry.findTechnique(family, it->second.technique);
        const config::ParamSpec* spec = entry.schema.find(field);
        if (!spec) {
            std::string msg = "sweep: technique '" + it->second.technique + "' declares no parameter '" +
                              field + "'";
            const auto close = closestNames(field, entry.schema.names());
            if (!close.empty())
                msg += "; did you mean " + joinList(close, "or") + "?";
            msg += " Its parameters: " + (entry.schema.empty() ? "none" : joinList(entry.schema.names())) + ".";
            file.fail(keyNode, msg);
        }
        it->second.params.set(field, config::parseValue(file, value, *spec,
                                                        "technique '" + it->second.technique + "'"));
    }

    std::vector<RunConfig> expand(const YAML::Node& sweep, const RunConfig& base,
                                  std::vector<std::string>& keys) const
    {
        std::vector<RunConfig> runs = {base};
        if (!sweep)
            return runs;
        if (!sweep.IsMap())
            file.fail(sweep, "sweep: expected a mapping from axis to a list of values, found " +
                                 config::describeNode(sweep));
        // Technique axes first, so parameter axes meet the technique they belong to.
        std::vector<std::pair<YAML::Node, YAML::Node>> axes;
        for (const auto& kv : sweep)
            if (kv.first.Scalar().ends_with(".technique"))
                axes.emplace_back(kv.first, kv.second);
        for (const auto& kv : sweep)
            if (!kv.first.Scalar().ends_with(".technique"))
                axes.emplace_back(kv.first, kv.second);
        for (const auto& [keyNode, values] : axes) {
            const std::string key = keyNode.Scalar();
            keys.push_back(key);
            if (!values.IsSequence() || values.size() == 0)
                file.fail(values, "sweep: axis '" + key + "' needs a non-empty list of values, found " +
                                      config::describeNode(values));
            std::vector<RunConfig> next;
            for (const auto& run : runs)
                for (const auto& value : values) {
                    RunConfig r = run;
                    applyAxis(key, keyNode, value, base, r);
                    next.push_back(std::move(r));
                }
            runs = std::move(next);
            if (runs.size() > 100000)
                file.fail(keyNode, "sweep: the cross product exceeds 100000 runs");
        }
        std::map<std::string, std::size_t> seen;
        for (std::size_t i = 0; i < runs.size(); ++i)
            if (!seen.emplace(runs[i].hash(), i).second)
                file.fail(sweep, "sweep: runs " + std::to_string(seen[runs[i].hash()] + 1) + " and " +
                                     std::to_string(i + 1) + " of the expansion are identical (" +
                                     runs[i].id() + "); does an axis repeat a value?");
        return runs;
    }
};

} // namespace

Experiment parseExperiment(const std::string& text, const std::string& label,
                           const plugin::Registry& registry)
{
    const YamlFile file = YamlFile::parse(text, label);
    const YAML::Node& root = file.root();
    config::checkKeys(file, root, {"name", "description", "base", "sweep"}, {"base"}, "experiment");
    Loader loader{file, registry};
    Experiment e;
    e.path = label;
    e.name = root["name"] ? config::readString(file, root["name"], "name")
                          : std::filesystem::path(label).stem().string();
    if (root["description"])
        e.description = config::readString(file, root["description"], "description");
    e.base = loader.readBase(root["base"]);
    e.runs = loader.expand(root["sweep"], e.base, e.sweepKeys);
    return e;
}

Experiment loadExperiment(const std::string& path, const plugin::Registry& registry)
{
    return parseExperiment(readTextFile(path), path, registry);
}

} // namespace rtlab::experiment
