// Compute shaders on the device with results checked on the CPU: saxpy (mapped and staged
// buffers), push and specialisation constants, defines, transfer commands, chained dispatches,
// and the errors that recording reports.

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/error.h"
#include "gpu/bus_counters.h"
#include "gpu/context.h"
#include "gpu_test_support.h"

namespace rtlab::gpu::test {
namespace {

struct SaxpyParams {
    float a;
    std::uint32_t count;
};

// Deterministic inputs in [-10, 10) that are not small integers, so products round.
float makeInput(std::uint32_t i, std::uint32_t salt)
{
    std::uint32_t v = i * 2654435761u + salt * 40503u;
    v ^= v >> 13;
    return static_cast<float>(v % 200000u) / 10000.0f - 10.0f;
}

// a * x rounded to float, then + y rounded to float: what `precise` requires of the shader.
// Vulkan requires correctly rounded 32-bit OpFMul and OpFAdd, so the results match exactly.
float referenceSaxpy(float a, float x, float y)
{
    const float product = a * x;
    return product + y;
}

class ComputeTest : public GpuTest {
protected:
    ComputePipeline createSaxpy()
    {
        return createTestPipeline(
            "saxpy.comp", {{0, BindingType::StorageBuffer}, {1, BindingType::StorageBuffer}},
            sizeof(SaxpyParams));
    }

    //! With `hostVisible` x and y are BufferDesc::hostVisible buffers: the shader reads and
    //! writes them where the host maps them.
    void runSaxpyAndCheck(bool hostVisible = false)
    {
        constexpr std::uint32_t kCount = 100003; // not a multiple of the group size 64
        constexpr float kA = 1.7f;
        std::vector<float> x(kCount), y(kCount), expected(kCount);
        for (std::uint32_t i = 0; i < kCount; ++i) {
            x[i] = makeInput(i, 1);
            y[i] = makeInput(i, 2);
            expected[i] = referenceSaxpy(kA, x[i], y[i]);
        }
        const ComputePipeline saxpy = createSaxpy();
        Buffer xBuffer = getContext().createBuffer(
            {.size = kCount * sizeof(float), .name = "x", .hostVisible = hostVisible});
        // One float of padding that the shader must not touch.
        Buffer yBuffer = getContext().createBuffer(
            {.size = (kCount + 1) * sizeof(float), .name = "y", .hostVisible = hostVisible});
        EXPECT_EQ(xBuffer.isHostMapped(), hostVisible || !getContext().usesStagingUploads());
        EXPECT_EQ(yBuffer.isHostMapped(), hostVisible || !getContext().usesStagingUploads());
        xBuffer.uploadSpan<float>(x);
        yBuffer.uploadSpan<float>(y);
        const float sentinel = 12345.5f;
        yBuffer.upload(&sentinel, sizeof sentinel, kCount * sizeof(float));

        const SaxpyParams params{kA, kCount};
        const RunResult run = getContext().run([&](CommandList& cmd) {
            cmd.dispatch(saxpy,
                         {Binding::storageBuffer(0, xBuffer), Binding::storageBuffer(1, yBuffer)},
                         PushConstants(params), GroupCount{computeGroupCount(kCount, 64)});
        });
        ASSERT_EQ(run.commands.size(), 1u);
        EXPECT_EQ(run.commands[0].label, "saxpy.comp");

        const std::vector<float> result = yBuffer.downloadVector<float>(kCount);
        std::uint32_t mismatches = 0;
        for (std::uint32_t i = 0; i < kCount; ++i) {
            if (result[i] != expected[i] && ++mismatches <= 5)
                ADD_FAILURE() << "y[" << i << "] = " << result[i] << ", expected " << expected[i];
        }
        EXPECT_EQ(mismatches, 0u);
        float tail = 0.0f;
        yBuffer.download(&tail, sizeof tail, kCount * sizeof(float));
        EXPECT_EQ(tail, sentinel);
        // x is read-only in the shader and must be unchanged.
        EXPECT_EQ(xBuffer.downloadVector<float>(), x);
    }
};

class StagedComputeTest : public ComputeTest {
protected:
    ContextOptions makeContextOptions() const override
    {
        ContextOptions options = ComputeTest::makeContextOptions();
        options.forceStagingUploads = true;
        return options;
    }
};

TEST_F(ComputeTest, SaxpyMatchesTheCpuExactly)
{
    if (getContext().getDeviceInfo().isCpu) {
        EXPECT_FALSE(getContext().usesStagingUploads()); // unified memory: mapped buffers
    }
    runSaxpyAndCheck();
}

TEST_F(StagedComputeTest, SaxpyMatchesTheCpuExactlyThroughStagingBuffers)
{
    EXPECT_TRUE(getContext().usesStagingUploads());
    runSaxpyAndCheck();
}

TEST_F(StagedComputeTest, HostVisibleBuffersSkipTheStagingBuffers)
{
    // Where device memory is not mapped, hostVisible buffers are: the shader reads x from and
    // writes y to host memory, and the transfers are memcpys.
    EXPECT_TRUE(getContext().usesStagingUploads());
    runSaxpyAndCheck(true);
}

TEST_F(ComputeTest, HostVisibleBuffersWorkOnUnifiedMemory)
{
    runSaxpyAndCheck(true);
}

// What crosses the bus is counted where it happens (gpu/bus_counters.h): the bytes of every
// upload and read-back, mapped or staged, of buffers and images alike; one submission and one
// host wait per run, and per staged transfer.
void checkBusCounters(Context& context)
{
    Buffer buffer = context.createBuffer({.size = 4096, .name = "counted"});
    Image image = context.createImage({.format = Format::R32Float, .width = 8, .height = 4, .name = "counted"});
    const std::vector<float> texels(32, 1.5f);
    const std::vector<std::uint8_t> bytes(1000, 7);
    const bool staged = context.usesStagingUploads();
    const BusCounters before = getBusCounters();
    buffer.upload(bytes.data(), bytes.size(), 96);
    image.uploadSpan<float>(texels);
    std::vector<std::uint8_t> back(300);
    buffer.download(back.data(), back.size(), 10);
    EXPECT_EQ(image.downloadVector<float>(), texels);
    const BusCounters transfers = getBusCounters() - before;
    EXPECT_EQ(transfers.uploadBytes, 1000u + 32u * sizeof(float));
    EXPECT_EQ(transfers.readbackBytes, 300u + 32u * sizeof(float));
    // An image always goes through a staging buffer and a submission; a buffer only when its
    // memory is not mapped.
    const std::uint64_t submits = 2 + (staged ? 2 : 0);
    EXPECT_EQ(transfers.submits, submits);
    EXPECT_EQ(transfers.waits, submits);
    EXPECT_GE(transfers.waitMs, 0.0);
    const BusCounters beforeRun = getBusCounters();
    context.run([&](CommandList& cmd) { cmd.fillBuffer(buffer, 0u); });
    const BusCounters run = getBusCounters() - beforeRun;
    EXPECT_EQ(run.submits, 1u);
    EXPECT_EQ(run.waits, 1u);
    EXPECT_EQ(run.uploadBytes, 0u);
    EXPECT_EQ(run.readbackBytes, 0u);
}

TEST_F(ComputeTest, AChangedSpanUploadsOnlyFromTheFirstToTheLastChangedElement)
{
    std::vector<std::uint32_t> held(100);
    for (std::uint32_t i = 0; i < 100; ++i)
        held[i] = i * 7u;
    // Room for 110 elements (a patched buffer has a margin, getPatchCapacity).
    Buffer buffer = getContext().createBuffer({.size = 110 * sizeof(std::uint32_t), .name = "patched"});
    buffer.uploadSpan<std::uint32_t>(held);
    std::vector<std::uint32_t> next = held;
    next[10] = 1;
    next[20] = 2;
    const BusCounters before = getBusCounters();
    EXPECT_EQ(uploadChangedSpan<std::uint32_t>(buffer, held, next), 11 * sizeof(std::uint32_t));
    EXPECT_EQ((getBusCounters() - before).uploadBytes, 11 * sizeof(std::uint32_t));
    EXPECT_EQ(buffer.downloadVector<std::uint32_t>(100), next);
    EXPECT_EQ(uploadChangedSpan<std::uint32_t>(buffer, next, next), 0u) << "nothing changed";
    // A different length (a dig changed a mesh): from the first difference to the new end.
    std::vector<std::uint32_t> longer = next;
    longer.insert(longer.begin() + 90, {5u, 6u, 7u});
    EXPECT_EQ(uploadChangedSpan<std::uint32_t>(buffer, next, longer), 13 * sizeof(std::uint32_t));
    EXPECT_EQ(buffer.downloadVector<std::uint32_t>(103), longer);
    std::vector<std::uint32_t> shorter(longer.begin(), longer.begin() + 95);
    shorter[94] = 9u;
    EXPECT_EQ(uploadChangedSpan<std::uint32_t>(buffer, longer, shorter), 1 * sizeof(std::uint32_t));
    EXPECT_EQ(buffer.downloadVector<std::uint32_t>(95), shorter);
    // More than the buffer holds: a clear error, nothing uploaded.
    EXPECT_THROW(uploadChangedSpan<std::uint32_t>(buffer, shorter, std::vector<std::uint32_t>(111, 0u)),
                 Error);
}

TEST_F(ComputeTest, WhatCrossesTheBusIsCounted)
{
    checkBusCounters(getContext());
}

TEST_F(StagedComputeTest, WhatCrossesTheBusIsCountedThroughStagingBuffers)
{
    checkBusCounters(getContext());
}

TEST_F(StagedComputeTest, KeptStagingBuffersCarryEveryTransferWhateverItsSizeAndOrder)
{
    // The kept staging buffer of each direction grows with the transfers (1 MiB, then powers of
    // two) and a transfer past 64 MiB gets one of its own: interleave sizes on both sides of
    // every step, several buffers at once, and partial ranges, and check every byte.
    const std::vector<std::size_t> sizes = {16,
                                            std::size_t(1) << 20,
                                            (std::size_t(1) << 20) + 4,
                                            3 << 20,
                                            12,
                                            (std::size_t(65) << 20),
                                            8 << 20};
    std::vector<Buffer> buffers;
    std::vector<std::vector<std::uint32_t>> sent;
    for (std::size_t k = 0; k < sizes.size(); ++k) {
        std::vector<std::uint32_t> words(sizes[k] / 4);
        for (std::size_t i = 0; i < words.size(); ++i)
            words[i] = std::uint32_t(i * 2654435761u + k);
        buffers.push_back(getContext().createBuffer({sizes[k], "kept_staging"}));
        buffers.back().uploadSpan<std::uint32_t>(words);
        sent.push_back(std::move(words));
    }
    for (std::size_t k = sizes.size(); k-- > 0;)
        EXPECT_EQ(buffers[k].downloadVector<std::uint32_t>(), sent[k]) << sizes[k] << " bytes";
    // A partial range in the middle of the largest kept-size buffer.
    std::vector<std::uint32_t> patch(1000, 0xdeadbeefu);
    buffers[3].upload(patch.data(), patch.size() * 4, 4096);
    const auto back = buffers[3].downloadVector<std::uint32_t>();
    for (std::size_t i = 0; i < back.size(); ++i)
        ASSERT_EQ(back[i], i >= 1024 && i < 2024 ? 0xdeadbeefu : sent[3][i]) << i;
}

TEST_F(ComputeTest, ChainedDispatchesSeeEachOthersWrites)
{
    constexpr std::uint32_t kCount = 4096;
    std::vector<float> x(kCount), y(kCount), expected(kCount);
    const float a1 = 0.3f, a2 = -2.25f;
    for (std::uint32_t i = 0; i < kCount; ++i) {
        x[i] = makeInput(i, 3);
        y[i] = makeInput(i, 4);
        expected[i] = referenceSaxpy(a2, x[i], referenceSaxpy(a1, x[i], y[i]));
    }
    const ComputePipeline saxpy = createSaxpy();
    Buffer xBuffer = getContext().createBuffer({kCount * sizeof(float), "x"});
    Buffer yBuffer = getContext().createBuffer({kCount * sizeof(float), "y"});
    Buffer copy = getContext().createBuffer({kCount * sizeof(float), "copy"});
    xBuffer.uploadSpan<float>(x);
    yBuffer.uploadSpan<float>(y);
    const std::vector<Binding> bindings = {Binding::storageBuffer(0, xBuffer),
                                           Binding::storageBuffer(1, yBuffer)};
    const RunResult run = getContext().run([&](CommandList& cmd) {
        cmd.dispatch(saxpy, bindings, PushConstants(SaxpyParams{a1, kCount}),
                     GroupCount{kCount / 64}, "first");
        cmd.dispatch(saxpy, bindings, PushConstants(SaxpyParams{a2, kCount}),
                     GroupCount{kCount / 64}, "second");
        cmd.copyBuffer(yBuffer, copy, "copy");
    });
    ASSERT_EQ(run.commands.size(), 3u);
    EXPECT_EQ(run.commands[0].label, "first");
    EXPECT_EQ(run.commands[1].label, "second");
    EXPECT_EQ(run.commands[2].label, "copy");
    EXPECT_EQ(yBuffer.downloadVector<float>(), expected);
    EXPECT_EQ(copy.downloadVector<float>(), expected);
}

TEST_F(ComputeTest, PushAndSpecialisationConstantsTakeEffect)
{
    struct Params {
        std::uint32_t base;
        std::uint32_t count;
        float scale;
    };
    struct Variant {
        std::uint32_t groupSize;
        std::uint32_t multiplier;
        float offset;
        bool negate;
        Params params;
    };
    // Small integers times 0.5 or 0.25 plus a quarter: every value is exact in float.
    const Variant variants[] = {
        {32, 3, 0.25f, false, {10, 1000, 0.5f}},
        {128, 5, -0.75f, true, {7, 777, 0.25f}},
    };
    for (const Variant& v : variants) {
        SCOPED_TRACE("group size " + std::to_string(v.groupSize));
        const ComputePipeline pipeline = createTestPipeline(
            "spec_push.comp", {{0, BindingType::StorageBuffer}, {1, BindingType::StorageBuffer}},
            sizeof(Params),
            {SpecConstant::makeUint(0, v.groupSize), SpecConstant::makeUint(1, v.multiplier),
             SpecConstant::makeFloat(2, v.offset), SpecConstant::makeBool(3, v.negate)});
        Buffer values = getContext().createBuffer({1024 * sizeof(float), "values"});
        Buffer info = getContext().createBuffer({2 * sizeof(std::uint32_t), "info"});
        const std::uint32_t groups = computeGroupCount(v.params.count, v.groupSize);
        getContext().run([&](CommandList& cmd) {
            cmd.fillBuffer(values, 0u);
            cmd.dispatch(pipeline,
                         {Binding::storageBuffer(0, values), Binding::storageBuffer(1, info)},
                         PushConstants(v.params), GroupCount{groups});
        });
        const std::vector<std::uint32_t> reported = info.downloadVector<std::uint32_t>();
        EXPECT_EQ(reported[0], v.groupSize);
        EXPECT_EQ(reported[1], groups);
        const std::vector<float> got = values.downloadVector<float>();
        for (std::uint32_t i = 0; i < 1024; ++i) {
            float expected = 0.0f; // from fillBuffer, beyond count
            if (i < v.params.count) {
                expected = static_cast<float>((v.params.base + i) * v.multiplier) * v.params.scale +
                           v.offset;
                if (v.negate)
                    expected = -expected;
            }
            ASSERT_EQ(got[i], expected) << "at " << i;
        }
    }
}

TEST_F(ComputeTest, DefinesReachTheShader)
{
    Buffer out = getContext().createBuffer({2 * sizeof(std::uint32_t), "out"});
    const auto runWith = [&](const std::vector<ShaderDefine>& defines) {
        const CompiledShader shader = compileTestShader("define_value.comp", defines);
        ComputePipelineDesc desc;
        desc.name = "define_value";
        desc.spirv = shader.spirv;
        desc.bindings = {{0, BindingType::StorageBuffer}};
        const ComputePipeline pipeline = getContext().createPipeline(desc);
        getContext().run([&](CommandList& cmd) {
            cmd.dispatch(pipeline, {Binding::storageBuffer(0, out)}, GroupCount{});
        });
        return std::make_pair(shader.cacheHit, out.downloadVector<std::uint32_t>());
    };
    const auto [hit3, three] = runWith({{"VALUE", "3u"}});
    EXPECT_FALSE(hit3);
    EXPECT_EQ(three, (std::vector<std::uint32_t>{3, 0}));
    const auto [hit7, seven] = runWith({{"VALUE", "7u"}, {"FLAG", ""}});
    EXPECT_FALSE(hit7);
    EXPECT_EQ(seven, (std::vector<std::uint32_t>{7, 1}));
    const auto [hitAgain, again] = runWith({{"VALUE", "3u"}});
    EXPECT_TRUE(hitAgain);
    EXPECT_EQ(again, (std::vector<std::uint32_t>{3, 0}));
}

TEST_F(ComputeTest, FillAndCopyBuffers)
{
    Buffer a = getContext().createBuffer({1000 * sizeof(std::uint32_t), "a"});
    Buffer b = getContext().createBuffer({600 * sizeof(std::uint32_t), "b"});
    b.uploadSpan<std::uint32_t>(std::vector<std::uint32_t>(600, 1u));
    getContext().run([&](CommandList& cmd) {
        cmd.fillBuffer(a, 0xdeadbeefu);
        cmd.copyBuffer(a, b); // copies min(size) = 600 words
    });
    EXPECT_EQ(a.downloadVector<std::uint32_t>(), std::vector<std::uint32_t>(1000, 0xdeadbeefu));
    EXPECT_EQ(b.downloadVector<std::uint32_t>(), std::vector<std::uint32_t>(600, 0xdeadbeefu));
}

// A count the device computes drives a dispatch without a read-back: the group count is written
// by one dispatch and read by the next (vkCmdDispatchIndirect) in the same submission.
TEST_F(ComputeTest, DispatchesAGroupCountTheDeviceWrote)
{
    struct Push {
        std::uint32_t mode;
    };
    const ComputePipeline pipeline = createTestPipeline(
        "indirect.comp", {{0, BindingType::StorageBuffer}, {1, BindingType::StorageBuffer}}, sizeof(Push));
    Buffer args = getContext().createBuffer({4 * sizeof(std::uint32_t), "args"});
    Buffer marks = getContext().createBuffer({1024 * sizeof(std::uint32_t), "marks"});
    args.uploadSpan<std::uint32_t>(std::vector<std::uint32_t>{0, 0, 0, 130}); // 130 items: 3 groups
    const Push write{0}, mark{1};
    getContext().run([&](CommandList& cmd) {
        cmd.fillBuffer(marks, 0u);
        cmd.dispatch(pipeline, {Binding::storageBuffer(0, args), Binding::storageBuffer(1, marks)},
                     PushConstants(write), GroupCount{1});
        cmd.dispatchIndirect(pipeline, {Binding::storageBuffer(0, args), Binding::storageBuffer(1, marks)},
                             PushConstants(mark), args, 0);
    });
    const std::vector<std::uint32_t> got = marks.downloadVector<std::uint32_t>();
    for (std::uint32_t i = 0; i < 1024; ++i)
        ASSERT_EQ(got[i], i < 192 ? 1u : 0u) << "at " << i;
    // Arguments outside the buffer are refused when recorded.
    getContext().run([&](CommandList& cmd) {
        EXPECT_THROW(cmd.dispatchIndirect(pipeline, {Binding::storageBuffer(0, args), Binding::storageBuffer(1, marks)},
                                          PushConstants(mark), args, 8),
                     Error);
    });
}

TEST_F(ComputeTest, FillsARangeOfABuffer)
{
    Buffer a = getContext().createBuffer({100 * sizeof(std::uint32_t), "a"});
    a.uploadSpan<std::uint32_t>(std::vector<std::uint32_t>(100, 1u));
    getContext().run([&](CommandList& cmd) { cmd.fillBuffer(a, 7u, 40 * 4, 20 * 4); });
    std::vector<std::uint32_t> expected(100, 1u);
    std::fill(expected.begin() + 40, expected.begin() + 60, 7u);
    EXPECT_EQ(a.downloadVector<std::uint32_t>(), expected);
    // Not whole words, or past the end: refused when recorded.
    getContext().run([&](CommandList& cmd) {
        EXPECT_THROW(cmd.fillBuffer(a, 0u, 2, 8), Error);
        EXPECT_THROW(cmd.fillBuffer(a, 0u, 96 * 4, 8 * 4), Error);
    });
}

TEST_F(ComputeTest, PartialUploadsAndDownloadsRespectOffsets)
{
    Buffer buffer = getContext().createBuffer({64, "partial"});
    std::vector<std::uint8_t> bytes(64);
    for (int i = 0; i < 64; ++i)
        bytes[i] = static_cast<std::uint8_t>(i);
    buffer.uploadSpan<std::uint8_t>(bytes);
    const std::uint8_t patch[3] = {200, 201, 202};
    buffer.upload(patch, 3, 61);
    bytes[61] = 200;
    bytes[62] = 201;
    bytes[63] = 202;
    EXPECT_EQ(buffer.downloadVector<std::uint8_t>(), bytes);
    EXPECT_EQ(buffer.downloadVector<std::uint8_t>(4, 60),
              (std::vector<std::uint8_t>{60, 200, 201, 202}));
    EXPECT_THROW(buffer.upload(patch, 3, 62), Error);
    std::uint8_t sink[8];
    EXPECT_THROW(buffer.download(sink, 8, 60), Error);
    EXPECT_THROW(getContext().createBuffer({0, "empty"}), Error);
}

TEST_F(ComputeTest, RecordingRejectsMismatchedBindingsAndPushConstants)
{
    const ComputePipeline saxpy = createSaxpy();
    Buffer x = getContext().createBuffer({256, "x"});
    Buffer y = getContext().createBuffer({256, "y"});
    Image image = getContext().createImage({ImageDimension::Image2D, Format::R32Float, 4, 4});
    const SaxpyParams params{1.0f, 64};
    auto expectError = [&](const std::function<void(CommandList&)>& record, const char* text) {
        try {
            getContext().run(record);
            ADD_FAILURE() << "expected rtlab::Error containing '" << text << "'";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
        }
    };
    expectError(
        [&](CommandList& cmd) {
            cmd.dispatch(saxpy, {Binding::storageBuffer(0, x)}, PushConstants(params),
                         GroupCount{1});
        },
        "binding 1 (storage buffer) is not bound");
    expectError(
        [&](CommandList& cmd) {
            cmd.dispatch(saxpy, {Binding::storageBuffer(0, x), Binding::storageImage(1, image)},
                         PushConstants(params), GroupCount{1});
        },
        "binding 1 expects a storage buffer, got a storage image");
    expectError(
        [&](CommandList& cmd) {
            cmd.dispatch(saxpy,
                         {Binding::storageBuffer(0, x), Binding::storageBuffer(1, y),
                          Binding::storageBuffer(2, y)},
                         PushConstants(params), GroupCount{1});
        },
        "binding 2 is not part of the pipeline layout");
    expectError(
        [&](CommandList& cmd) {
            cmd.dispatch(saxpy, {Binding::storageBuffer(0, x), Binding::storageBuffer(1, y)},
                         GroupCount{1});
        },
        "0 bytes of push constants given, the pipeline declares 8");
    // After failed recordings the context still works.
    const RunResult ok = getContext().run([&](CommandList& cmd) {
        cmd.dispatch(saxpy, {Binding::storageBuffer(0, x), Binding::storageBuffer(1, y)},
                     PushConstants(params), GroupCount{1});
    });
    EXPECT_EQ(ok.commands.size(), 1u);
}

TEST_F(ComputeTest, PipelineDescriptionsAreChecked)
{
    ComputePipelineDesc desc;
    desc.name = "bad";
    desc.spirv = {1, 2, 3};
    EXPECT_THROW(getContext().createPipeline(desc), Error);
    desc.spirv = compileTestShader("saxpy.comp").spirv;
    desc.bindings = {{0, BindingType::StorageBuffer}, {0, BindingType::StorageBuffer}};
    EXPECT_THROW(getContext().createPipeline(desc), Error);
    desc.bindings = {{0, BindingType::StorageBuffer}, {1, BindingType::StorageBuffer}};
    desc.pushConstantSize = 6;
    EXPECT_THROW(getContext().createPipeline(desc), Error);
}

} // namespace
} // namespace rtlab::gpu::test
