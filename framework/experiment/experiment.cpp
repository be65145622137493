#include "experiment/experiment.h"

#include "config/yaml_file.h"
#include "core/hash.h"
#include "core/json.h"
#include "core/strings.h"
#include "plugin/technique.h"
#include "scene/camera_paths.h"
#include "scene/procedural.h"
#include "scene/scene_file.h"
#include "scene/sdf_shapes.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <filesystem>

namespace rtlab::experiment {

using config::YamlFile;

bool RunConfig::wantsMetric(const std::string& metric) const
{
    return metrics.empty() || std::find(metrics.begin(), metrics.end(), metric) != metrics.end();
}

std::string RunConfig::toJson() const
{
    JsonObject techniquesJson;
    for (const auto& [family, choice] : techniques)
        techniquesJson.addRaw(family, JsonObject()
                                          .add("technique", choice.technique)
                                          .addRaw("params", choice.params.toJson())
                                          .str());
    // Keys added after the first studies are written only when set, so that the hashes (and
    // therefore the resumability) of existing results stay valid.
    JsonObject referenceJson;
    referenceJson.add("target_stderr", reference.targetStdErr)
        .add("target_rel_stderr", reference.targetRelStdErr)
        .add("max_samples", reference.maxSamples)
        .add("seed", std::int64_t(reference.seed));
    if (!reference.quantity.empty())
        referenceJson.add("quantity", reference.quantity);
    if (!reference.falloff.empty())
        referenceJson.add("falloff", reference.falloff);
    if (reference.radius > 0.0)
        referenceJson.add("radius", reference.radius);
    JsonObject json;
    json.add("scene", scene)
        .add("grid", grid)
        .add("width", width)
        .add("height", height)
        .add("frames", frames);
    if (!cameraPath.empty())
        json.add("camera_path", cameraPath);
    if (!metrics.empty()) {
        std::string list;
        for (const auto& m : metrics)
            list += (list.empty() ? "" : ",") + m;
        json.add("metrics", list);
    }
    if (!culling || lighting || !gbufferOnGpu) {
        JsonObject frame;
        if (!culling)
            frame.add("culling", false);
        if (!gbufferOnGpu)
            frame.add("gbuffer_on_gpu", false);
        if (lighting)
            frame.add("lighting", true)
                .add("tonemapper", tonemapper)
                .add("exposure_ev", exposureEv)
                .add("shadow_map_size", shadowMapSize);
        if (lighting && sky != "auto")
            frame.add("sky", sky);
        json.addRaw("frame", frame.str());
    }
    return json.addRaw("reference", referenceJson.str())
        .addRaw("timing",
                JsonObject().add("warmup", timing.warmup).add("repeats", timing.repeats).str())
        .addRaw("techniques", techniquesJson.str())
        .str();
}

std::string RunConfig::hash() const
{
    return hashHex(toJson());
}

std::string RunConfig::id() const
{
    const bool screenSpace = !volume;
    std::string s = std::filesystem::path(scene).stem().string() +
                    (screenSpace ? "-" + std::to_string(width) + "x" + std::to_string(height)
                                 : "-g" + std::to_string(grid));
    if (!cameraPath.empty() && cameraPath != "scene")
        s += "-" + cameraPath;
    for (const auto& [family, choice] : techniques)
        s += "-" + choice.technique;
    return s + "-" + hash().substr(0, 8);
}

namespace {

constexpr const char* kTechniqueKey = "technique";

struct Loader {
    const YamlFile& file;
    const plugin::Registry& registry;
    mutable std::vector<std::pair<std::string, YAML::Node>>
        cameraPathNodes; //!< non-built-in names, where

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
        if (run.scene.ends_with(".yaml") || run.scene.ends_with(".yml")) {
            // Scene files resolve against the experiment file's folder, then the working folder.
            const auto beside = std::filesystem::path(file.path()).parent_path() / run.scene;
            if (std::filesystem::exists(beside))
                run.scene = beside.lexically_normal().string();
            else if (!std::filesystem::exists(run.scene))
                file.fail(node, "scene file '" + run.scene + "' does not exist (looked beside " +
                                    file.path() + " and in the working folder)");
            return;
        }
        // An SDF model of a procedural scene, for the isosurface family: "csg_gallery/torus".
        if (const auto slash = run.scene.find('/'); slash != std::string::npos) {
            const std::string parent = run.scene.substr(0, slash);
            config::checkName(file, node, parent, scene::getProceduralSceneNames(),
                              "procedural scene");
            std::vector<std::string> models;
            for (const auto& m : scene::makeProceduralScene(parent).sdfModels)
                models.push_back(m.name);
            if (models.empty())
                file.fail(node, "scene '" + parent + "' has no SDF models to name after '/'");
            config::checkName(file, node, run.scene.substr(slash + 1), models,
                              "SDF model of '" + parent + "'");
            return;
        }
        std::vector<std::string> names = scene::analyticShapeNames();
        for (const auto& n : scene::getProceduralSceneNames())
            names.push_back(n);
        config::checkName(file, node, run.scene, names, "scene");
    }

    void readResolution(const YAML::Node& node, RunConfig& run) const
    {
        if (!node.IsSequence() || node.size() != 2)
            file.fail(node, "resolution: expected [width, height] in pixels, found " +
                                config::describeNode(node));
        run.width = int(config::readInt(file, node[0], "resolution width", 1, 8192));
        run.height = int(config::readInt(file, node[1], "resolution height", 1, 8192));
    }

    void readReference(const YAML::Node& node, RunConfig& run) const
    {
        config::checkKeys(file, node,
                          {"target_stderr", "target_rel_stderr", "max_samples", "seed", "quantity",
                           "falloff", "radius"},
                          {}, "reference");
        auto positive = [&](const char* key, double& out) {
            if (!node[key])
                return;
            out = config::readFloat(file, node[key], std::string("reference.") + key);
            if (!(out >= 0.0))
                file.fail(node[key], std::string("reference.") + key + ": expected a number >= 0");
        };
        positive("target_stderr", run.reference.targetStdErr);
        positive("target_rel_stderr", run.reference.targetRelStdErr);
        if (node["max_samples"])
            run.reference.maxSamples = int(
                config::readInt(file, node["max_samples"], "reference.max_samples", 1, 1 << 24));
        if (node["seed"])
            run.reference.seed =
                std::uint64_t(config::readInt(file, node["seed"], "reference.seed", 0, INT64_MAX));
        if (node["quantity"]) {
            run.reference.quantity =
                config::readString(file, node["quantity"], "reference.quantity");
            config::checkName(file, node["quantity"], run.reference.quantity,
                              {"ao", "ao_uniform", "obscurance"}, "ground-truth quantity");
        }
        if (node["falloff"]) {
            run.reference.falloff = config::readString(file, node["falloff"], "reference.falloff");
            config::checkName(file, node["falloff"], run.reference.falloff,
                              {"linear", "smoothstep"}, "obscurance falloff");
        }
        if (node["radius"]) {
            run.reference.radius = config::readFloat(file, node["radius"], "reference.radius");
            if (!(run.reference.radius > 0.0) || !std::isfinite(run.reference.radius))
                file.fail(node["radius"],
                          "reference.radius: expected a finite number > 0 (world units)");
        }
    }

    void readCameraPath(const YAML::Node& node, RunConfig& run) const
    {
        run.cameraPath = config::readString(file, node, "camera_path");
        if (!scene::isBuiltinCameraPathName(run.cameraPath))
            cameraPathNodes.emplace_back(run.cameraPath,
                                         node); // checked against the scene after expansion
    }

    void readMetrics(const YAML::Node& node, RunConfig& run) const
    {
        if (!node.IsSequence() || node.size() == 0)
            file.fail(node, "metrics: expected a non-empty list of metric names, found " +
                                config::describeNode(node));
        std::vector<std::string> valid;
        for (const auto& [family, choice] : run.techniques)
            for (const auto& m : registry.findFamily(family)->metrics)
                if (std::find(valid.begin(), valid.end(), m.name) == valid.end())
                    valid.push_back(m.name);
        run.metrics.clear();
        for (const auto& item : node) {
            const std::string name = config::readString(file, item, "metric");
            config::checkName(file, item, name, valid, "metric of the run's families");
            if (std::find(run.metrics.begin(), run.metrics.end(), name) != run.metrics.end())
                file.fail(item, "metrics: '" + name + "' is listed twice");
            run.metrics.push_back(name);
        }
    }

    // Named camera paths that are not built in must exist in the run's scene.
    void checkCameraPaths(const std::vector<RunConfig>& runs) const
    {
        std::map<std::string, std::vector<std::string>> namesByScene;
        for (const auto& run : runs) {
            if (run.cameraPath.empty() || scene::isBuiltinCameraPathName(run.cameraPath))
                continue;
            auto it = namesByScene.find(run.scene);
            if (it == namesByScene.end()) {
                std::vector<std::string> names = scene::getBuiltinCameraPathNames();
                if (!scene::findAnalyticShape(run.scene))
                    names = scene::getCameraPathNames(scene::loadScene(run.scene));
                it = namesByScene.emplace(run.scene, names).first;
            }
            for (const auto& [name, node] : cameraPathNodes)
                if (name == run.cameraPath)
                    config::checkName(file, node, name, it->second,
                                      "camera path of scene '" + run.scene + "'");
        }
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
            run.timing.repeats =
                int(config::readInt(file, node["repeats"], "timing.repeats", 1, 10000));
    }

    bool readBool(const YAML::Node& node, const std::string& what) const
    {
        if (node.IsScalar() && (node.Scalar() == "true" || node.Scalar() == "false"))
            return node.Scalar() == "true";
        file.fail(node, what + ": expected true or false, found " + config::describeNode(node));
        return false;
    }

    void readSky(const YAML::Node& node, RunConfig& run) const
    {
        run.sky = config::readString(file, node, "frame.sky");
        config::checkName(file, node, run.sky, {"auto", "lobes"}, "frame.sky");
    }

    void readFrame(const YAML::Node& node, RunConfig& run) const
    {
        if (!node.IsMap())
            file.fail(node, "frame: expected a mapping such as {culling: false}, found " +
                                config::describeNode(node));
        config::checkKeys(file, node,
                          {"culling", "lighting", "gbuffer_on_gpu", "tonemapper", "exposure_ev",
                           "shadow_map_size", "sky"},
                          {}, "frame");
        if (node["sky"])
            readSky(node["sky"], run);
        if (node["gbuffer_on_gpu"])
            run.gbufferOnGpu = readBool(node["gbuffer_on_gpu"], "frame.gbuffer_on_gpu");
        if (node["culling"])
            run.culling = readBool(node["culling"], "frame.culling");
        if (node["lighting"])
            run.lighting = readBool(node["lighting"], "frame.lighting");
        if (node["tonemapper"]) {
            run.tonemapper = config::readString(file, node["tonemapper"], "frame.tonemapper");
            config::checkName(file, node["tonemapper"], run.tonemapper, {"aces", "reinhard"},
                              "tonemapper");
        }
        if (node["exposure_ev"])
            run.exposureEv = config::readFloat(file, node["exposure_ev"], "frame.exposure_ev");
        if (node["shadow_map_size"])
            run.shadowMapSize = int(
                config::readInt(file, node["shadow_map_size"], "frame.shadow_map_size", 1, 4096));
    }

    // A run's families share one frame: screen families share the frame start, a volume family
    // has a frame of its own and cannot be combined.
    void checkFamilyDomains(const YAML::Node& node, const RunConfig& run) const
    {
        std::vector<std::string> screen, volume;
        for (const auto& [family, choice] : run.techniques)
            (registry.findFamily(family)->domain == plugin::FamilyDomain::Volume ? volume : screen)
                .push_back(family);
        if (!volume.empty() && run.techniques.size() > 1)
            file.fail(
                node,
                "techniques: family '" + volume.front() +
                    "' works on a sampled volume and cannot share a run with other families (" +
                    joinList(volume.size() > 1 ? volume : screen) +
                    "); put it in a run of its own");
    }

    void readTechniques(const YAML::Node& node, RunConfig& run) const
    {
        if (!node.IsMap() || node.size() == 0)
            file.fail(
                node,
                "techniques: expected a mapping from family to {technique: name, params: {...}}, "
                "found " +
                    config::describeNode(node) + ". Families: " + joinList(registry.familyNames()));
        for (const auto& kv : node) {
            const std::string family = kv.first.Scalar();
            config::checkName(file, kv.first, family, registry.familyNames(), "technique family");
            const YAML::Node& choiceNode = kv.second;
            config::checkKeys(file, choiceNode, {kTechniqueKey, "params"}, {kTechniqueKey},
                              "techniques." + family);
            const std::string name =
                config::readString(file, choiceNode[kTechniqueKey], "technique");
            const auto& entry = findTechnique(choiceNode[kTechniqueKey], family, name);
            TechniqueChoice choice{name, config::ParamSet::defaultsOf(entry.schema)};
            if (choiceNode["params"])
                choice.params = config::parseParams(file, choiceNode["params"], entry.schema,
                                                    "technique '" + name + "'");
            run.techniques[family] = std::move(choice);
        }
        checkFamilyDomains(node, run);
    }

    RunConfig readBase(const YAML::Node& node) const
    {
        config::checkKeys(file, node,
                          {"scene", "grid", "resolution", "frames", "camera_path", "metrics",
                           "timing", "reference", "frame", "techniques"},
                          {"scene"}, "base");
        RunConfig run;
        readScene(node["scene"], run);
        if (node["grid"])
            readGrid(node["grid"], run);
        if (node["resolution"])
            readResolution(node["resolution"], run);
        if (node["frames"])
            run.frames = int(config::readInt(file, node["frames"], "frames", 1, 100000));
        if (node["reference"])
            readReference(node["reference"], run);
        if (node["timing"])
            readTiming(node["timing"], run);
        if (node["frame"])
            readFrame(node["frame"], run);
        // Without base techniques every run takes its technique from the sweep (a study of
        // several families, one variant each); expand() checks that each run has one.
        if (node["techniques"])
            readTechniques(node["techniques"], run);
        if (node["camera_path"])
            readCameraPath(node["camera_path"], run);
        if (node["metrics"])
            readMetrics(node["metrics"], run);
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
        if (key == "resolution")
            return readResolution(value, run);
        if (key == "frames") {
            run.frames = int(config::readInt(file, value, "frames", 1, 100000));
            return;
        }
        if (key == "camera_path")
            return readCameraPath(value, run);
        if (key == "frame.culling") {
            run.culling = readBool(value, "frame.culling");
            return;
        }
        if (key == "frame.sky")
            return readSky(value, run);
        if (key == "frame.gbuffer_on_gpu") {
            run.gbufferOnGpu = readBool(value, "frame.gbuffer_on_gpu");
            return;
        }
        if (key == "reference.max_samples") {
            run.reference.maxSamples =
                int(config::readInt(file, value, "reference.max_samples", 1, 1 << 24));
            return;
        }
        const auto dot = key.find('.');
        if (dot == std::string::npos)
            file.fail(
                keyNode,
                "sweep: unknown axis '" + key +
                    "'; valid axes: scene, grid, resolution, frames, camera_path, frame.culling, "
                    "frame.gbuffer_on_gpu, frame.sky, reference.max_samples, "
                    "<family>.technique, <family>.<parameter>, zip");
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
            checkFamilyDomains(value, run);
            return;
        }
        auto it = run.techniques.find(family);
        if (it == run.techniques.end())
            file.fail(keyNode, "sweep: axis '" + key + "' sets a parameter of family '" + family +
                                   "', but the run uses no technique of that family; add it under "
                                   "base.techniques or sweep " +
                                   family + ".technique");
        const auto& entry = *registry.findTechnique(family, it->second.technique);
        const config::ParamSpec* spec = entry.schema.find(field);
        if (!spec) {
            std::string msg = "sweep: technique '" + it->second.technique +
                              "' declares no parameter '" + field + "'";
            const auto close = closestNames(field, entry.schema.names());
            if (!close.empty())
                msg += "; did you mean " + joinList(close, "or") + "?";
            msg += " Its parameters: " +
                   (entry.schema.empty() ? "none" : joinList(entry.schema.names())) + ".";
            file.fail(keyNode, msg);
        }
        it->second.params.set(
            field,
            config::parseValue(file, value, *spec, "technique '" + it->second.technique + "'"));
    }

    // Expands `sweep` on top of `runs`: the cross product of its axes (and zip groups), with
    // `variants` (a list of sub-sweeps, each expanded on its own and the results concatenated,
    // e.g. one per technique with its own parameters) applied last.
    std::vector<RunConfig> expand(const YAML::Node& sweep, const RunConfig& base,
                                  std::vector<std::string>& keys) const
    {
        std::vector<RunConfig> runs = expandAxes(sweep, {base}, base, keys, true);
        for (std::size_t i = 0; i < runs.size(); ++i)
            if (runs[i].techniques.empty())
                file.fail(sweep ? sweep : file.root()["base"],
                          "run " + std::to_string(i + 1) + " of the expansion (" + runs[i].id() +
                              ") has no technique: give base a `techniques:` entry, or set "
                              "<family>.technique in every variant");
        std::map<std::string, std::size_t> seen;
        for (std::size_t i = 0; i < runs.size(); ++i)
            if (!seen.emplace(runs[i].hash(), i).second)
                file.fail(sweep, "sweep: runs " + std::to_string(seen[runs[i].hash()] + 1) +
                                     " and " + std::to_string(i + 1) +
                                     " of the expansion are identical (" + runs[i].id() +
                                     "); does an axis repeat a value?");
        return runs;
    }

    std::vector<RunConfig> expandAxes(const YAML::Node& sweep, std::vector<RunConfig> runs,
                                      const RunConfig& base, std::vector<std::string>& keys,
                                      bool topLevel) const
    {
        if (!sweep)
            return runs;
        if (!sweep.IsMap())
            file.fail(sweep, "sweep: expected a mapping from axis to a list of values, found " +
                                 config::describeNode(sweep));
        // An axis of the cross product: one key, or a zip group of keys whose lists move
        // together (value i of every key in the group goes into the same run).
        struct Axis {
            std::vector<std::pair<YAML::Node, YAML::Node>> keys; // (key node, list of values)
            std::size_t size = 0;
            bool switchesTechnique = false;
        };
        auto checkList = [&](const YAML::Node& keyNode, const YAML::Node& values) {
            if (!values.IsSequence() || values.size() == 0)
                file.fail(values, "sweep: axis '" + keyNode.Scalar() +
                                      "' needs a non-empty list of values, found " +
                                      config::describeNode(values));
        };
        std::vector<Axis> axes;
        for (const auto& kv : sweep) {
            const std::string key = kv.first.Scalar();
            if (key == "variants") {
                if (!topLevel)
                    file.fail(kv.first, "sweep: variants cannot be nested");
                continue;
            }
            if (key != "zip") {
                checkList(kv.first, kv.second);
                axes.push_back(
                    {{{kv.first, kv.second}}, kv.second.size(), key.ends_with(".technique")});
                continue;
            }
            if (!kv.second.IsSequence() || kv.second.size() == 0)
                file.fail(kv.second,
                          "sweep: zip: expected a list of groups, each a mapping from axis to "
                          "lists of equal length, found " +
                              config::describeNode(kv.second));
            for (const auto& group : kv.second) {
                if (!group.IsMap() || group.size() < 2)
                    file.fail(
                        group,
                        "sweep: zip: a group needs a mapping of at least two axes whose values "
                        "move together, found " +
                            config::describeNode(group));
                Axis axis;
                for (const auto& member : group) {
                    if (member.first.Scalar() == "zip")
                        file.fail(member.first, "sweep: zip groups cannot be nested");
                    checkList(member.first, member.second);
                    if (axis.size != 0 && member.second.size() != axis.size)
                        file.fail(member.second,
                                  "sweep: zip: '" + member.first.Scalar() + "' has " +
                                      std::to_string(member.second.size()) + " values but '" +
                                      axis.keys.front().first.Scalar() + "' has " +
                                      std::to_string(axis.size) +
                                      "; zipped lists need equal lengths");
                    axis.size = member.second.size();
                    axis.switchesTechnique =
                        axis.switchesTechnique || member.first.Scalar().ends_with(".technique");
                    axis.keys.emplace_back(member.first, member.second);
                }
                axes.push_back(std::move(axis));
            }
        }
        // Axes that switch techniques first (and technique keys first within a zip group), so
        // parameter axes meet the technique they belong to. Orders are kept as indices: assigning
        // a YAML::Node overwrites the node it refers to, so nodes are never swapped.
        auto techniquesFirst = [](std::size_t n, auto isTechnique) {
            std::vector<std::size_t> order(n);
            for (std::size_t i = 0; i < n; ++i)
                order[i] = i;
            std::stable_partition(order.begin(), order.end(), isTechnique);
            return order;
        };
        for (std::size_t a : techniquesFirst(
                 axes.size(), [&](std::size_t i) { return axes[i].switchesTechnique; })) {
            const Axis& axis = axes[a];
            const auto keyOrder = techniquesFirst(axis.keys.size(), [&](std::size_t i) {
                return axis.keys[i].first.Scalar().ends_with(".technique");
            });
            std::string name;
            for (const auto& [keyNode, values] : axis.keys)
                name += (name.empty() ? "" : "+") + keyNode.Scalar();
            keys.push_back(axis.keys.size() > 1 ? "zip(" + name + ")" : name);
            std::vector<RunConfig> next;
            for (const auto& run : runs)
                for (std::size_t i = 0; i < axis.size; ++i) {
                    RunConfig r = run;
                    for (std::size_t k : keyOrder)
                        applyAxis(axis.keys[k].first.Scalar(), axis.keys[k].first,
                                  axis.keys[k].second[i], base, r);
                    next.push_back(std::move(r));
                }
            runs = std::move(next);
            if (runs.size() > 100000)
                file.fail(axis.keys.front().first, "sweep: the cross product exceeds 100000 runs");
        }
        const YAML::Node variants = sweep["variants"];
        if (topLevel && variants) {
            if (!variants.IsSequence() || variants.size() == 0)
                file.fail(
                    variants,
                    "sweep: variants: expected a list of sub-sweeps (mappings of axes), found " +
                        config::describeNode(variants));
            std::vector<RunConfig> all;
            for (const auto& variant : variants) {
                std::vector<std::string> variantKeys;
                for (auto& r : expandAxes(variant, runs, base, variantKeys, false))
                    all.push_back(std::move(r));
                for (const auto& k : variantKeys)
                    if (std::find(keys.begin(), keys.end(), k) == keys.end())
                        keys.push_back(k);
            }
            runs = std::move(all);
        }
        return runs;
    }
};

} // namespace

Experiment parseExperiment(const std::string& text, const std::string& label,
                           const plugin::Registry& registry)
{
    const YamlFile file = YamlFile::parse(text, label);
    const YAML::Node& root = file.root();
    config::checkKeys(file, root, {"name", "description", "base", "sweep", "report"}, {"base"},
                      "experiment");
    Loader loader{file, registry};
    Experiment e;
    e.path = label;
    e.name = root["name"] ? config::readString(file, root["name"], "name")
                          : std::filesystem::path(label).stem().string();
    if (root["description"])
        e.description = config::readString(file, root["description"], "description");
    if (const YAML::Node report = root["report"]) {
        config::checkKeys(file, report, {"time_from_frame"}, {}, "report");
        if (report["time_from_frame"])
            e.reportTimeFromFrame = int(config::readInt(file, report["time_from_frame"],
                                                        "report.time_from_frame", 0, 100000));
    }
    e.base = loader.readBase(root["base"]);
    e.runs = loader.expand(root["sweep"], e.base, e.sweepKeys);
    auto markVolume = [&](RunConfig& run) {
        run.volume = false;
        for (const auto& [family, choice] : run.techniques)
            run.volume =
                run.volume || registry.findFamily(family)->domain == plugin::FamilyDomain::Volume;
    };
    markVolume(e.base);
    for (auto& run : e.runs)
        markVolume(run);
    loader.checkCameraPaths(e.runs);
    return e;
}

Experiment loadExperiment(const std::string& path, const plugin::Registry& registry)
{
    return parseExperiment(readTextFile(path), path, registry);
}

} // namespace rtlab::experiment
