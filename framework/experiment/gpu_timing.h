#pragma once
// How the harness reads GPU pass times from a Vulkan context after a technique ran.
//
// On a real GPU: the timestamps around each labelled dispatch or draw. On a CPU implementation
// (Mesa's lavapipe) timestamps do not bracket compute dispatches that write storage images: a
// GTAO dispatch at 1280x720 read 0.03 ms between its timestamps while its submission took 571 ms
// from submit to fence (Mesa 22.3). There the GPU time of a submission is its submit-to-fence
// wall time, reported under the labels of its commands joined by '+'. Either way the technique
// reports nothing itself: the numbers come from the context's run log.

#include "metrics/timing.h"

#include <string>

namespace rtlab::gpu {
class Context;
struct DeviceInfo;
} // namespace rtlab::gpu

namespace rtlab::experiment {

enum class GpuTimeSource {
    Timestamps,     //!< per command, from timestamp queries
    SubmitWallTime, //!< per submission, submit to fence, on the CPU
};

GpuTimeSource chooseGpuTimeSource(const gpu::DeviceInfo& device);
const char* toString(GpuTimeSource source);

//! Pass times of everything `context` ran since the last call (and clears its run log).
metrics::GpuPassTimes collectGpuPassTimes(gpu::Context& context);

} // namespace rtlab::experiment
