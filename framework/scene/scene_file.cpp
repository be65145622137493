#include "scene/scene_file.h"

#include "scene/camera_paths.h"

#include "config/yaml_file.h"
#include "core/error.h"
#include "core/strings.h"
#include "scene/mesh_loader.h"
#include "scene/procedural.h"

#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/rotate_vector.hpp>

#include <filesystem>
#include <map>

namespace rtlab::scene {

namespace {

using config::YamlFile;

struct Parser {
    const YamlFile& file;
    std::filesystem::path folder;
    Scene scene;
    std::map<std::string, std::uint32_t> materialIndex;

    glm::dvec3 readVec3(const YAML::Node& node, const std::string& what, bool allowScalar = false) const
    {
        if (allowScalar && node.IsScalar()) {
            const double v = config::readFloat(file, node, what);
            return glm::dvec3(v);
        }
        if (!node.IsSequence() || (node.size() != 3 && !(allowScalar && node.size() == 1)))
            file.fail(node, what + ": expected a list of 3 numbers [x, y, z]" +
                                (allowScalar ? std::string(" or one number") : std::string()) + ", found " +
                                config::describeNode(node));
        if (node.size() == 1)
            return glm::dvec3(config::readFloat(file, node[0], what));
        return {config::readFloat(file, node[0], what), config::readFloat(file, node[1], what),
                config::readFloat(file, node[2], what)};
    }

    glm::vec3 readColour(const YAML::Node& node, const std::string& what, double max) const
    {
        const glm::dvec3 c = readVec3(node, what, true);
        for (int i = 0; i < 3; ++i)
            if (c[i] < 0.0 || c[i] > max)
                file.fail(node, what + ": each channel must be in [0, " + config::formatValue(max) + "], found " +
                                    config::formatValue(c[i]));
        return glm::vec3(c);
    }

    double readPositive(const YAML::Node& node, const std::string& what) const
    {
        const double v = config::readFloat(file, node, what);
        if (!(v > 0.0))
            file.fail(node, what + ": expected a number > 0, found " + config::describeNode(node));
        return v;
    }

    std::uint32_t readMaterial(const YAML::Node& node, const std::string& what) const
    {
        const std::string name = config::readString(file, node, what);
        auto it = materialIndex.find(name);
        if (it == materialIndex.end()) {
            std::vector<std::string> names;
            for (const auto& [n, i] : materialIndex)
                names.push_back(n);
            config::checkName(file, node, name, names, "material");
        }
        return it->second;
    }

    void readMaterials(const YAML::Node& list)
    {
        if (!list.IsSequence())
            file.fail(list, "materials: expected a list of {name, albedo, emission}");
        for (const auto& m : list) {
            config::checkKeys(file, m, {"name", "albedo", "emission"}, {"name"}, "material");
            Material mat;
            mat.name = config::readString(file, m["name"], "material name");
            if (materialIndex.count(mat.name))
                file.fail(m["name"], "material '" + mat.name + "' is defined twice");
            if (m["albedo"])
                mat.albedo = readColour(m["albedo"], "albedo", 0.999);  // < 1: energy must be lost
            if (m["emission"])
                mat.emission = readColour(m["emission"], "emission", 1e6);
            materialIndex[mat.name] = std::uint32_t(scene.materials.size());
            scene.materials.push_back(mat);
        }
    }

    //! A mesh's `normals`: from_file (the default: what the file means, mesh_loader.h), flat,
    //! smooth, or {crease_angle: degrees in (0, 180]}.
    NormalMode readNormalMode(const YAML::Node& node) const
    {
        NormalMode mode;
        if (!node)
            return mode;
        const char* expected = "normals: expected from_file, flat, smooth or {crease_angle: degrees}";
        if (node.IsMap()) {
            config::checkKeys(file, node, {"crease_angle"}, {"crease_angle"}, "normals");
            const double a = config::readFloat(file, node["crease_angle"], "crease_angle");
            if (!(a > 0.0 && a <= 180.0))
                file.fail(node["crease_angle"], "crease_angle: expected degrees in (0, 180], found " +
                                                    std::to_string(a));
            mode.kind = NormalMode::Kind::CreaseAngle;
            mode.creaseAngleDegrees = a;
            return mode;
        }
        if (!node.IsScalar())
            file.fail(node, expected);
        const std::string name = config::readString(file, node, "normals");
        config::checkName(file, node, name, {"from_file", "flat", "smooth"}, "normals");
        mode.kind = name == "flat"     ? NormalMode::Kind::Flat
                    : name == "smooth" ? NormalMode::Kind::Smooth
                                       : NormalMode::Kind::FromFile;
        return mode;
    }

    void readMeshes(const YAML::Node& list)
    {
        if (!list.IsSequence())
            file.fail(list, "meshes: expected a list of {file, material, translate, scale, rotate_y}");
        for (const auto& m : list) {
            config::checkKeys(file, m,
                              {"file", "name", "material", "translate", "scale", "rotate_y", "normals"},
                              {"file"}, "mesh");
            const std::string rel = config::readString(file, m["file"], "mesh file");
            const std::string path = (folder / rel).lexically_normal().string();
            LoadedMesh loaded;
            try {
                // A material assigned here makes the file's own materials optional.
                loaded = loadMesh(path, {.materialsOptional = bool(m["material"]),
                                         .normals = readNormalMode(m["normals"])});
            } catch (const InputError& e) {
                // Name both places: where the scene refers to the mesh, and the mesh's own error.
                file.fail(m["file"], "mesh '" + rel + "': " + e.what());
            }
            scene.warnings.insert(scene.warnings.end(), loaded.warnings.begin(), loaded.warnings.end());
            MeshInstance inst;
            inst.name = m["name"] ? config::readString(file, m["name"], "mesh name") : rel;
            inst.sourceFile = path;
            inst.normalsSource = loaded.normalsSource;
            const glm::dvec3 t = m["translate"] ? readVec3(m["translate"], "translate") : glm::dvec3(0.0);
            const double s = m["scale"] ? readPositive(m["scale"], "scale") : 1.0;
            const double ry = m["rotate_y"] ? config::readFloat(file, m["rotate_y"], "rotate_y") : 0.0;
            for (const auto& p : loaded.positions)
                inst.positions.push_back(glm::vec3(t + s * glm::rotateY(glm::dvec3(p), glm::radians(ry))));
            for (const auto& n : loaded.normals)
                inst.normals.push_back(glm::vec3(glm::rotateY(glm::dvec3(n), glm::radians(ry))));
            inst.indices = loaded.indices;
            // A material named in the scene overrides the file's; otherwise the file's materials
            // become scene materials (by name).
            const bool overridden = bool(m["material"]);
            const std::uint32_t fixed = overridden ? readMaterial(m["material"], "mesh material") : 0;
            for (std::size_t tri = 0; tri < loaded.triangleMaterial.size(); ++tri) {
                if (overridden) {
                    inst.triangleMaterial.push_back(fixed);
                    continue;
                }
                const std::string& name = loaded.triangleMaterial[tri];
                auto it = materialIndex.find(name);
                if (it == materialIndex.end()) {
                    Material mat{name.empty() ? rel + ":default" : name};
                    for (std::size_t k = 0; k < loaded.materialNames.size(); ++k)
                        if (loaded.materialNames[k] == name) {
                            mat.albedo = loaded.materialAlbedo[k];
                            mat.emission = loaded.materialEmission[k];
                        }
                    it = materialIndex.emplace(mat.name, std::uint32_t(scene.materials.size())).first;
                    scene.materials.push_back(mat);
                }
                inst.triangleMaterial.push_back(it->second);
            }
            scene.meshes.push_back(std::move(inst));
        }
    }

    CsgEdit readEdit(const YAML::Node& e) const
    {
        config::checkKeys(file, e, {"shape", "op", "center", "size", "rotate", "rounding", "blend", "material", "frame"},
                          {"shape", "size"}, "edit");
        CsgEdit edit;
        const std::string shape = config::readString(file, e["shape"], "shape");
        config::checkName(file, e["shape"], shape, getCsgShapeNames(), "shape");
        edit.shape = CsgShape(std::find(getCsgShapeNames().begin(), getCsgShapeNames().end(), shape) -
                              getCsgShapeNames().begin());
        if (e["op"]) {
            const std::string op = config::readString(file, e["op"], "op");
            config::checkName(file, e["op"], op, getCsgOpNames(), "op");
            edit.op = CsgOp(std::find(getCsgOpNames().begin(), getCsgOpNames().end(), op) - getCsgOpNames().begin());
        }
        if (e["center"])
            edit.center = readVec3(e["center"], "center");
        edit.size = readVec3(e["size"], "size", true);
        if (e["rotate"]) {
            // Euler angles in degrees, applied x, then y, then z.
            const glm::dvec3 deg = readVec3(e["rotate"], "rotate");
            edit.rotation = glm::angleAxis(glm::radians(deg.z), glm::dvec3(0, 0, 1)) *
                            glm::angleAxis(glm::radians(deg.y), glm::dvec3(0, 1, 0)) *
                            glm::angleAxis(glm::radians(deg.x), glm::dvec3(1, 0, 0));
        }
        if (e["rounding"])
            edit.rounding = config::readFloat(file, e["rounding"], "rounding");
        if (e["blend"]) {
            edit.blend = config::readFloat(file, e["blend"], "blend");
            if (edit.blend < 0.0)
                file.fail(e["blend"], "blend: expected a radius >= 0 (world units)");
        }
        if (e["material"])
            edit.material = readMaterial(e["material"], "edit material");
        if (e["frame"])
            edit.frame = int(config::readInt(file, e["frame"], "frame", 0, 1000000));
        for (int i = 0; i < 3; ++i)
            if (edit.size[i] < 0.0)
                file.fail(e["size"], "size: every component must be >= 0 (world units)");
        return edit;
    }

    void readSdfModels(const YAML::Node& list)
    {
        if (!list.IsSequence())
            file.fail(list, "sdf_models: expected a list of {name, bounds, resolution, edits}");
        for (const auto& m : list) {
            config::checkKeys(file, m, {"name", "bounds", "resolution", "edits"}, {"name", "bounds", "edits"},
                              "sdf model");
            SdfModel model;
            model.name = config::readString(file, m["name"], "sdf model name");
            const YAML::Node& b = m["bounds"];
            if (!b.IsSequence() || b.size() != 2)
                file.fail(b, "bounds: expected [[min x, y, z], [max x, y, z]]");
            model.boundsMin = readVec3(b[0], "bounds min");
            model.boundsMax = readVec3(b[1], "bounds max");
            for (int i = 0; i < 3; ++i)
                if (!(model.boundsMax[i] > model.boundsMin[i]))
                    file.fail(b, "bounds: max must exceed min on every axis");
            if (m["resolution"])
                model.resolution = int(config::readInt(file, m["resolution"], "resolution", 4, 2048));
            if (!m["edits"].IsSequence() || m["edits"].size() == 0)
                file.fail(m["edits"], "edits: expected a non-empty list of CSG edits");
            for (const auto& e : m["edits"])
                model.edits.push_back(readEdit(e));
            scene.sdfModels.push_back(std::move(model));
        }
    }

    void readPointLights(const YAML::Node& list)
    {
        if (!list.IsSequence())
            file.fail(list, "point_lights: expected a list of {position, intensity}");
        for (const auto& l : list) {
            config::checkKeys(file, l, {"position", "intensity"}, {"position", "intensity"}, "point light");
            scene.pointLights.push_back(
                {glm::vec3(readVec3(l["position"], "position")), readColour(l["intensity"], "intensity", 1e9)});
        }
    }

    void readSky(const YAML::Node& s)
    {
        config::checkKeys(file, s, {"kind", "radiance", "zenith", "horizon", "ground", "lobes", "sharpness"}, {"kind"},
                          "sky");
        const std::string kind = config::readString(file, s["kind"], "sky kind");
        config::checkName(file, s["kind"], kind, {"none", "constant", "gradient", "srbf"}, "sky kind");
        Sky& sky = scene.sky;
        if (kind == "none") {
            sky.kind = Sky::Kind::None;
        } else if (kind == "constant") {
            sky.kind = Sky::Kind::Constant;
            if (!s["radiance"])
                file.fail(s, "sky: kind 'constant' needs 'radiance'");
            sky.constant = readColour(s["radiance"], "radiance", 1e6);
        } else if (kind == "gradient") {
            sky.kind = Sky::Kind::Gradient;
            for (const char* key : {"zenith", "horizon", "ground"})
                if (!s[key])
                    file.fail(s, std::string("sky: kind 'gradient' needs '") + key + "'");
            sky.zenith = readColour(s["zenith"], "zenith", 1e6);
            sky.horizon = readColour(s["horizon"], "horizon", 1e6);
            sky.ground = readColour(s["ground"], "ground", 1e6);
        } else {
            sky.kind = Sky::Kind::Srbf;
            const YAML::Node& lobes = s["lobes"];
            if (!lobes.IsSequence() || lobes.size() != kConeDirectionCount)
                file.fail(lobes.IsDefined() ? lobes : s, "sky: kind 'srbf' needs 'lobes', a list of 16 radiances");
            for (int i = 0; i < kConeDirectionCount; ++i)
                sky.lobes[i] = readColour(lobes[i], "lobe", 1e6);
            if (s["sharpness"])
                sky.sharpness = float(readPositive(s["sharpness"], "sharpness"));
        }
    }

    void readCharacters(const YAML::Node& list)
    {
        if (!list.IsSequence())
            file.fail(list, "characters: expected a list of {name, capsules, path, material}");
        for (const auto& c : list) {
            config::checkKeys(file, c, {"name", "capsules", "path", "material"}, {"name", "capsules"}, "character");
            Character ch;
            ch.name = config::readString(file, c["name"], "character name");
            if (c["material"])
                ch.material = readMaterial(c["material"], "character material");
            if (!c["capsules"].IsSequence() || c["capsules"].size() == 0)
                file.fail(c["capsules"], "capsules: expected a non-empty list of {a, b, radius}");
            for (const auto& cap : c["capsules"]) {
                config::checkKeys(file, cap, {"a", "b", "radius"}, {"a", "b", "radius"}, "capsule");
                ch.capsules.push_back({glm::vec3(readVec3(cap["a"], "a")), glm::vec3(readVec3(cap["b"], "b")),
                                       float(readPositive(cap["radius"], "radius"))});
            }
            if (c["path"]) {
                for (const auto& k : c["path"]) {
                    config::checkKeys(file, k, {"time", "position", "heading"}, {"time", "position"}, "path key");
                    CharacterKey key;
                    key.time = float(config::readFloat(file, k["time"], "time"));
                    key.position = glm::vec3(readVec3(k["position"], "position"));
                    if (k["heading"])
                        key.headingDegrees = float(config::readFloat(file, k["heading"], "heading"));
                    if (!ch.path.empty() && key.time <= ch.path.back().time)
                        file.fail(k["time"], "path: times must increase");
                    ch.path.push_back(key);
                }
            }
            scene.characters.push_back(std::move(ch));
        }
    }

    CameraPath readCameraPath(const YAML::Node& node, const std::string& what) const
    {
        if (!node.IsSequence() || node.size() == 0)
            file.fail(node, what + ": expected a list of keyframes {time, position, target, ...}, found " +
                                config::describeNode(node));
        std::vector<CameraKeyframe> keys;
        Camera previous = scene.camera;
        for (const auto& k : node) {
            CameraKeyframe key;
            key.camera = readCamera(k, previous, true);
            key.time = float(config::readFloat(file, k["time"], "time"));
            if (!keys.empty() && key.time <= keys.back().time)
                file.fail(k["time"], what + ": times must increase");
            previous = key.camera;
            keys.push_back(key);
        }
        return CameraPath(keys);
    }

    Camera readCamera(const YAML::Node& c, Camera camera, bool keyframe) const
    {
        std::vector<std::string> keys = {"position", "target", "up", "fov", "near", "far"};
        if (keyframe)
            keys.insert(keys.begin(), "time");
        config::checkKeys(file, c, keys, keyframe ? std::vector<std::string>{"time"} : std::vector<std::string>{},
                          keyframe ? "camera path key" : "camera");
        if (c["position"])
            camera.position = glm::vec3(readVec3(c["position"], "position"));
        if (c["target"])
            camera.target = glm::vec3(readVec3(c["target"], "target"));
        if (c["up"])
            camera.up = glm::vec3(readVec3(c["up"], "up"));
        if (c["fov"]) {
            camera.verticalFovDegrees = float(config::readFloat(file, c["fov"], "fov"));
            if (!(camera.verticalFovDegrees > 0.0f && camera.verticalFovDegrees < 180.0f))
                file.fail(c["fov"], "fov: expected a vertical field of view in (0, 180) degrees");
        }
        if (c["near"])
            camera.nearPlane = float(readPositive(c["near"], "near"));
        if (c["far"])
            camera.farPlane = float(readPositive(c["far"], "far"));
        if (camera.farPlane <= camera.nearPlane)
            file.fail(c, "camera: far must be greater than near");
        if (camera.position == camera.target)
            file.fail(c, "camera: position and target must differ");
        return camera;
    }
};

} // namespace

Scene parseSceneFile(const std::string& text, const std::string& label)
{
    const YamlFile file = YamlFile::parse(text, label);
    const YAML::Node& root = file.root();
    config::checkKeys(file, root,
                      {"scene", "base", "materials", "meshes", "sdf_models", "point_lights", "sky", "characters",
                       "camera", "camera_path", "camera_paths", "frames", "frame_rate", "parameters"},
                      {"scene"}, "scene file");
    Parser p{file, std::filesystem::path(label).parent_path(), {}, {}};
    if (root["base"]) {
        const std::string base = config::readString(file, root["base"], "base");
        config::checkName(file, root["base"], base, getProceduralSceneNames(), "procedural scene");
        p.scene = makeProceduralScene(base);
        for (std::size_t i = 0; i < p.scene.materials.size(); ++i)
            p.materialIndex[p.scene.materials[i].name] = std::uint32_t(i);
    }
    p.scene.name = config::readString(file, root["scene"], "scene name");
    p.scene.source = label;
    if (root["materials"])
        p.readMaterials(root["materials"]);
    if (p.scene.materials.empty())
        p.scene.materials.push_back(Material{"default"});
    if (!p.materialIndex.count(p.scene.materials[0].name))
        p.materialIndex[p.scene.materials[0].name] = 0;
    if (root["meshes"])
        p.readMeshes(root["meshes"]);
    if (root["sdf_models"])
        p.readSdfModels(root["sdf_models"]);
    if (root["point_lights"])
        p.readPointLights(root["point_lights"]);
    if (root["sky"])
        p.readSky(root["sky"]);
    if (root["characters"])
        p.readCharacters(root["characters"]);
    if (root["camera"])
        p.scene.camera = p.readCamera(root["camera"], p.scene.camera, false);
    if (root["camera_path"])
        p.scene.cameraPath = p.readCameraPath(root["camera_path"], "camera_path");
    if (root["camera_paths"]) {
        const YAML::Node& paths = root["camera_paths"];
        if (!paths.IsMap())
            file.fail(paths, "camera_paths: expected a mapping from a path name to a list of keyframes, found " +
                                 config::describeNode(paths));
        for (const auto& kv : paths) {
            const std::string name = kv.first.Scalar();
            if (isBuiltinCameraPathName(name))
                file.fail(kv.first, "camera_paths: '" + name + "' is a built-in camera path (" +
                                        joinList(getBuiltinCameraPathNames()) + "); choose another name");
            p.scene.namedCameraPaths[name] = p.readCameraPath(kv.second, "camera_paths." + name);
        }
    }
    if (root["parameters"]) {
        const YAML::Node& params = root["parameters"];
        if (!params.IsMap())
            file.fail(params, "parameters: expected a mapping from a name to a number, found " +
                                  config::describeNode(params));
        for (const auto& kv : params) {
            const std::string name = kv.first.Scalar();
            if (name.empty() || name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") !=
                                    std::string::npos)
                file.fail(kv.first, "parameters: '" + name + "' must be snake_case");
            p.scene.parameters[name] = config::readFloat(file, kv.second, "parameters." + name);
        }
    }
    if (root["frames"])
        p.scene.frameCount = int(config::readInt(file, root["frames"], "frames", 1, 100000));
    if (root["frame_rate"])
        p.scene.frameRate = float(p.readPositive(root["frame_rate"], "frame_rate"));
    if (p.scene.meshes.empty() && p.scene.sdfModels.empty() && p.scene.characters.empty())
        file.fail(root, "the scene is empty: it needs at least one of meshes, sdf_models, characters "
                        "(or a procedural 'base')");
    return p.scene;
}

Scene loadSceneFile(const std::string& path)
{
    return parseSceneFile(readTextFile(path), path);
}

Scene loadScene(const std::string& nameOrPath)
{
    if (nameOrPath.ends_with(".yaml") || nameOrPath.ends_with(".yml") ||
        nameOrPath.find('/') != std::string::npos)
        return loadSceneFile(nameOrPath);
    return makeProceduralScene(nameOrPath);
}

} // namespace rtlab::scene
