// Scene files: a valid file builds the scene it describes; every kind of bad input is one clear
// error with file:line:column.

#include "core/error.h"
#include "scene/scene_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

using namespace rtlab::scene;

namespace {

std::string errorOf(const std::string& text)
{
    try {
        parseSceneFile(text, "scene.yaml");
    } catch (const rtlab::InputError& e) {
        return e.what();
    } catch (const rtlab::Error& e) {
        return std::string("not an InputError: ") + e.what();
    }
    return "";
}

const char* kScene = R"(scene: test_room
materials:
  - {name: white, albedo: [0.8, 0.8, 0.8]}
  - {name: lamp, albedo: 0, emission: [4, 4, 4]}
sdf_models:
  - name: rock
    bounds: [[-1, -1, -1], [1, 1, 1]]
    resolution: 24
    edits:
      - {shape: box, op: add, size: 0.5, material: white}
      - {shape: sphere, op: subtract, center: [0.5, 0.5, 0.5], size: 0.4, blend: 0.1, frame: 2}
point_lights:
  - {position: [0, 2, 0], intensity: [5, 5, 5]}
sky: {kind: gradient, zenith: [1, 1, 1], horizon: 0.5, ground: 0.1}
characters:
  - name: walker
    material: lamp
    capsules: [{a: [0, 0.2, 0], b: [0, 1.4, 0], radius: 0.25}]
    path: [{time: 0, position: [2, 0, 0]}, {time: 1, position: [3, 0, 0], heading: 90}]
camera: {position: [0, 1, 4], target: [0, 0, 0], fov: 50}
camera_path:
  - {time: 0, position: [0, 1, 4]}
  - {time: 1, position: [2, 1, 4]}
frames: 4
)";

} // namespace

TEST(SceneFile, ValidFileBuildsTheScene)
{
    const Scene s = parseSceneFile(kScene, "scene.yaml");
    EXPECT_EQ(s.name, "test_room");
    ASSERT_EQ(s.materials.size(), 2u);
    EXPECT_EQ(s.materials[1].emission, glm::vec3(4.0f));
    ASSERT_EQ(s.sdfModels.size(), 1u);
    EXPECT_EQ(s.sdfModels[0].edits[1].frame, 2);
    EXPECT_EQ(s.sdfModels[0].edits[1].op, CsgOp::Subtract);
    EXPECT_EQ(s.sky.kind, Sky::Kind::Gradient);
    EXPECT_EQ(s.sky.horizon, glm::vec3(0.5f));
    EXPECT_EQ(s.characters[0].material, 1u);
    EXPECT_EQ(s.frameCount, 4);
    const FeatureSet f = s.computeFeatures();
    for (SceneFeature feature : FeatureSet::getAll())
        EXPECT_TRUE(f.has(feature)) << FeatureSet::getName(feature);
    EXPECT_GT(s.buildRenderScene(0).triangleCount(), 100u);
}

TEST(SceneFile, ParametersAreNumbersAStudyPlotsAgainst)
{
    const Scene s = parseSceneFile(
        "scene: p\nbase: cornell_box\nparameters: {wall_voxels: 0.25, rooms: 3}\n", "scene.yaml");
    ASSERT_EQ(s.parameters.size(), 2u);
    EXPECT_EQ(s.parameters.at("wall_voxels"), 0.25);
    EXPECT_EQ(s.parameters.at("rooms"), 3.0);
}

TEST(SceneFile, BaseStartsFromAProceduralScene)
{
    const Scene s = parseSceneFile("scene: lit_box\nbase: cornell_box\npoint_lights: [{position: [0.27, 0.4, 0.27], "
                                   "intensity: 1}]\n",
                                   "scene.yaml");
    EXPECT_EQ(s.name, "lit_box");
    EXPECT_EQ(s.materials.size(), 4u);
    EXPECT_TRUE(s.computeFeatures().has(SceneFeature::PointLights));
}

TEST(SceneFile, BadInputGivesOneClearErrorWithItsPosition)
{
    struct Case {
        const char* text;
        const char* where;
        const char* what;
    };
    const Case cases[] = {
        {"", "scene.yaml:1:1:", "the file is empty"},
        {"scene: [x\n", "scene.yaml:", "not valid YAML"},
        {"materials: []\n", "scene.yaml:1:1:", "missing required key 'scene'"},
        {"scene: x\n", "scene.yaml:1:1:", "the scene is empty"},
        {"scene: x\nsdf_model: []\n", "scene.yaml:2:1:", "did you mean sdf_models?"},
        {"scene: x\nbase: cornel_box\n", "scene.yaml:2:7:", "did you mean cornell_box?"},
        {"scene: x\nbase: cornell_box\nparameters: [1]\n", "scene.yaml:3:13:",
         "parameters: expected a mapping"},
        {"scene: x\nbase: cornell_box\nparameters: {Wall: 1}\n", "scene.yaml:3:14:",
         "must be snake_case"},
        {"scene: x\nmaterials: [{name: a, albedo: [2, 0, 0]}]\nbase: cornell_box\n", "scene.yaml:2:31:",
         "each channel must be in [0, 0.999]"},
        {"scene: x\nsdf_models: [{name: r, bounds: [[0,0,0],[1,1,1]], edits: [{shape: cube, size: 1}]}]\n",
         "scene.yaml:2:67:", "unknown shape 'cube'"},
        {"scene: x\nsdf_models: [{name: r, bounds: [[0,0,0],[1,1,1]], edits: [{shape: box, size: [1, 2]}]}]\n",
         "scene.yaml:2:78:", "expected a list of 3 numbers"},
        {"scene: x\nsdf_models: [{name: r, bounds: [[1,0,0],[0,1,1]], edits: [{shape: box, size: 1}]}]\n",
         "scene.yaml:2:32:", "max must exceed min"},
        {"scene: x\nbase: ao_testbed\ncamera: {position: [0, 0, 0], target: [0, 0, 0]}\n", "scene.yaml:3:9:",
         "position and target must differ"},
        {"scene: x\nbase: ao_testbed\nsky: {kind: srbf, lobes: [1, 2]}\n", "scene.yaml:3:26:",
         "a list of 16 radiances"},
        {"scene: x\nbase: ao_testbed\nframes: 0\n", "scene.yaml:3:9:", "expected an integer in [1, 100000]"},
        {"scene: x\nbase: ao_testbed\nmeshes: [{file: missing.obj}]\n", "scene.yaml:3:17:",
         "mesh 'missing.obj': missing.obj: error: file not found"},
        {"scene: x\nbase: ao_testbed\ncharacters: [{name: c, capsules: [{a: [0,0,0], b: [0,1,0], radius: 0}]}]\n",
         "scene.yaml:3:68:", "expected a number > 0"},
    };
    for (const auto& c : cases) {
        const std::string err = errorOf(c.text);
        EXPECT_NE(err.find(c.where), std::string::npos) << "input:\n" << c.text << "\nerror: " << err;
        EXPECT_NE(err.find(c.what), std::string::npos) << "input:\n" << c.text << "\nerror: " << err;
    }
}

TEST(SceneFile, LoadsMeshesRelativeToTheSceneFile)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_scene_file_test";
    std::filesystem::create_directories(dir / "models");
    std::ofstream(dir / "models" / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    std::ofstream(dir / "room.yaml") << "scene: room\nmaterials: [{name: grey, albedo: 0.5}]\n"
                                        "meshes: [{file: models/tri.obj, material: grey, translate: [0, 0, 2], "
                                        "scale: 2}]\n";
    const Scene s = loadScene((dir / "room.yaml").string());
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].positions[1], glm::vec3(2, 0, 2));
    EXPECT_EQ(s.meshes[0].triangleMaterial[0], 0u);
    EXPECT_EQ(loadScene("cornell_box").name, "cornell_box");
}

TEST(SceneFile, AMeshWhoseMaterialTheSceneAssignsLoadsWithoutItsMtl)
{
    // Downloaded models often lack their .mtl. When the scene file assigns the material, the
    // missing library is a warning on the scene (and on every run's row), not an error.
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_scene_file_mtl_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "model.obj") << "mtllib model.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                        "usemtl paint\nf 1 2 3\n";
    std::ofstream(dir / "assigned.yaml") << "scene: assigned\nmaterials: [{name: grey, albedo: 0.5}]\n"
                                            "meshes: [{file: model.obj, material: grey}]\n";
    const Scene s = loadScene((dir / "assigned.yaml").string());
    ASSERT_EQ(s.meshes.size(), 1u);
    EXPECT_EQ(s.meshes[0].triangleMaterial[0], 0u);
    ASSERT_EQ(s.warnings.size(), 2u);
    EXPECT_NE(s.warnings[0].find("model.obj:1:"), std::string::npos) << s.warnings[0];
    EXPECT_NE(s.warnings[0].find("model.mtl"), std::string::npos) << s.warnings[0];
    // Without a material of its own the mesh needs the file's: still an error, naming both files.
    std::ofstream(dir / "unassigned.yaml") << "scene: unassigned\nmeshes: [{file: model.obj}]\n";
    try {
        loadScene((dir / "unassigned.yaml").string());
        FAIL() << "expected an error";
    } catch (const rtlab::Error& e) {
        EXPECT_NE(std::string(e.what()).find("unassigned.yaml:2:"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("model.mtl"), std::string::npos) << e.what();
    }
}

TEST(SceneFile, AMeshsNormalsAreWhatItsFileMeansUnlessTheSceneSaysOtherwise)
{
    // Two triangles meeting at 90 degrees along an edge, no vn, no smoothing groups.
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_scene_file_normals_test";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "hinge.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\n";
    const auto load = [&](const std::string& normals) {
        std::ofstream(dir / "hinge.yaml") << "scene: hinge\nmaterials: [{name: grey, albedo: 0.5}]\n"
                                             "meshes: [{file: hinge.obj, material: grey"
                                          << (normals.empty() ? "" : ", normals: " + normals) << "}]\n";
        return loadScene((dir / "hinge.yaml").string());
    };
    const Scene file = load("");
    EXPECT_EQ(file.meshes[0].positions.size(), 6u); // flat: each face its own vertices
    EXPECT_EQ(file.meshes[0].normalsSource, "flat (no vn, no smoothing groups)");
    const Scene smooth = load("smooth");
    EXPECT_EQ(smooth.meshes[0].positions.size(), 4u);
    EXPECT_EQ(smooth.meshes[0].normalsSource, "smooth");
    EXPECT_EQ(load("{crease_angle: 60}").meshes[0].positions.size(), 6u);
    EXPECT_EQ(load("{crease_angle: 120}").meshes[0].positions.size(), 4u);
    EXPECT_EQ(load("flat").meshes[0].normalsSource, "flat");
    // Bad values name the line and column and what was expected.
    try {
        load("smoth");
        FAIL() << "expected an error";
    } catch (const rtlab::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("hinge.yaml:3:"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("smooth"), std::string::npos) << e.what();
    }
    try {
        load("{crease_angle: 0}");
        FAIL() << "expected an error";
    } catch (const rtlab::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("expected degrees in (0, 180]"), std::string::npos) << e.what();
    }
}

TEST(SceneFile, EveryShippedSceneFileLoadsAndBuilds)
{
    // The scene files under scenes/ are part of the product: each must load and build every frame.
    int count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(std::filesystem::path(RTLAB_SOURCE_DIR) / "scenes")) {
        if (entry.path().extension() != ".yaml")
            continue;
        const Scene s = loadScene(entry.path().string());
        for (int frame = 0; frame < s.frameCount; ++frame)
            EXPECT_GT(s.buildRenderScene(frame).triangleCount(), 0u) << entry.path() << " frame " << frame;
        ++count;
    }
    EXPECT_GE(count, 1);
}
