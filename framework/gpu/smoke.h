#pragma once
// A quick end-to-end check of the GPU path for the command line: compile the built-in smoke
// shader, run it on 2^20 elements, verify every result on the CPU and report timings.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gpu/context.h"
#include "gpu/shader_compiler.h"

namespace rtlab::gpu {

//! Settings of the smoke test.
struct SmokeOptions {
    std::uint32_t elementCount = 1u << 20;
    std::uint32_t repetitions = 5;  //!< timed runs; the reported GPU time is their median
    ShaderCompilerOptions compiler; //!< cache directory etc.; the include dir is added
};

//! What the smoke test found.
struct SmokeResult {
    bool passed = false;
    std::string message; //!< "ok" or what went wrong
    DeviceInfo device;
    std::uint32_t elementCount = 0;
    std::uint64_t mismatches = 0; //!< elements that differ from the CPU result
    double compileMs = 0.0;
    bool cacheHit = false;
    std::optional<double> gpuMs;     //!< median dispatch time; empty without timestamps
    std::vector<double> gpuMsPerRun; //!< every repetition (empty without timestamps)
    double cpuMs = 0.0;              //!< median submit-to-completion wall time
};

//! Runs the smoke test on a new Context. Environment problems (no device, missing layer) and
//! shader errors throw; wrong results give passed == false.
SmokeResult runSmokeTest(const ContextOptions& contextOptions = {},
                         const SmokeOptions& smokeOptions = {});

} // namespace rtlab::gpu
