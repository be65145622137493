// Timestamp queries: per-command GPU times, the submission's CPU wall time, label sums, and
// the tick arithmetic (valid bits, wrap-around, period).

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "gpu/context.h"
#include "gpu/timestamps.h"
#include "gpu_test_support.h"

namespace rtlab::gpu::test {
namespace {

struct BusyParams {
    std::uint32_t count;
    std::uint32_t iterations;
};

std::uint32_t mixBits(std::uint32_t v)
{
    v ^= v >> 16;
    v *= 0x7feb352du;
    v ^= v >> 15;
    v *= 0x846ca68bu;
    v ^= v >> 16;
    return v;
}

std::uint32_t referenceBusy(std::uint32_t v, std::uint32_t iterations)
{
    for (std::uint32_t k = 0; k < iterations; ++k)
        v = mixBits(v + k);
    return v;
}

class TimingTest : public GpuTest {
protected:
    ComputePipeline createBusy()
    {
        return createTestPipeline("busy.comp", {{0, BindingType::StorageBuffer}},
                                  sizeof(BusyParams));
    }
};

TEST_F(TimingTest, EveryCommandGetsAPositiveFiniteGpuTime)
{
    constexpr std::uint32_t kCount = 1 << 16;
    const ComputePipeline busy = createBusy();
    Buffer data = getContext().createBuffer({kCount * sizeof(std::uint32_t), "data"});
    std::vector<std::uint32_t> values(kCount);
    for (std::uint32_t i = 0; i < kCount; ++i)
        values[i] = i;
    data.uploadSpan<std::uint32_t>(values);

    // The first dispatch of a pipeline can include one-off driver work (lavapipe finishes
    // compiling then), so a timing harness discards warm-up runs; so does this test.
    getContext().run([&](CommandList& cmd) {
        cmd.dispatch(busy, {Binding::storageBuffer(0, data)}, PushConstants(BusyParams{kCount, 1}),
                     GroupCount{kCount / 64}, "warm-up");
    });
    data.uploadSpan<std::uint32_t>(values);

    const std::uint32_t iterations[] = {64, 256, 16};
    const RunResult run = getContext().run([&](CommandList& cmd) {
        cmd.dispatch(busy, {Binding::storageBuffer(0, data)}, PushConstants(BusyParams{kCount, 64}),
                     GroupCount{kCount / 64}, "light");
        cmd.dispatch(busy, {Binding::storageBuffer(0, data)},
                     PushConstants(BusyParams{kCount, 256}), GroupCount{kCount / 64}, "heavy");
        cmd.dispatch(busy, {Binding::storageBuffer(0, data)}, PushConstants(BusyParams{kCount, 16}),
                     GroupCount{kCount / 64}, "light");
        cmd.fillBuffer(data, 0u, "clear");
    });
    ASSERT_EQ(run.commands.size(), 4u);
    const char* labels[] = {"light", "heavy", "light", "clear"};
    double sum = 0.0;
    for (std::size_t i = 0; i < 4; ++i) {
        EXPECT_EQ(run.commands[i].label, labels[i]);
        ASSERT_TRUE(run.commands[i].gpuMs.has_value()) << labels[i];
        const double ms = *run.commands[i].gpuMs;
        EXPECT_TRUE(std::isfinite(ms));
        EXPECT_GT(ms, 0.0) << labels[i];
        sum += ms;
    }
    // The commands run one after another, so their intervals do not overlap.
    ASSERT_TRUE(run.gpuTotalMs.has_value());
    EXPECT_GE(*run.gpuTotalMs, sum * (1 - 1e-9));
    // No comparison of the heavy and light dispatches' times: on a loaded machine any ratio can
    // fail, and tests check what was computed, not how fast (the benchmarks measure cost).
    // GPU time fits inside the wall time of the submission (units check: ms vs us vs ns).
    EXPECT_TRUE(std::isfinite(run.cpuSubmitMs));
    EXPECT_GT(run.cpuSubmitMs, 0.0);
    EXPECT_LE(*run.gpuTotalMs, run.cpuSubmitMs * 1.01 + 0.05);
    EXPECT_GE(run.cpuRecordMs, 0.0);

    const std::optional<double> light = run.sumGpuMs("light");
    ASSERT_TRUE(light.has_value());
    EXPECT_DOUBLE_EQ(*light, *run.commands[0].gpuMs + *run.commands[2].gpuMs);
    EXPECT_FALSE(run.sumGpuMs("no-such-label").has_value());

    // The work really ran (the clear came last, so check a separate run's result).
    data.uploadSpan<std::uint32_t>(values);
    getContext().run([&](CommandList& cmd) {
        cmd.dispatch(busy, {Binding::storageBuffer(0, data)},
                     PushConstants(BusyParams{kCount, iterations[0]}), GroupCount{kCount / 64});
    });
    const std::vector<std::uint32_t> got = data.downloadVector<std::uint32_t>();
    for (std::uint32_t i = 0; i < kCount; i += 997)
        ASSERT_EQ(got[i], referenceBusy(i, iterations[0])) << "at " << i;
}

TEST_F(TimingTest, GpuTimeTracksTheAmountOfWork)
{
    // Long enough (tens of ms on a CPU device) that submission overhead is small: the GPU time
    // then accounts for most of the wall time, which a unit error (us or ns taken as ms) breaks.
    constexpr std::uint32_t kCount = 1 << 16;
    const ComputePipeline busy = createBusy();
    Buffer data = getContext().createBuffer({kCount * sizeof(std::uint32_t), "data"});
    data.uploadSpan<std::uint32_t>(std::vector<std::uint32_t>(kCount, 1u));
    const RunResult run = getContext().run([&](CommandList& cmd) {
        cmd.dispatch(busy, {Binding::storageBuffer(0, data)},
                     PushConstants(BusyParams{kCount, 2048}), GroupCount{kCount / 64}, "busy");
    });
    ASSERT_TRUE(run.gpuTotalMs.has_value());
    std::printf("busy: gpu %.3f ms, submit wall %.3f ms\n", *run.gpuTotalMs, run.cpuSubmitMs);
    EXPECT_LE(*run.gpuTotalMs, run.cpuSubmitMs * 1.01 + 0.05);
    if (run.cpuSubmitMs > 5.0) {
        EXPECT_GE(*run.gpuTotalMs, 0.5 * run.cpuSubmitMs);
    }
}

TEST_F(TimingTest, RepeatedRunsReuseAndGrowPools)
{
    constexpr std::uint32_t kCount = 256;
    const ComputePipeline busy = createBusy();
    Buffer data = getContext().createBuffer({kCount * sizeof(std::uint32_t), "data"});
    std::vector<std::uint32_t> values(kCount, 5u);
    for (int frame = 0; frame < 3; ++frame) {
        // 40 dispatches in one run: more than the initial descriptor and query pool sizes.
        data.uploadSpan<std::uint32_t>(values);
        const RunResult run = getContext().run([&](CommandList& cmd) {
            for (int k = 0; k < 40; ++k)
                cmd.dispatch(busy, {Binding::storageBuffer(0, data)},
                             PushConstants(BusyParams{kCount, 1}), GroupCount{kCount / 64}, "step");
        });
        ASSERT_EQ(run.commands.size(), 40u);
        for (const CommandTime& c : run.commands) {
            ASSERT_TRUE(c.gpuMs.has_value());
            EXPECT_GT(*c.gpuMs, 0.0);
        }
        // Each dispatch applies one round to every element; all 40 must have run in order.
        std::uint32_t expected = 5u;
        for (int k = 0; k < 40; ++k)
            expected = referenceBusy(expected, 1);
        EXPECT_EQ(data.downloadVector<std::uint32_t>(),
                  std::vector<std::uint32_t>(kCount, expected));
    }
    const RunResult empty = getContext().run([](CommandList&) {});
    EXPECT_TRUE(empty.commands.empty());
    EXPECT_FALSE(empty.gpuTotalMs.has_value());
}

class NoTimestampTest : public TimingTest {
protected:
    ContextOptions makeContextOptions() const override
    {
        ContextOptions options = TimingTest::makeContextOptions();
        options.disableTimestamps = true;
        return options;
    }
};

TEST_F(NoTimestampTest, GpuTimesAreUnavailableNotZero)
{
    EXPECT_FALSE(getContext().hasGpuTimestamps());
    EXPECT_TRUE(getContext().getDeviceInfo().timestampsSupported); // the device still has them
    constexpr std::uint32_t kCount = 1024;
    const ComputePipeline busy = createBusy();
    Buffer data = getContext().createBuffer({kCount * sizeof(std::uint32_t), "data"});
    data.uploadSpan<std::uint32_t>(std::vector<std::uint32_t>(kCount, 9u));
    const RunResult run = getContext().run([&](CommandList& cmd) {
        for (int k = 0; k < 2; ++k)
            cmd.dispatch(busy, {Binding::storageBuffer(0, data)},
                         PushConstants(BusyParams{kCount, 3}), GroupCount{kCount / 64}, "busy");
    });
    ASSERT_EQ(run.commands.size(), 2u);
    for (const CommandTime& c : run.commands) {
        EXPECT_EQ(c.label, "busy");
        EXPECT_FALSE(c.gpuMs.has_value());
    }
    EXPECT_FALSE(run.gpuTotalMs.has_value());
    EXPECT_FALSE(run.sumGpuMs("busy").has_value());
    EXPECT_GT(run.cpuSubmitMs, 0.0); // the CPU wall time is still measured
    EXPECT_EQ(data.downloadVector<std::uint32_t>(),
              std::vector<std::uint32_t>(kCount, referenceBusy(referenceBusy(9u, 3), 3)));
}

TEST(TimestampArithmetic, ConvertsTicksWithThePeriod)
{
    EXPECT_DOUBLE_EQ(*convertTicksToMs(1000, 3000, 64, 1.0), 0.002);
    EXPECT_DOUBLE_EQ(*convertTicksToMs(0, 12'000'000, 64, 83.333), 12'000'000 * 83.333e-6);
    EXPECT_DOUBLE_EQ(*convertTicksToMs(5, 5, 64, 1.0), 0.0);
}

TEST(TimestampArithmetic, UsesOnlyTheValidBitsAndHandlesWrapAround)
{
    constexpr std::uint64_t kTop36 = 1ull << 36;
    // Counter wrapped from 2^36 - 10 to 5: 15 ticks.
    EXPECT_DOUBLE_EQ(*convertTicksToMs(kTop36 - 10, 5, 36, 1e6), 15.0);
    // Garbage above the valid bits is ignored.
    EXPECT_DOUBLE_EQ(*convertTicksToMs(0xABCDull << 40 | 100, 0x1234ull << 40 | 300, 36, 1e6),
                     200.0);
    // Full 64-bit counters wrap too.
    EXPECT_DOUBLE_EQ(*convertTicksToMs(~0ull - 1, 3, 64, 1e6), 5.0);
}

TEST(TimestampArithmetic, NoTimestampsMeansNoValueNotZero)
{
    EXPECT_FALSE(convertTicksToMs(0, 100, 0, 1.0).has_value());
    EXPECT_FALSE(convertTicksToMs(0, 100, 64, 0.0).has_value());
    EXPECT_FALSE(
        convertTicksToMs(0, 100, 64, std::numeric_limits<double>::quiet_NaN()).has_value());
}

} // namespace
} // namespace rtlab::gpu::test
