#include "cli/commands.h"

#include "core/error.h"
#include "gpu/smoke.h"

#include <fmt/core.h>

namespace rtlab::cli {

int gpuSmoke(const GpuOptions& options)
{
    gpu::ContextOptions contextOptions;
    contextOptions.deviceName = options.device;
    contextOptions.enableValidation = options.validation;
    try {
        const gpu::SmokeResult r = gpu::runSmokeTest(contextOptions);
        fmt::print("device:      {}\n", r.device.describe());
        fmt::print("smoke:       {} elements, {}\n", r.elementCount, r.passed ? "results verified" : r.message);
        fmt::print("compile:     {:.2f} ms ({})\n", r.compileMs, r.cacheHit ? "SPIR-V cache hit" : "compiled");
        if (r.gpuMs)
            fmt::print("gpu time:    {:.4f} ms (median of {} timestamped dispatches)\n", *r.gpuMs,
                       r.gpuMsPerRun.size());
        else
            fmt::print("gpu time:    unavailable (the queue has no timestamps)\n");
        fmt::print("cpu time:    {:.4f} ms (median submit-to-completion)\n", r.cpuMs);
        return r.passed ? kExitOk : kExitFailed;
    } catch (const EnvironmentError& e) {
        fmt::print(stderr, "rtlab gpu: {}\n", e.what());
        return kExitEnvironment;
    } catch (const Error& e) {
        fmt::print(stderr, "rtlab gpu: {}\n", e.what());
        return kExitFailed;
    }
}

} // namespace rtlab::cli
