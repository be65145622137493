// The GPU smoke test behind `rtlab` commands that check the installation.

#include "gpu/smoke.h"

#include <algorithm>

namespace rtlab::gpu {

namespace {

constexpr std::uint32_t kGroupSize = 64;
constexpr float kScale = 2.5f;

struct SmokeParams {
    float a;
    std::uint32_t count;
};

// Inputs are small integers so that a * x + y is exact in float, with or without fused
// multiply-add; every GPU must then match the CPU bit for bit.
float makeX(std::uint32_t i)
{
    return static_cast<float>(i % 1024u);
}

float makeY(std::uint32_t i)
{
    return static_cast<float>((i * 7u) % 512u);
}

double findMedian(std::vector<double> values)
{
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

} // namespace

SmokeResult runSmokeTest(const ContextOptions& contextOptions, const SmokeOptions& smokeOptions)
{
    Context context(contextOptions);
    SmokeResult result;
    result.device = context.getDeviceInfo();
    const std::uint32_t n = std::max<std::uint32_t>(smokeOptions.elementCount, 1);
    result.elementCount = n;

    ShaderCompilerOptions compilerOptions = smokeOptions.compiler;
    compilerOptions.includeDirs.push_back(getBuiltinShaderDir());
    const ShaderCompiler compiler(compilerOptions);
    const CompiledShader shader = compiler.compileFile(getBuiltinShaderDir() / "smoke.comp");
    result.compileMs = shader.compileMs;
    result.cacheHit = shader.cacheHit;

    ComputePipelineDesc desc;
    desc.name = "smoke";
    desc.spirv = shader.spirv;
    desc.bindings = {{0, BindingType::StorageBuffer}, {1, BindingType::StorageBuffer}};
    desc.pushConstantSize = sizeof(SmokeParams);
    desc.specConstants = {SpecConstant::makeUint(0, kGroupSize)};
    const ComputePipeline pipeline = context.createPipeline(desc);

    std::vector<float> x(n), y(n), expected(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        x[i] = makeX(i);
        y[i] = makeY(i);
        expected[i] = kScale * x[i] + y[i];
    }
    Buffer xBuffer = context.createBuffer({n * sizeof(float), "smoke.x"});
    Buffer yBuffer = context.createBuffer({n * sizeof(float), "smoke.y"});
    xBuffer.uploadSpan<float>(x);

    const SmokeParams params{kScale, n};
    std::vector<double> cpuMs;
    const std::uint32_t repetitions = std::max<std::uint32_t>(smokeOptions.repetitions, 1);
    for (std::uint32_t rep = 0; rep < repetitions; ++rep) {
        yBuffer.uploadSpan<float>(y);
        const RunResult run = context.run([&](CommandList& cmd) {
            cmd.dispatch(
                pipeline, {Binding::storageBuffer(0, xBuffer), Binding::storageBuffer(1, yBuffer)},
                PushConstants(params), GroupCount{computeGroupCount(n, kGroupSize)}, "smoke");
        });
        cpuMs.push_back(run.cpuSubmitMs);
        if (const std::optional<double> ms = run.sumGpuMs("smoke"))
            result.gpuMsPerRun.push_back(*ms);
        const std::vector<float> got = yBuffer.downloadVector<float>(n);
        for (std::uint32_t i = 0; i < n; ++i)
            result.mismatches += got[i] != expected[i];
    }
    result.cpuMs = findMedian(cpuMs);
    if (!result.gpuMsPerRun.empty())
        result.gpuMs = findMedian(result.gpuMsPerRun);
    result.passed = result.mismatches == 0;
    result.message = result.passed ? "ok"
                                   : std::to_string(result.mismatches) + " of " +
                                         std::to_string(std::uint64_t{n} * repetitions) +
                                         " results differ from the CPU";
    return result;
}

} // namespace rtlab::gpu
