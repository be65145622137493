#pragma once
// The RenderScene as one Embree 3 triangle geometry (internal to rtlab_reference: the only
// header that includes Embree). Owns its device and scene (RAII, move-only).

#include "scene/render_scene.h"

#include <embree3/rtcore.h>
#include <glm/vec3.hpp>

#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <limits>
#include <vector>

namespace rtlab::reference {

struct RayHit {
    float t = 0.0f;
    std::uint32_t triangle = 0;
    float u = 0.0f;                  //!< barycentric of vertex 1
    float v = 0.0f;                  //!< barycentric of vertex 2
    glm::vec3 geometricNormal{0.0f}; //!< unnormalised, Embree's orientation
};

//! A ray as an estimator traced it: the query (closest hit or occlusion) and the ray.
struct LoggedRay {
    RTCRay ray;
    bool closest = false;
};
//! The rays each thread traced, in its order (EmbreeScene::setRayLog).
using RayLog = tbb::enumerable_thread_specific<std::vector<LoggedRay>>;

class EmbreeScene {
public:
    //! Throws rtlab::Error when the scene has no triangles or Embree reports an error.
    explicit EmbreeScene(const scene::RenderScene& scene);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;
    EmbreeScene(EmbreeScene&& other) noexcept;
    EmbreeScene& operator=(EmbreeScene&& other) noexcept;

    //! Closest hit along org + t dir, 0 <= t <= tFar (dir need not be unit; t is in its units).
    bool intersect(const glm::vec3& org, const glm::vec3& dir, float tFar, RayHit& hit) const;
    //! Whether anything lies along org + t dir, 0 <= t <= tFar.
    bool occluded(const glm::vec3& org, const glm::vec3& dir, float tFar) const;
    //! The same for a stream of rays (rtcOccluded1M), traced together: `coherent` makes Embree
    //! trace them as packets, which suits rays that stay together (not a hemisphere's). An
    //! occluded ray's tfar becomes -inf.
    void occluded(RTCRay* rays, unsigned count, bool coherent) const;
    //! While `log` is set, every ray traced through this scene is appended to the calling
    //! thread's list in `log` (measureRayThroughput replays them through bare Embree calls);
    //! nullptr stops logging.
    void setRayLog(RayLog* log) const { mLog = log; }

    RTCScene getHandle() const { return mScene; }
    //! Length of the diagonal of the triangles' bounding box.
    double getSceneScale() const { return mSceneScale; }

private:
    void release();

    RTCDevice mDevice = nullptr;
    RTCScene mScene = nullptr;
    double mSceneScale = 0.0;
    mutable RayLog* mLog = nullptr;
};

//! The largest float tFar Embree accepts as "no limit".
constexpr float kInfiniteDistance = std::numeric_limits<float>::infinity();

//! An Embree ray org + t dir, 0 <= t <= tFar, every mask bit set, time 0.
inline RTCRay makeRay(const glm::vec3& org, const glm::vec3& dir, float tFar)
{
    RTCRay ray;
    ray.org_x = org.x;
    ray.org_y = org.y;
    ray.org_z = org.z;
    ray.tnear = 0.0f;
    ray.dir_x = dir.x;
    ray.dir_y = dir.y;
    ray.dir_z = dir.z;
    ray.time = 0.0f;
    ray.tfar = tFar;
    ray.mask = 0xffffffffu;
    ray.id = 0;
    ray.flags = 0;
    return ray;
}

} // namespace rtlab::reference
