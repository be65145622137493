#include "scene/camera_paths.h"

#include "core/error.h"
#include "core/strings.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <glm/gtx/rotate_vector.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::scene {

namespace {

constexpr int kGeneratedKeys = 5;

// Keyframes of camera(u), u in [0, 1], spread over `frames` frames at `frameRate`.
template <class F> CameraPath makePath(int frames, float frameRate, F cameraAt)
{
    const float duration = float(std::max(frames, 2) - 1) / frameRate;
    std::vector<CameraKeyframe> keys;
    for (int k = 0; k < kGeneratedKeys; ++k) {
        const float u = float(k) / float(kGeneratedKeys - 1);
        keys.push_back({u * duration, cameraAt(u)});
    }
    return CameraPath(keys);
}

} // namespace

const std::vector<std::string>& getBuiltinCameraPathNames()
{
    static const std::vector<std::string> names = {"scene", "static", "orbit", "dolly", "strafe"};
    return names;
}

bool isBuiltinCameraPathName(const std::string& name)
{
    const auto& names = getBuiltinCameraPathNames();
    return std::find(names.begin(), names.end(), name) != names.end();
}

std::vector<std::string> getCameraPathNames(const Scene& scene)
{
    std::vector<std::string> names = getBuiltinCameraPathNames();
    for (const auto& [name, path] : scene.namedCameraPaths)
        names.push_back(name);
    return names;
}

void selectCameraPath(Scene& scene, const std::string& name, int frames)
{
    if (name.empty() || name == "scene")
        return;
    const Camera c = scene.camera;
    const glm::vec3 offset = c.position - c.target;
    const float distance = glm::length(offset);
    if (name == "static") {
        scene.cameraPath = CameraPath();
    } else if (name == "orbit") {
        const glm::vec3 axis = glm::length(c.up) > 0.0f ? glm::normalize(c.up) : glm::vec3(0, 1, 0);
        scene.cameraPath = makePath(frames, scene.frameRate, [&](float u) {
            Camera k = c;
            k.position = c.target + glm::rotate(offset, u * glm::quarter_pi<float>(), axis);
            return k;
        });
    } else if (name == "dolly") {
        scene.cameraPath = makePath(frames, scene.frameRate, [&](float u) {
            Camera k = c;
            k.position = c.target + offset * (1.0f - 0.3f * u);
            return k;
        });
    } else if (name == "strafe") {
        glm::vec3 right = glm::cross(-offset, c.up);
        right = glm::length(right) > 0.0f ? glm::normalize(right) : glm::vec3(1, 0, 0);
        scene.cameraPath = makePath(frames, scene.frameRate, [&](float u) {
            Camera k = c;
            const glm::vec3 shift = right * (0.2f * distance * (u - 0.5f));
            k.position = c.position + shift;
            k.target = c.target + shift;
            return k;
        });
    } else if (auto it = scene.namedCameraPaths.find(name); it != scene.namedCameraPaths.end()) {
        scene.cameraPath = it->second;
    } else {
        std::string message = "scene '" + scene.name + "' has no camera path '" + name + "'";
        const auto close = closestNames(name, getCameraPathNames(scene));
        if (!close.empty())
            message += "; did you mean " + joinList(close, "or") + "?";
        throw Error(message + " Valid paths: " + joinList(getCameraPathNames(scene)) + ".");
    }
    scene.frameCount = std::max(scene.frameCount, frames);
}

} // namespace rtlab::scene
