// The smoke entry point used by the command line.

#include <cmath>
#include <cstdio>

#include "gpu/smoke.h"
#include "gpu_test_support.h"

namespace rtlab::gpu::test {
namespace {

TEST(GpuSmoke, PassesWithValidationAndReportsTimings)
{
    TempDir cache("smoke-cache");
    ContextOptions contextOptions;
    contextOptions.enableValidation = true;
    contextOptions.echoValidationMessages = false;
    contextOptions.validationLog = std::make_shared<ValidationLog>();
    SmokeOptions smokeOptions;
    smokeOptions.compiler.cacheDir = cache.getPath();

    const SmokeResult first = runSmokeTest(contextOptions, smokeOptions);
    EXPECT_TRUE(first.passed) << first.message;
    EXPECT_EQ(first.message, "ok");
    EXPECT_EQ(first.mismatches, 0u);
    EXPECT_EQ(first.elementCount, 1u << 20);
    EXPECT_FALSE(first.device.name.empty());
    EXPECT_FALSE(first.cacheHit);
    EXPECT_GT(first.compileMs, 0.0);
    ASSERT_TRUE(first.gpuMs.has_value());
    EXPECT_TRUE(std::isfinite(*first.gpuMs));
    EXPECT_GT(*first.gpuMs, 0.0);
    EXPECT_EQ(first.gpuMsPerRun.size(), smokeOptions.repetitions);
    EXPECT_GT(first.cpuMs, 0.0);
    EXPECT_LE(*first.gpuMs, first.cpuMs * 1.01 + 0.05);

    const SmokeResult second = runSmokeTest(contextOptions, smokeOptions);
    EXPECT_TRUE(second.passed) << second.message;
    EXPECT_TRUE(second.cacheHit);

    const std::vector<std::string> messages = contextOptions.validationLog->getMessages();
    EXPECT_TRUE(messages.empty()) << joinMessages(messages);
}

TEST(GpuSmoke, TimingWithoutValidation)
{
    TempDir cache("smoke-cache");
    SmokeOptions smokeOptions;
    smokeOptions.compiler.cacheDir = cache.getPath();
    ScopedEnv validation("RTLAB_VK_VALIDATION", std::nullopt);
    const SmokeResult r = runSmokeTest({}, smokeOptions);
    ASSERT_TRUE(r.passed) << r.message;
    ASSERT_TRUE(r.gpuMs.has_value());
    std::printf("smoke on %s: gpu %.3f ms (median of %zu), submit wall %.3f ms, compile %.1f ms "
                "(cache %s)\n",
                r.device.name.c_str(), *r.gpuMs, r.gpuMsPerRun.size(), r.cpuMs, r.compileMs,
                r.cacheHit ? "hit" : "miss");
    for (double ms : r.gpuMsPerRun)
        std::printf("  run: %.3f ms\n", ms);
    ::testing::Test::RecordProperty("smoke_gpu_ms", std::to_string(*r.gpuMs));
    EXPECT_GT(*r.gpuMs, 0.0);
}

TEST(GpuSmoke, ReportsNoGpuTimeWithoutTimestamps)
{
    TempDir cache("smoke-cache");
    ContextOptions contextOptions;
    contextOptions.disableTimestamps = true;
    SmokeOptions smokeOptions;
    smokeOptions.compiler.cacheDir = cache.getPath();
    smokeOptions.elementCount = 1000;
    smokeOptions.repetitions = 2;
    const SmokeResult r = runSmokeTest(contextOptions, smokeOptions);
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_EQ(r.elementCount, 1000u);
    EXPECT_FALSE(r.gpuMs.has_value());
    EXPECT_TRUE(r.gpuMsPerRun.empty());
    EXPECT_GT(r.cpuMs, 0.0);
}

} // namespace
} // namespace rtlab::gpu::test
