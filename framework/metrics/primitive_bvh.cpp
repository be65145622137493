// PrimitiveBvh on Embree: a scene of one user geometry whose primitives are the given boxes.
// Point queries (rtcPointQuery) visit the primitives whose boxes reach the query sphere and
// shrink its radius; collisions (rtcCollide of the scene with itself) report box pairs.

#include "metrics/mesh_metrics_detail.h"

#include "core/error.h"

#include <embree3/rtcore.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

namespace rtlab::metrics::detail {

namespace {

void checkEmbree(RTCDevice device, const char* what)
{
    const RTCError code = rtcGetDeviceError(device);
    if (code != RTC_ERROR_NONE)
        throw Error(std::string("metrics: Embree failed to ") + what + " (error " +
                    std::to_string(int(code)) + ")");
}

// Float boxes rounded outwards, so that each contains its double-precision primitive.
struct FloatBox {
    float lo[3];
    float hi[3];
};

void setBounds(const RTCBoundsFunctionArguments* args)
{
    const auto* boxes = static_cast<const FloatBox*>(args->geometryUserPtr);
    const FloatBox& b = boxes[args->primID];
    RTCBounds* out = args->bounds_o;
    out->lower_x = b.lo[0];
    out->lower_y = b.lo[1];
    out->lower_z = b.lo[2];
    out->upper_x = b.hi[0];
    out->upper_y = b.hi[1];
    out->upper_z = b.hi[2];
}

struct NearestQuery {
    glm::dvec3 point;
    double offset;  // distance between point and the float query centre

    const PrimitiveBvh::DistanceFunction* distance;
    double best;
    std::uint32_t bestIndex;
};

bool visitNearest(RTCPointQueryFunctionArguments* args)
{
    auto* q = static_cast<NearestQuery*>(args->userPtr);
    const double d = (*q->distance)(args->primID, q->point);
    if (!(d < q->best))
        return false;
    q->best = d;
    q->bestIndex = args->primID;
    // Shrink the search sphere around the float centre, with a relative margin so that float
    // culling in the traversal never drops a primitive that is as near in double precision.
    const float radius = std::nextafter(float((d + q->offset) * (1.0 + 1e-6)),
                                        std::numeric_limits<float>::infinity());
    if (radius < args->query->radius) {
        args->query->radius = radius;
        return true;
    }
    return false;
}

struct PairCollector {
    std::mutex mutex;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
};

void collectPairs(void* userPtr, RTCCollision* collisions, unsigned int count)
{
    auto* collector = static_cast<PairCollector*>(userPtr);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> local;
    local.reserve(count);
    for (unsigned int i = 0; i < count; ++i) {
        const std::uint32_t a = collisions[i].primID0, b = collisions[i].primID1;
        if (a != b)
            local.emplace_back(std::min(a, b), std::max(a, b));
    }
    const std::lock_guard<std::mutex> lock(collector->mutex);
    collector->pairs.insert(collector->pairs.end(), local.begin(), local.end());
}

} // namespace

struct PrimitiveBvh::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<FloatBox> boxes;

    ~Impl()
    {
        if (scene)
            rtcReleaseScene(scene);
        if (device)
            rtcReleaseDevice(device);
    }
};

PrimitiveBvh::PrimitiveBvh(const std::vector<Box>& boxes) : mImpl(std::make_unique<Impl>())
{
    constexpr float kInf = std::numeric_limits<float>::infinity();
    mImpl->boxes.resize(boxes.size());
    for (std::size_t i = 0; i < boxes.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            mImpl->boxes[i].lo[k] = std::nextafter(float(boxes[i].lo[k]), -kInf);
            mImpl->boxes[i].hi[k] = std::nextafter(float(boxes[i].hi[k]), kInf);
        }
    if (boxes.empty())
        return;
    if (boxes.size() > std::size_t(std::numeric_limits<unsigned>::max()))
        throw Error("metrics: too many primitives for one Embree geometry");

    mImpl->device = rtcNewDevice(nullptr);
    if (!mImpl->device)
        throw Error("metrics: Embree failed to create a device (error " +
                    std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    mImpl->scene = rtcNewScene(mImpl->device);
    RTCGeometry geometry = rtcNewGeometry(mImpl->device, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(geometry, unsigned(boxes.size()));
    rtcSetGeometryUserData(geometry, mImpl->boxes.data());
    rtcSetGeometryBoundsFunction(geometry, setBounds, mImpl->boxes.data());
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(mImpl->scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(mImpl->scene);
    checkEmbree(mImpl->device, "build a BVH");
}

PrimitiveBvh::~PrimitiveBvh() = default;

double PrimitiveBvh::findNearestDistance(const glm::dvec3& p, const DistanceFunction& distance,
                                         std::uint32_t* nearest) const
{
    const glm::vec3 centre(p);
    NearestQuery q{p, glm::length(p - glm::dvec3(centre)), &distance,
                   std::numeric_limits<double>::infinity(), 0};
    if (mImpl->scene) {
        RTCPointQuery query;
        query.x = centre.x;
        query.y = centre.y;
        query.z = centre.z;
        query.time = 0.0f;
        query.radius = std::numeric_limits<float>::infinity();
        RTCPointQueryContext context;
        rtcInitPointQueryContext(&context);
        rtcPointQuery(mImpl->scene, &query, &context, visitNearest, &q);
    }
    if (nearest)
        *nearest = q.bestIndex;
    return q.best;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> PrimitiveBvh::findOverlappingPairs() const
{
    PairCollector collector;
    if (mImpl->scene) {
        rtcCollide(mImpl->scene, mImpl->scene, collectPairs, &collector);
        checkEmbree(mImpl->device, "find overlapping boxes");
    }
    auto& pairs = collector.pairs;
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    return std::move(pairs);
}

} // namespace rtlab::metrics::detail
