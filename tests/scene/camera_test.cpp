// Cameras: projection conventions, jitter, and paths through keyframes.

#include "scene/camera.h"

#include "core/error.h"
#include "scene/camera_paths.h"
#include "scene/procedural.h"
#include "scene/scene_file.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace rtlab::scene;

namespace {
glm::vec3 project(const Camera& c, const glm::vec3& p, float aspect, glm::vec2 jitter = {},
                  glm::ivec2 size = glm::ivec2(64, 64))
{
    const glm::vec4 clip = c.projectionMatrix(aspect, jitter, size) * c.viewMatrix() * glm::vec4(p, 1.0f);
    return glm::vec3(clip) / clip.w;
}
} // namespace

TEST(Camera, VulkanClipConventions)
{
    Camera c;
    c.position = {0, 0, 5};
    c.target = {0, 0, 0};
    c.nearPlane = 1.0f;
    c.farPlane = 10.0f;
    // Depth 0 at the near plane, 1 at the far plane.
    EXPECT_NEAR(project(c, {0, 0, 4}, 1.0f).z, 0.0f, 1e-6f);
    EXPECT_NEAR(project(c, {0, 0, -5}, 1.0f).z, 1.0f, 1e-6f);
    // World up (+y) is NDC y < 0 (Vulkan's y points down), so row 0 is the top of the image.
    EXPECT_LT(project(c, {0, 1, 0}, 1.0f).y, 0.0f);
    EXPECT_GT(project(c, {1, 0, 0}, 1.0f).x, 0.0f);
}

TEST(Camera, JitterShiftsByTheRequestedPixels)
{
    Camera c;
    const glm::ivec2 size(64, 32);
    const glm::vec3 a = project(c, {0.3f, 0.2f, 0}, 2.0f, {}, size);
    const glm::vec3 b = project(c, {0.3f, 0.2f, 0}, 2.0f, {0.5f, -0.25f}, size);
    // The samples move by +jitter, so the image content moves by -jitter. NDC spans 2 over
    // `size` pixels: half a pixel is 1/64 in x; -0.25 px is -0.5/32 in y.
    EXPECT_NEAR(b.x - a.x, -2.0f * 0.5f / 64.0f, 1e-6f);
    EXPECT_NEAR(b.y - a.y, -2.0f * -0.25f / 32.0f, 1e-6f);
}

TEST(CameraPath, PassesThroughKeyframesAndHoldsAtTheEnds)
{
    std::vector<CameraKeyframe> keys(4);
    for (int i = 0; i < 4; ++i) {
        keys[i].time = float(i);
        keys[i].camera.position = {float(i), float(i * i), 3.0f};
    }
    const CameraPath path(keys);
    EXPECT_TRUE(path.moves());
    EXPECT_FLOAT_EQ(path.duration(), 3.0f);
    for (int i = 0; i < 4; ++i) {
        const glm::vec3 p = path.evaluate(float(i)).position;
        EXPECT_NEAR(glm::length(p - keys[i].camera.position), 0.0f, 1e-5f) << i;
    }
    EXPECT_EQ(path.evaluate(-1.0f).position, keys.front().camera.position);
    EXPECT_EQ(path.evaluate(9.0f).position, keys.back().camera.position);
    // Between keys the path moves monotonically in x here.
    float previous = -1.0f;
    for (float t = 0.0f; t <= 3.0f; t += 0.125f) {
        const float x = path.evaluate(t).position.x;
        EXPECT_GT(x, previous) << t;
        previous = x;
    }
}

TEST(CameraPath, UnsortedKeysAndStillCamera)
{
    std::vector<CameraKeyframe> keys(2);
    keys[0].time = 2.0f;
    keys[1].time = 0.0f;
    const CameraPath path(keys);
    EXPECT_FLOAT_EQ(path.keyframes().front().time, 0.0f);
    EXPECT_FALSE(path.moves());
}

// ---- camera paths chosen by name ----

namespace rtlab::scene {
namespace {

TEST(CameraPaths, GeneratedPathsStartAtTheCanonicalCameraAndMoveAsDocumented)
{
    Scene base = makeProceduralScene("ao_testbed");
    const Camera c = base.camera;
    const float distance = glm::length(c.position - c.target);
    const int frames = 9;
    {
        Scene s = base;
        selectCameraPath(s, "orbit", frames);
        EXPECT_EQ(s.frameCount, std::max(base.frameCount, frames));
        const Camera first = s.getCameraAt(0), last = s.getCameraAt(frames - 1);
        EXPECT_LT(glm::length(first.position - c.position), 1e-4f * distance);
        // 45 degrees about the up axis through the target, at the same distance.
        EXPECT_NEAR(glm::length(last.position - c.target), distance, 1e-3f * distance);
        // The angle of the turn, seen from above (the offsets projected on the plane normal to up).
        const glm::vec3 up = glm::normalize(c.up);
        auto flat = [&](glm::vec3 v) { return glm::normalize(v - glm::dot(v, up) * up); };
        const glm::vec3 a = flat(c.position - c.target), b = flat(last.position - c.target);
        EXPECT_NEAR(glm::degrees(std::acos(std::clamp(glm::dot(a, b), -1.0f, 1.0f))), 45.0f, 0.05f);
    }
    {
        Scene s = base;
        selectCameraPath(s, "dolly", frames);
        EXPECT_NEAR(glm::length(s.getCameraAt(frames - 1).position - c.target), 0.7f * distance, 1e-3f * distance);
    }
    {
        Scene s = base;
        selectCameraPath(s, "strafe", frames);
        const Camera first = s.getCameraAt(0), last = s.getCameraAt(frames - 1);
        EXPECT_NEAR(glm::length(last.position - first.position), 0.2f * distance, 1e-3f * distance);
        EXPECT_NEAR(glm::length((last.target - first.target) - (last.position - first.position)), 0.0f,
                    1e-4f * distance)
            << "camera and target move together";
    }
    {
        Scene s = base;
        selectCameraPath(s, "static", frames);
        EXPECT_TRUE(s.cameraPath.empty());
        EXPECT_EQ(s.getCameraAt(frames - 1).position, c.position);
    }
}

TEST(CameraPaths, TheScenesOwnPathIsTheDefaultAndUnknownNamesAreErrorsListingTheValidOnes)
{
    Scene town = makeProceduralScene("tomorrow_town");
    const Camera before = town.getCameraAt(3);
    selectCameraPath(town, "", 2);
    EXPECT_EQ(town.getCameraAt(3).position, before.position);
    selectCameraPath(town, "scene", 2);
    EXPECT_EQ(town.getCameraAt(3).position, before.position);
    try {
        selectCameraPath(town, "orbiit", 2);
        ADD_FAILURE() << "unknown path accepted";
    } catch (const Error& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("did you mean orbit"), std::string::npos) << message;
        EXPECT_NE(message.find("strafe"), std::string::npos) << message;
    }
}

TEST(CameraPaths, SceneFilesDeclareNamedPathsButNotUnderBuiltInNames)
{
    const Scene s = parseSceneFile(R"(scene: room
base: ao_testbed
camera_paths:
  low_pass:
    - {time: 0, position: [0, 0.3, 3], target: [0, 0.3, 0]}
    - {time: 1, position: [1, 0.3, 3], target: [0, 0.3, 0]}
)",
                                   "room.yaml");
    ASSERT_EQ(s.namedCameraPaths.count("low_pass"), 1u);
    Scene chosen = s;
    selectCameraPath(chosen, "low_pass", 31);
    EXPECT_NEAR(chosen.getCameraAt(30).position.x, 1.0f, 1e-5f);
    try {
        parseSceneFile(R"(scene: room
base: ao_testbed
camera_paths:
  orbit:
    - {time: 0, position: [0, 0.3, 3], target: [0, 0.3, 0]}
)",
                       "room.yaml");
        ADD_FAILURE() << "a path named like a built-in was accepted";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("room.yaml:4:3"), std::string::npos) << message;
        EXPECT_NE(message.find("built-in"), std::string::npos) << message;
    }
}

} // namespace
} // namespace rtlab::scene
