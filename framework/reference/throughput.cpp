// Ray throughput of the reference next to bare Embree calls on the same rays.
#include "reference/reference.h"

#include "reference/prepared.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace rtlab::reference {

namespace {

double getSecondsSince(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Bare Embree calls over `work` in chunks of 1024 on the arena's threads: rtcIntersect1 where
// closest(i), else rtcOccluded1. Returns the seconds.
template <class Closest>
double traceBare(RTCScene handle, std::vector<RTCRayHit>& work, const Closest& closest)
{
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, work.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          RTCIntersectContext context;
                          rtcInitIntersectContext(&context);
                          for (std::size_t i = r.begin(); i != r.end(); ++i)
                              if (closest(i))
                                  rtcIntersect1(handle, &context, &work[i]);
                              else
                                  rtcOccluded1(handle, &context, &work[i].ray);
                      });
    return getSecondsSince(start);
}

} // namespace

RayThroughput measureRayThroughput(const scene::RenderScene& scene, const scene::GBuffer& gbuffer,
                                   const ReferenceSettings& settings, int samplesPerPixel, int repeats)
{
    ReferenceSettings s = settings;
    s.batchSize = std::max(1, samplesPerPixel);
    s.maxSamples = s.batchSize;
    s.targetStdErr = 0.0;
    s.targetRelStdErr = 0.0;
    s.useCache = false;

    RayThroughput result;
    tbb::task_arena arena(s.threadCount > 0 ? s.threadCount : int(tbb::task_arena::automatic));
    result.threads = arena.max_concurrency();
    arena.execute([&] {
        const PreparedReference prepared(scene, gbuffer, s);
        ProgressiveRule rule;
        rule.channels = 1; // no early stop: the targets are 0
        rule.batchSize = s.batchSize;
        rule.maxSamples = s.maxSamples;
        for (std::uint8_t active : prepared.getActive())
            result.referenceSamples += active ? std::uint64_t(s.batchSize) : 0;

        const auto traceReference = [&] {
            const auto start = std::chrono::steady_clock::now();
            const ProgressiveOutput out = runProgressive(
                gbuffer.width, gbuffer.height, prepared.getActive(), rule,
                [&](std::size_t pixel, std::uint32_t first, std::uint32_t count, SampleValue* values) {
                    return prepared.evaluateBatch(pixel, first, count, values);
                });
            result.referenceRays = out.rayCount;
            return getSecondsSince(start);
        };

        // The same number of rays as AO would trace: cosine-distributed from the same origins.
        std::vector<RTCRayHit> rays;
        const double eps = prepared.getContext().rayEpsilon;
        const float tFar = std::isinf(s.radius) ? kInfiniteDistance : float(s.radius);
        for (std::size_t pixel = 0; pixel < prepared.getActive().size(); ++pixel) {
            if (!prepared.getActive()[pixel])
                continue;
            const SurfacePoint& p = prepared.getPoint(pixel);
            const Frame frame = Frame::fromNormal(p.normal);
            const glm::vec3 o(p.position + eps * p.normal);
            const PixelSequence sequence(s.seed, pixel);
            for (std::uint32_t i = 0; i < std::uint32_t(s.maxSamples); ++i) {
                const glm::vec3 d(frame.toWorld(sampleCosineHemisphere(sequence.get2D(i, 0))));
                RTCRayHit rh{};
                rh.ray = makeRay(o, d, tFar);
                rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                rays.push_back(rh);
            }
        }
        result.rawRays = rays.size();
        const RTCScene handle = prepared.getEmbree().getHandle();
        std::vector<RTCRayHit> work;
        const auto traceRaw = [&](bool closest) {
            work = rays;
            return traceBare(handle, work, [closest](std::size_t) { return closest; });
        };
        // The estimator's own rays: logged per thread in one untimed round, then traced in the
        // same per-thread order and chunks through the bare call each was made with.
        RayLog log;
        prepared.getEmbree().setRayLog(&log);
        traceReference();
        prepared.getEmbree().setRayLog(nullptr);
        std::vector<LoggedRay> logged;
        for (const std::vector<LoggedRay>& threadRays : log)
            logged.insert(logged.end(), threadRays.begin(), threadRays.end());
        log.clear();
        result.replayRays = logged.size();
        std::vector<RTCRayHit> replayWork(logged.size());
        const auto traceReplay = [&] {
            for (std::size_t i = 0; i < logged.size(); ++i) {
                replayWork[i].ray = logged[i].ray;
                replayWork[i].hit.geomID = RTC_INVALID_GEOMETRY_ID;
                replayWork[i].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            }
            return traceBare(handle, replayWork, [&](std::size_t i) { return logged[i].closest; });
        };
        // One untimed round wakes the arena's threads and warms the caches for all four (the
        // estimator's was the logged round); then the four alternate, and each keeps its median
        // (a 16-sample run lasts tens of ms, where one thread start-up or preemption would decide
        // the ratio).
        traceRaw(true);
        traceReplay();
        std::vector<double> reference, intersect, occluded, replay;
        for (int r = 0; r < std::max(1, repeats); ++r) {
            reference.push_back(traceReference());
            intersect.push_back(traceRaw(true));
            occluded.push_back(traceRaw(false));
            replay.push_back(traceReplay());
        }
        const auto median = [](std::vector<double> v) {
            std::sort(v.begin(), v.end());
            return v[v.size() / 2];
        };
        result.referenceSeconds = median(reference);
        result.rawIntersectSeconds = median(intersect);
        result.rawOccludedSeconds = median(occluded);
        result.replaySeconds = median(replay);
        result.repeats = int(reference.size());
    });
    auto rate = [](std::uint64_t rays, double seconds) {
        return seconds > 0.0 ? double(rays) / seconds * 1e-6 : 0.0;
    };
    result.referenceMraysPerSecond = rate(result.referenceRays, result.referenceSeconds);
    result.rawIntersectMraysPerSecond = rate(result.rawRays, result.rawIntersectSeconds);
    result.rawOccludedMraysPerSecond = rate(result.rawRays, result.rawOccludedSeconds);
    result.replayMraysPerSecond = rate(result.replayRays, result.replaySeconds);
    return result;
}

} // namespace rtlab::reference
