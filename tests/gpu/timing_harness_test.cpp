// The timing harness (metrics/timing.h) around real GPU work: shader compilation is reported as
// setup and excluded, the first use is reported on its own, and the statistics hold CPU wall time
// and per-pass GPU timestamps side by side.

#include <chrono>
#include <cmath>
#include <vector>

#include "gpu/context.h"
#include "gpu_test_support.h"
#include "metrics/timing.h"

namespace rtlab::gpu::test {
namespace {

struct SaxpyParams {
    float a;
    std::uint32_t count;
};

// Per-label GPU time of everything the context ran since the last call, in the harness's form:
// the harness reads the context's log, the work itself reports nothing.
metrics::GpuPassTimes collectPassTimes(Context& context)
{
    metrics::GpuPassTimes times;
    for (const auto& c : context.takeRunLog())
        if (c.gpuMs)
            times[c.label] += *c.gpuMs;
    return times;
}

class TimingHarnessTest : public GpuTest {};

TEST_F(TimingHarnessTest, SeparatesCompilationFirstUseAndRepeats)
{
    constexpr std::uint32_t kCount = 1u << 18;
    Buffer x = getContext().createBuffer({kCount * sizeof(float), "x"});
    Buffer y = getContext().createBuffer({kCount * sizeof(float), "y"});
    x.uploadSpan<float>(std::vector<float>(kCount, 1.0f));
    y.uploadSpan<float>(std::vector<float>(kCount, 0.0f));
    std::optional<ComputePipeline> saxpy;
    int submissions = 0;

    const metrics::TimingReport report = metrics::measure(
        {.warmup = 1, .repeats = 7},
        [&] {
            ++submissions;
            const SaxpyParams params{2.0f, kCount};
            getContext().run([&](CommandList& cmd) {
                cmd.dispatch(*saxpy, {Binding::storageBuffer(0, x), Binding::storageBuffer(1, y)},
                             PushConstants(params), GroupCount{computeGroupCount(kCount, 64)}, "saxpy");
                cmd.dispatch(*saxpy, {Binding::storageBuffer(0, x), Binding::storageBuffer(1, y)},
                             PushConstants(params), GroupCount{computeGroupCount(kCount, 64)}, "saxpy_again");
            });
            return collectPassTimes(getContext());
        },
        // Setup: compiling the shader and creating the pipeline, timed apart from the work.
        [&] {
            saxpy = createTestPipeline("saxpy.comp",
                                       {{0, BindingType::StorageBuffer}, {1, BindingType::StorageBuffer}},
                                       sizeof(SaxpyParams));
        });

    EXPECT_EQ(submissions, 1 + 1 + 7);
    EXPECT_GT(report.setupMs, 0.0);
    EXPECT_GT(report.firstUseMs, 0.0);
    EXPECT_EQ(report.cpuMs.count, 7);
    ASSERT_TRUE(getContext().hasGpuTimestamps());
    ASSERT_EQ(report.gpuMs.size(), 2u);  // one entry per labelled pass
    for (const auto& [pass, stats] : report.gpuMs) {
        EXPECT_EQ(stats.count, 7) << pass;
        EXPECT_TRUE(std::isfinite(stats.median) && stats.median > 0.0) << pass;
        EXPECT_LE(stats.q1, stats.median) << pass;
        EXPECT_LE(stats.median, stats.q3) << pass;
    }
    // Two passes run inside one submission: their GPU medians cannot exceed its wall time by
    // more than the spread of the repeats.
    EXPECT_LE(report.gpuTotalMedianMs(), report.cpuMs.max) << "GPU time must fit in the CPU wall time";
    // 9 submissions of y += 2 * x twice, on x = 1.
    EXPECT_EQ(y.downloadVector<float>(1)[0], 36.0f);
    EXPECT_TRUE(getContext().takeRunLog().empty());  // the log was emptied by every read
}

TEST_F(TimingHarnessTest, RunLogRecordsEachSubmissionsWallTime)
{
    Buffer b = getContext().createBuffer({1024, "b"});
    getContext().takeRunLog();
    const RunResult first = getContext().run([&](CommandList& cmd) {
        cmd.fillBuffer(b, 1u, "a");
        cmd.fillBuffer(b, 2u, "b");
    });
    getContext().run([&](CommandList& cmd) { cmd.fillBuffer(b, 3u, "c"); });
    const auto log = getContext().takeRunLog();
    ASSERT_EQ(log.size(), 3u);
    EXPECT_EQ(log[0].runIndex, log[1].runIndex);  // one submission
    EXPECT_EQ(log[2].runIndex, log[0].runIndex + 1);
    EXPECT_EQ(log[0].runSubmitMs, first.cpuSubmitMs);
    EXPECT_EQ(log[1].runSubmitMs, first.cpuSubmitMs);
    EXPECT_GT(log[2].runSubmitMs, 0.0);
}

} // namespace
} // namespace rtlab::gpu::test
