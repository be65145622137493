#include "reference/embree_scene.h"

#include "core/error.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <cstring>
#include <string>
#include <utility>

namespace rtlab::reference {

namespace {

std::string describeEmbreeError(RTCError code)
{
    switch (code) {
    case RTC_ERROR_NONE:
        return "no error";
    case RTC_ERROR_UNKNOWN:
        return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT:
        return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION:
        return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:
        return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:
        return "unsupported CPU";
    case RTC_ERROR_CANCELLED:
        return "cancelled";
    }
    return "error " + std::to_string(int(code));
}

void checkDevice(RTCDevice device, const char* what)
{
    const RTCError code = rtcGetDeviceError(device);
    if (code != RTC_ERROR_NONE)
        throw Error(std::string("reference: Embree failed to ") + what + ": " +
                    describeEmbreeError(code));
}

} // namespace

EmbreeScene::EmbreeScene(const scene::RenderScene& scene)
{
    const std::size_t triangles = scene.triangleCount();
    if (triangles == 0 || scene.positions.empty())
        throw Error("reference: the scene has no triangles to trace against");
    if (scene.indices.size() % 3 != 0)
        throw Error("reference: the scene has " + std::to_string(scene.indices.size()) +
                    " indices, not a multiple of 3");
    for (std::size_t i = 0; i < scene.indices.size(); ++i)
        if (scene.indices[i] >= scene.positions.size())
            throw Error("reference: index " + std::to_string(i) + " of the scene is " +
                        std::to_string(scene.indices[i]) + " but there are only " +
                        std::to_string(scene.positions.size()) + " positions");
    for (std::size_t i = 0; i < scene.positions.size(); ++i)
        if (!std::isfinite(scene.positions[i].x) || !std::isfinite(scene.positions[i].y) ||
            !std::isfinite(scene.positions[i].z))
            throw Error("reference: scene position " + std::to_string(i) + " is not finite");

    mDevice = rtcNewDevice(nullptr);
    if (!mDevice)
        throw Error("reference: Embree failed to create a device: " +
                    describeEmbreeError(rtcGetDeviceError(nullptr)));
    try {
        glm::vec3 lo = scene.positions.front();
        glm::vec3 hi = lo;
        for (const auto& p : scene.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        mSceneScale = glm::length(glm::dvec3(hi) - glm::dvec3(lo));

        mScene = rtcNewScene(mDevice);
        // Robust traversal: no rays slip through shared edges (closed furnaces stay closed).
        rtcSetSceneFlags(mScene, RTC_SCENE_FLAG_ROBUST);
        rtcSetSceneBuildQuality(mScene, RTC_BUILD_QUALITY_HIGH);
        RTCGeometry geometry = rtcNewGeometry(mDevice, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vertices = static_cast<float*>(
            rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                    3 * sizeof(float), scene.positions.size()));
        auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles));
        checkDevice(mDevice, "allocate the triangle buffers");
        for (std::size_t i = 0; i < scene.positions.size(); ++i) {
            vertices[3 * i + 0] = scene.positions[i].x;
            vertices[3 * i + 1] = scene.positions[i].y;
            vertices[3 * i + 2] = scene.positions[i].z;
        }
        std::memcpy(indices, scene.indices.data(), triangles * 3 * sizeof(unsigned));
        rtcCommitGeometry(geometry);
        rtcAttachGeometry(mScene, geometry);
        rtcReleaseGeometry(geometry);
        rtcCommitScene(mScene);
        checkDevice(mDevice, "build the scene");
    } catch (...) {
        release();
        throw;
    }
}

EmbreeScene::~EmbreeScene()
{
    release();
}

EmbreeScene::EmbreeScene(EmbreeScene&& other) noexcept
    : mDevice(std::exchange(other.mDevice, nullptr)), mScene(std::exchange(other.mScene, nullptr)),
      mSceneScale(other.mSceneScale)
{
}

EmbreeScene& EmbreeScene::operator=(EmbreeScene&& other) noexcept
{
    if (this != &other) {
        release();
        mDevice = std::exchange(other.mDevice, nullptr);
        mScene = std::exchange(other.mScene, nullptr);
        mSceneScale = other.mSceneScale;
    }
    return *this;
}

void EmbreeScene::release()
{
    if (mScene)
        rtcReleaseScene(mScene);
    if (mDevice)
        rtcReleaseDevice(mDevice);
    mScene = nullptr;
    mDevice = nullptr;
}

bool EmbreeScene::intersect(const glm::vec3& org, const glm::vec3& dir, float tFar,
                            RayHit& hit) const
{
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh;
    rh.ray.org_x = org.x;
    rh.ray.org_y = org.y;
    rh.ray.org_z = org.z;
    rh.ray.tnear = 0.0f;
    rh.ray.dir_x = dir.x;
    rh.ray.dir_y = dir.y;
    rh.ray.dir_z = dir.z;
    rh.ray.time = 0.0f;
    rh.ray.tfar = tFar;
    rh.ray.mask = 0xffffffffu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    if (mLog != nullptr)
        mLog->local().push_back({rh.ray, true});
    rtcIntersect1(mScene, &context, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return false;
    hit.t = rh.ray.tfar;
    hit.triangle = rh.hit.primID;
    hit.u = rh.hit.u;
    hit.v = rh.hit.v;
    hit.geometricNormal = glm::vec3(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
    return true;
}

bool EmbreeScene::occluded(const glm::vec3& org, const glm::vec3& dir, float tFar) const
{
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRay ray = makeRay(org, dir, tFar);
    if (mLog != nullptr)
        mLog->local().push_back({ray, false});
    rtcOccluded1(mScene, &context, &ray);
    // Embree sets tfar to -inf when the ray is occluded.
    return ray.tfar < 0.0f;
}

void EmbreeScene::occluded(RTCRay* rays, unsigned count, bool coherent) const
{
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = coherent ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    if (mLog != nullptr)
        for (unsigned i = 0; i < count; ++i)
            mLog->local().push_back({rays[i], false});
    rtcOccluded1M(mScene, &context, rays, count, sizeof(RTCRay));
}

} // namespace rtlab::reference
