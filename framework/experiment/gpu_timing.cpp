#include "experiment/gpu_timing.h"

#include "gpu/context.h"

#include <map>

namespace rtlab::experiment {

GpuTimeSource chooseGpuTimeSource(const gpu::DeviceInfo& device)
{
    return device.isCpu || !device.timestampsSupported ? GpuTimeSource::SubmitWallTime
                                                       : GpuTimeSource::Timestamps;
}

const char* toString(GpuTimeSource source)
{
    return source == GpuTimeSource::Timestamps ? "timestamps"
                                               : "submit-to-fence wall time (CPU Vulkan device)";
}

metrics::GpuPassTimes collectGpuPassTimes(gpu::Context& context)
{
    metrics::GpuPassTimes times;
    const auto log = context.takeRunLog();
    if (chooseGpuTimeSource(context.getDeviceInfo()) == GpuTimeSource::Timestamps) {
        for (const auto& c : log)
            if (c.gpuMs)
                times[c.label] += *c.gpuMs;
        return times;
    }
    // One entry per submission: its labels joined, its wall time.
    std::map<std::uint64_t, std::pair<std::string, double>> runs;
    for (const auto& c : log) {
        auto& [label, ms] = runs[c.runIndex];
        label += (label.empty() ? "" : "+") + c.label;
        ms = c.runSubmitMs;
    }
    for (const auto& [index, run] : runs)
        times[run.first] += run.second;
    return times;
}

} // namespace rtlab::experiment
