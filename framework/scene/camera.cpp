#include "scene/camera.h"

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::scene {

glm::mat4 Camera::viewMatrix() const
{
    return glm::lookAtRH(position, target, up);
}

glm::mat4 Camera::projectionMatrix(float aspect) const
{
    return projectionMatrix(aspect, glm::vec2(0.0f), glm::ivec2(1));
}

glm::mat4 Camera::projectionMatrix(float aspect, glm::vec2 jitterPixels, glm::ivec2 size) const
{
    // Right-handed view space, Vulkan clip space: depth in [0, 1], NDC y pointing down.
    glm::mat4 p = glm::perspectiveRH_ZO(glm::radians(verticalFovDegrees), aspect, nearPlane, farPlane);
    p[1][1] = -p[1][1];
    // The sample moves to pixel centre + jitter, so the image moves by -jitter: a translation in
    // NDC by -2 * jitter / size after the divide, i.e. the third column gets +2 * jitter / size
    // (clip w = -z_view).
    p[2][0] += 2.0f * jitterPixels.x / float(size.x);
    p[2][1] += 2.0f * jitterPixels.y / float(size.y);
    return p;
}

CameraPath::CameraPath(std::vector<CameraKeyframe> keys) : mKeys(std::move(keys))
{
    std::stable_sort(mKeys.begin(), mKeys.end(),
                     [](const CameraKeyframe& a, const CameraKeyframe& b) { return a.time < b.time; });
}

bool CameraPath::moves() const
{
    for (const auto& k : mKeys) {
        const Camera& a = k.camera;
        const Camera& b = mKeys.front().camera;
        if (a.position != b.position || a.target != b.target || a.up != b.up ||
            a.verticalFovDegrees != b.verticalFovDegrees)
            return true;
    }
    return false;
}

namespace {

// Centripetal Catmull-Rom (alpha = 0.5) through p1..p2 at t in [0, 1] [Yuksel et al. 2011]:
// it never forms cusps or self-intersections within a segment, unlike the uniform variant.
glm::vec3 evaluateCatmullRom(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                             const glm::vec3& p3, float t)
{
    auto knot = [](float ti, const glm::vec3& a, const glm::vec3& b) {
        return ti + std::max(std::sqrt(glm::length(b - a)), 1e-6f);
    };
    const float t0 = 0.0f;
    const float t1 = knot(t0, p0, p1);
    const float t2 = knot(t1, p1, p2);
    const float t3 = knot(t2, p2, p3);
    const float u = t1 + (t2 - t1) * t;
    const glm::vec3 a1 = (t1 - u) / (t1 - t0) * p0 + (u - t0) / (t1 - t0) * p1;
    const glm::vec3 a2 = (t2 - u) / (t2 - t1) * p1 + (u - t1) / (t2 - t1) * p2;
    const glm::vec3 a3 = (t3 - u) / (t3 - t2) * p2 + (u - t2) / (t3 - t2) * p3;
    const glm::vec3 b1 = (t2 - u) / (t2 - t0) * a1 + (u - t0) / (t2 - t0) * a2;
    const glm::vec3 b2 = (t3 - u) / (t3 - t1) * a2 + (u - t1) / (t3 - t1) * a3;
    return (t2 - u) / (t2 - t1) * b1 + (u - t1) / (t2 - t1) * b2;
}

} // namespace

Camera CameraPath::evaluate(float time) const
{
    if (mKeys.empty())
        return Camera{};
    if (time <= mKeys.front().time || mKeys.size() == 1)
        return mKeys.front().camera;
    if (time >= mKeys.back().time)
        return mKeys.back().camera;
    std::size_t i = 0;
    while (i + 1 < mKeys.size() && mKeys[i + 1].time <= time)
        ++i;
    const auto& k1 = mKeys[i];
    const auto& k2 = mKeys[i + 1];
    const auto& k0 = i > 0 ? mKeys[i - 1] : k1;
    const auto& k3 = i + 2 < mKeys.size() ? mKeys[i + 2] : k2;
    const float span = k2.time - k1.time;
    const float t = span > 0 ? (time - k1.time) / span : 0.0f;

    Camera c = k1.camera;
    // Duplicate end points would make a zero-length knot interval; extrapolate them instead.
    const glm::vec3 p0 = i > 0 ? k0.camera.position : 2.0f * k1.camera.position - k2.camera.position;
    const glm::vec3 p3 = i + 2 < mKeys.size() ? k3.camera.position : 2.0f * k2.camera.position - k1.camera.position;
    const glm::vec3 q0 = i > 0 ? k0.camera.target : 2.0f * k1.camera.target - k2.camera.target;
    const glm::vec3 q3 = i + 2 < mKeys.size() ? k3.camera.target : 2.0f * k2.camera.target - k1.camera.target;
    c.position = k1.camera.position == k2.camera.position
                     ? k1.camera.position
                     : evaluateCatmullRom(p0, k1.camera.position, k2.camera.position, p3, t);
    c.target = k1.camera.target == k2.camera.target
                   ? k1.camera.target
                   : evaluateCatmullRom(q0, k1.camera.target, k2.camera.target, q3, t);
    c.up = glm::normalize(glm::mix(k1.camera.up, k2.camera.up, t));
    c.verticalFovDegrees = glm::mix(k1.camera.verticalFovDegrees, k2.camera.verticalFovDegrees, t);
    c.nearPlane = glm::mix(k1.camera.nearPlane, k2.camera.nearPlane, t);
    c.farPlane = glm::mix(k1.camera.farPlane, k2.camera.farPlane, t);
    return c;
}

} // namespace rtlab::scene
