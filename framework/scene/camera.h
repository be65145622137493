#pragma once
// Pinhole cameras and camera paths (keyframes interpolated over time).

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <vector>

namespace rtlab::scene {

//! A pinhole camera. Right-handed: looks from `position` toward `target`, `up` roughly up.
struct Camera {
    glm::vec3 position{0.0f, 0.0f, 3.0f};  //!< world units
    glm::vec3 target{0.0f};                //!< world units, != position
    glm::vec3 up{0.0f, 1.0f, 0.0f};        //!< need not be orthogonal to the view direction
    float verticalFovDegrees = 45.0f;      //!< (0, 180)
    float nearPlane = 0.05f;               //!< world units, > 0
    float farPlane = 100.0f;               //!< world units, > nearPlane

    //! World -> view (camera at origin looking down -z, y up).
    glm::mat4 viewMatrix() const;
    //! View -> Vulkan clip space (depth 0 at near, 1 at far; y down in NDC) for `aspect` = w/h.
    glm::mat4 projectionMatrix(float aspect) const;
    //! The same with the pixel samples of a `size` image moved to pixel centre + `jitterPixels`
    //! (sub-pixel offset in pixels, for temporal jitter; the image content moves by -jitter).
    glm::mat4 projectionMatrix(float aspect, glm::vec2 jitterPixels, glm::ivec2 size) const;
};

//! A camera at a time, for paths.
struct CameraKeyframe {
    float time = 0.0f;  //!< seconds
    Camera camera;
};

//! Keyframed camera motion: positions and targets follow centripetal Catmull-Rom splines through
//! the keyframes (no overshoot loops); field of view and planes are interpolated linearly.
//! Before the first and after the last keyframe the camera holds still.
class CameraPath {
public:
    CameraPath() = default;
    explicit CameraPath(std::vector<CameraKeyframe> keys);  //!< sorted by time on construction

    Camera evaluate(float time) const;
    bool empty() const { return mKeys.empty(); }
    bool moves() const;  //!< false when every keyframe is the same camera
    float duration() const { return mKeys.empty() ? 0.0f : mKeys.back().time - mKeys.front().time; }
    const std::vector<CameraKeyframe>& keyframes() const { return mKeys; }

private:
    std::vector<CameraKeyframe> mKeys;
};

} // namespace rtlab::scene
