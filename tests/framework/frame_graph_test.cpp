// The frame graph's culling rules, on small graphs whose answer is known.

#include "core/error.h"
#include "experiment/results.h"
#include "experiment/runner.h"
#include "gpu/bus_counters.h"
#include "pipeline/frame_graph.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace rtlab::pipeline {
namespace {

using scene::FeatureSet;
using scene::SceneFeature;

const PassRecord& find(const std::vector<PassRecord>& records, const std::string& name)
{
    for (const auto& r : records)
        if (r.name == name)
            return r;
    throw Error("no pass " + name);
}

// scene -> geometry -> gbuffer -> ao -> ao_metrics; characters -> geometry (optional);
// gbuffer -> reference -> ao_metrics; reference_bent -> bent_metrics.
struct Fixture {
    FrameGraph graph;
    std::vector<std::string> ran;

    explicit Fixture(bool previousFrame = true)
    {
        graph.addExternal("scene");
        graph.addExternal("previous_frame", previousFrame, "first frame of the run");
        auto pass = [&](PassDesc d) {
            const std::string name = d.name;
            graph.addPass(std::move(d), [this, name] {
                ran.push_back(name);
                return PassOutcome{};
            });
        };
        pass({.name = "character_pose",
              .reads = {"scene"},
              .writes = {"capsules"},
              .needs = {SceneFeature::Characters}});
        pass({.name = "geometry",
              .reads = {"scene"},
              .optionalReads = {"capsules"},
              .writes = {"geometry"}});
        pass({.name = "gbuffer", .reads = {"geometry"}, .writes = {"gbuffer"}});
        pass({.name = "technique", .reads = {"gbuffer"}, .writes = {"ao", "bent"}});
        pass({.name = "reference", .reads = {"geometry", "gbuffer"}, .writes = {"gt_ao"}});
        pass({.name = "reference_bent", .reads = {"geometry", "gbuffer"}, .writes = {"gt_bent"}});
        pass({.name = "ao_metrics", .reads = {"ao", "gt_ao"}, .writes = {"ao_metrics"}});
        pass({.name = "bent_metrics", .reads = {"bent", "gt_bent"}, .writes = {"bent_metrics"}});
        pass(
            {.name = "flicker", .reads = {"ao", "gt_ao", "previous_frame"}, .writes = {"flicker"}});
        pass({.name = "lit",
              .reads = {"gbuffer"},
              .writes = {"lit"},
              .needs = {SceneFeature::PointLights}});
        pass({.name = "lit_metrics", .reads = {"lit"}, .writes = {"lit_metrics"}});
    }
};

FeatureSet makeFeatures(std::initializer_list<SceneFeature> list)
{
    FeatureSet f;
    for (auto x : list)
        f.add(x);
    return f;
}

TEST(FrameGraph, RunsEverythingAScenesWithAllFeaturesAndAllOutputsNeeds)
{
    Fixture f;
    const auto records =
        f.graph.execute(makeFeatures({SceneFeature::Characters, SceneFeature::PointLights}),
                        {"ao_metrics", "bent_metrics", "flicker", "lit_metrics"});
    for (const auto& r : records)
        EXPECT_TRUE(r.ran) << r.name << ": " << r.reason;
    EXPECT_EQ(f.ran.size(), 11u);
    EXPECT_EQ(f.ran.front(), "character_pose") << "passes run in declaration order";
}

TEST(FrameGraph, SkipsPassesWhoseSceneFeatureIsMissingAndTheirReaders)
{
    Fixture f;
    const auto records = f.graph.execute(FeatureSet{}, {"ao_metrics", "lit_metrics"});
    EXPECT_FALSE(find(records, "character_pose").ran);
    EXPECT_EQ(find(records, "character_pose").reason, "the scene has no characters");
    EXPECT_TRUE(find(records, "geometry").ran) << "capsules are an optional input";
    EXPECT_FALSE(find(records, "lit").ran);
    EXPECT_EQ(find(records, "lit").reason, "the scene has no point_lights");
    EXPECT_FALSE(find(records, "lit_metrics").ran);
    EXPECT_EQ(find(records, "lit_metrics").reason,
              "input 'lit' is not produced: pass 'lit' is skipped");
    EXPECT_EQ(std::count(f.ran.begin(), f.ran.end(), "lit"), 0);
}

TEST(FrameGraph, SkipsPassesNobodyReads)
{
    Fixture f;
    const auto records = f.graph.execute(makeFeatures({SceneFeature::Characters}), {"ao_metrics"});
    EXPECT_FALSE(find(records, "reference_bent").ran);
    EXPECT_NE(find(records, "reference_bent").reason.find("no consumer"), std::string::npos)
        << find(records, "reference_bent").reason;
    EXPECT_FALSE(find(records, "bent_metrics").ran);
    EXPECT_TRUE(find(records, "reference").ran);
    EXPECT_TRUE(find(records, "technique").ran);
    EXPECT_EQ(f.ran, (std::vector<std::string>{"character_pose", "geometry", "gbuffer", "technique",
                                               "reference", "ao_metrics"}));
}

TEST(FrameGraph, AReadBackThatOnlyMeasurementsReadCountsAsOne)
{
    // technique -> readback (forReaders) -> metric (measurement), technique -> plain -> metric,
    // and optionally a CPU consumer that makes the frame: the read-back is a measurement in the
    // first graph only; a pass not flagged forReaders is never made one, and neither is a
    // read-back whose output the run asks for.
    for (const bool cpuConsumer : {false, true}) {
        FrameGraph graph;
        graph.addExternal("scene");
        const auto nothing = [] { return PassOutcome{}; };
        graph.addPass({.name = "technique", .reads = {"scene"}, .writes = {"on_gpu"}}, nothing);
        graph.addPass(
            {.name = "readback", .reads = {"on_gpu"}, .writes = {"on_cpu"}, .forReaders = true},
            nothing);
        graph.addPass({.name = "plain", .reads = {"on_gpu"}, .writes = {"derived"}}, nothing);
        graph.addPass({.name = "metric",
                       .reads = {"on_cpu", "derived"},
                       .writes = {"metric"},
                       .measurement = true},
                      nothing);
        std::vector<std::string> outputs = {"metric"};
        if (cpuConsumer) {
            graph.addPass({.name = "consumer", .reads = {"on_cpu"}, .writes = {"frame"}}, nothing);
            outputs.push_back("frame");
        }
        const auto records = graph.execute(FeatureSet{}, outputs);
        EXPECT_TRUE(find(records, "readback").ran);
        EXPECT_EQ(find(records, "readback").measurement, !cpuConsumer) << cpuConsumer;
        EXPECT_FALSE(find(records, "plain").measurement) << "not flagged forReaders";
        EXPECT_FALSE(find(records, "technique").measurement);
        // Asked for by the run: part of the frame.
        const auto asked = graph.execute(FeatureSet{}, {"metric", "on_cpu"});
        EXPECT_FALSE(find(asked, "readback").measurement);
    }
}

TEST(FrameGraph, AnUnavailableExternalSkipsItsReadersWithTheExternalsReason)
{
    Fixture f(/*previousFrame=*/false);
    const auto records = f.graph.execute(FeatureSet{}, {"ao_metrics", "flicker"});
    EXPECT_FALSE(find(records, "flicker").ran);
    EXPECT_EQ(find(records, "flicker").reason,
              "input 'previous_frame' is not available: first frame of the run");
    EXPECT_TRUE(find(records, "ao_metrics").ran);
}

TEST(FrameGraph, AProducerWhoseOnlyReaderIsSkippedNamesThatReader)
{
    FrameGraph graph;
    graph.addExternal("scene");
    graph.addPass({.name = "a", .reads = {"scene"}, .writes = {"x"}}, [] { return PassOutcome{}; });
    graph.addPass({.name = "b", .reads = {"x"}, .writes = {"y"}, .needs = {SceneFeature::Sky}},
                  [] { return PassOutcome{}; });
    const auto records = graph.plan(FeatureSet{}, {"y"});
    EXPECT_FALSE(records[0].ran);
    EXPECT_EQ(records[0].reason, "no consumer: its readers (b) are skipped");
}

TEST(FrameGraph, APassCanReportAtRunTimeThatItsWorkIsDone)
{
    FrameGraph graph;
    graph.addExternal("scene");
    graph.addPass({.name = "upload", .reads = {"scene"}, .writes = {"gpu_scene"}},
                  [] { return PassOutcome::skipped("geometry unchanged"); });
    int drawn = 0;
    graph.addPass({.name = "draw", .reads = {"gpu_scene"}, .writes = {"image"}}, [&] {
        ++drawn;
        return PassOutcome{};
    });
    const auto records = graph.execute(FeatureSet{}, {"image"});
    EXPECT_FALSE(records[0].ran);
    EXPECT_EQ(records[0].reason, "geometry unchanged");
    EXPECT_TRUE(records[1].ran) << "outputs of a pass that found its work done count as available";
    EXPECT_EQ(drawn, 1);
    EXPECT_EQ(formatPassRecords(records), "upload:skipped(geometry unchanged);draw:run");
}

TEST(FrameGraph, RejectsMalformedGraphs)
{
    FrameGraph graph;
    graph.addExternal("scene");
    EXPECT_THROW(graph.addExternal("scene"), Error);
    EXPECT_THROW(graph.addPass({.name = "a", .reads = {"later"}, .writes = {"x"}},
                               [] { return PassOutcome{}; }),
                 Error);
    graph.addPass({.name = "a", .reads = {"scene"}, .writes = {"x"}}, [] { return PassOutcome{}; });
    EXPECT_THROW(graph.addPass({.name = "a", .reads = {"scene"}, .writes = {"y"}},
                               [] { return PassOutcome{}; }),
                 Error);
    EXPECT_THROW(graph.addPass({.name = "b", .reads = {"scene"}, .writes = {"x"}},
                               [] { return PassOutcome{}; }),
                 Error);
    EXPECT_THROW(graph.plan(FeatureSet{}, {"nothing_writes_this"}), Error);
}

// Typed resources: the graph checks types when the graph is built, owns the data, hands it to
// passes, and releases it after its last reader.
TEST(FrameGraph, RejectsAReaderWhoseTypeDiffersFromItsProducersNamingBothPassesAndTypes)
{
    FrameGraph graph;
    const Resource<std::vector<float>> depth{"depth", ResourceType::cpuImage("float", 4, 4)};
    graph.addPass({.name = "raster", .writes = {depth}}, [] { return PassOutcome{}; });
    const Resource<std::vector<float>> asGpu{"depth", ResourceType::gpuImage("r32f", 4, 4)};
    try {
        graph.addPass({.name = "ao", .reads = {asGpu}, .writes = {"ao"}},
                      [] { return PassOutcome{}; });
        FAIL() << "a mismatched type must be refused";
    } catch (const Error& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("pass 'ao' reads 'depth' as gpu_image<r32f> 4x4"), std::string::npos) << m;
        EXPECT_NE(m.find("pass 'raster' writes it as cpu_image<float> 4x4"), std::string::npos)
            << m;
    }
    // Same declared type, other C++ type: also refused.
    const Resource<std::vector<double>> asDouble{"depth", ResourceType::cpuImage("float", 4, 4)};
    EXPECT_THROW(graph.addPass({.name = "ao2", .reads = {asDouble}, .writes = {"ao2"}},
                               [] { return PassOutcome{}; }),
                 Error);
    // A token read only orders passes: it is accepted and gives no access to the data.
    graph.addPass({.name = "order", .reads = {"depth"}, .writes = {"ordered"}},
                  [] { return PassOutcome{}; });
}

TEST(FrameGraph, OwnsTheDataAndReleasesItAfterTheLastReader)
{
    FrameGraph graph;
    const Resource<std::vector<int>> a{"a", ResourceType::table("ints")};
    const Resource<std::vector<int>> b{"b", ResourceType::table("ints")};
    const Resource<int> sum{"sum", ResourceType::value("int")};
    graph.addPass({.name = "make_a", .writes = {a}}, [&](PassContext& ctx) {
        ctx.write(a) = {1, 2, 3};
        return PassOutcome{};
    });
    bool aHeldDuringB = false;
    graph.addPass({.name = "make_b", .reads = {a}, .writes = {b}}, [&](PassContext& ctx) {
        aHeldDuringB = graph.holds("a");
        for (int v : ctx.read(a))
            ctx.write(b).push_back(2 * v);
        return PassOutcome{};
    });
    graph.addPass({.name = "add", .reads = {b}, .writes = {sum}}, [&](PassContext& ctx) {
        EXPECT_FALSE(graph.holds("a")) << "'a' is released once its last reader (make_b) has run";
        int total = 0;
        for (int v : ctx.read(b))
            total += v;
        ctx.write(sum) = total;
        EXPECT_THROW(ctx.read(a), Error) << "a pass reads only what it declares";
        return PassOutcome{};
    });
    int seen = 0;
    graph.addPass({.name = "show", .reads = {sum}, .writes = {"shown"}}, [&](PassContext& ctx) {
        seen = ctx.read(sum);
        return PassOutcome{};
    });
    const auto records = graph.execute(FeatureSet{}, {"shown"});
    EXPECT_TRUE(aHeldDuringB);
    EXPECT_EQ(seen, 12);
    EXPECT_FALSE(graph.holds("b"));
    EXPECT_FALSE(graph.holds("sum"));
    EXPECT_EQ(graph.lastReleased(), (std::vector<std::string>{"a", "b", "sum"}));
}

TEST(FrameGraph, TimesEveryPassThatRunsAndOnlyThose)
{
    FrameGraph graph;
    graph.addExternal("scene");
    int calls = 0;
    graph.addPass({.name = "once", .reads = {"scene"}, .writes = {"x"}},
                  [] { return PassOutcome{}; });
    graph.addPass(
        {.name = "repeated", .reads = {"x"}, .writes = {"y"}, .timing = PassTiming::Repeated}, [&] {
            ++calls;
            return PassOutcome{};
        });
    graph.addPass({.name = "unread", .reads = {"x"}, .writes = {"z"}},
                  [] { return PassOutcome{}; });
    int gpuDrains = 0;
    FrameOptions options;
    options.outputs = {"y"};
    options.timing = {.warmup = 2, .repeats = 3};
    options.collectGpuTimes = [&] {
        ++gpuDrains;
        return metrics::GpuPassTimes{{"draw", 1.5}};
    };
    const auto records = graph.execute(options);
    ASSERT_TRUE(records[0].time.has_value());
    EXPECT_EQ(records[0].time->cpuMs.count, 1);
    EXPECT_EQ(records[0].time->gpuMs.at("draw").median, 1.5);
    ASSERT_TRUE(records[1].time.has_value());
    EXPECT_EQ(calls, 1 + 2 + 3) << "first use, warm-up and repeats";
    EXPECT_EQ(records[1].time->cpuMs.count, 3);
    EXPECT_FALSE(records[2].time.has_value()) << "a skipped pass has no time";
    EXPECT_GE(gpuDrains, 2 * 2);
}

TEST(FrameGraph, RecordsWhatEachPassSendsOverTheBusAndTheRowSumsTheFramesPasses)
{
    // Passes that stand in for GPU work by counting transfers where the gpu module does
    // (gpu/bus_counters.h): each record carries its own, per call for a repeated pass; the row
    // has them per pass and summed over the frame's passes (a measurement's left out), and each
    // pass's host time, its CPU wall time less its waits on the device.
    FrameGraph graph;
    graph.addExternal("scene");
    graph.addPass({.name = "upload", .reads = {"scene"}, .writes = {"x"}}, [] {
        gpu::detail::countUpload(1000);
        gpu::detail::countSubmit();
        gpu::detail::countWait(0.0);
        return PassOutcome{};
    });
    graph.addPass({.name = "repeated", .reads = {"x"}, .writes = {"y"}, .timing = PassTiming::Repeated},
                  [] {
                      gpu::detail::countReadback(64);
                      return PassOutcome{};
                  });
    graph.addPass({.name = "measure", .reads = {"y"}, .writes = {"m"}, .measurement = true}, [] {
        gpu::detail::countReadback(5000);
        return PassOutcome{};
    });
    FrameOptions options;
    options.outputs = {"y", "m"};
    options.timing = {.warmup = 1, .repeats = 2};
    const auto records = graph.execute(options);
    const PassRecord& upload = find(records, "upload");
    EXPECT_EQ(upload.uploadBytes, 1000u);
    EXPECT_EQ(upload.readbackBytes, 0u);
    EXPECT_EQ(upload.submits, 1u);
    EXPECT_EQ(upload.waits, 1u);
    EXPECT_EQ(find(records, "repeated").readbackBytes, 64u) << "per call, of 1 + 1 + 2 calls";
    EXPECT_EQ(find(records, "measure").readbackBytes, 5000u);
    experiment::ResultRow row;
    experiment::writePassRecords(row, records);
    const auto number = [&](const std::string& column) {
        const experiment::Cell* c = row.find(column);
        if (c == nullptr)
            throw Error("no column " + column);
        return std::visit([](const auto& v) -> double {
            if constexpr (std::is_arithmetic_v<std::decay_t<decltype(v)>>)
                return double(v);
            else
                return std::nan("");
        }, *c);
    };
    EXPECT_EQ(number("upload.upload_bytes"), 1000.0);
    EXPECT_EQ(number("upload.submits"), 1.0);
    EXPECT_EQ(number("repeated.readback_bytes"), 64.0);
    EXPECT_EQ(number("measure.readback_bytes"), 5000.0);
    EXPECT_EQ(number("frame.upload_bytes"), 1000.0);
    EXPECT_EQ(number("frame.readback_bytes"), 64.0) << "the measurement is not the frame's";
    EXPECT_EQ(number("frame.submits"), 1.0);
    EXPECT_EQ(number("frame.waits"), 1.0);
    EXPECT_GE(number("upload.host_ms"), 0.0);
    EXPECT_LE(number("upload.host_ms"), number("upload.cpu_ms"));
    EXPECT_LE(number("frame.host_ms"), number("frame.cpu_ms") + 1e-9);
}

// A repeated pass's host time is per call its wall time less its own waits, the median over the
// timed calls: a first use that works on the host without waiting and a timed call that only
// waits (the wait counted as long as the sleep measured) give a host time near 0, not the timed
// call's wall time less the mean wait of all calls (half of it here). The bound, a quarter of the
// pass's time, leaves the clock reads around the sleep their microseconds many times over.
TEST(FrameGraph, AHostTimeIsTheTimedCallsWallLessTheirOwnWaits)
{
    FrameGraph graph;
    graph.addExternal("scene");
    int calls = 0;
    graph.addPass({.name = "waits", .reads = {"scene"}, .writes = {"x"}, .timing = PassTiming::Repeated}, [&] {
        const auto start = std::chrono::steady_clock::now();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        const double slept =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        if (calls++ > 0) // the first use works on the host; the timed call waits on the device
            gpu::detail::countWait(slept);
        return PassOutcome{};
    });
    FrameOptions options;
    options.outputs = {"x"};
    options.timing = {.warmup = 0, .repeats = 1};
    const auto records = graph.execute(options);
    const PassRecord& r = find(records, "waits");
    ASSERT_TRUE(r.time.has_value());
    EXPECT_EQ(calls, 2);
    EXPECT_GE(r.hostMs, 0.0);
    EXPECT_LT(r.hostMs, 0.25 * r.time->cpuMs.median) << "cpu " << r.time->cpuMs.median << " ms";
}

TEST(FrameGraph, ReleasedGpuResourcesServeTheNextWriterOfTheSameType)
{
    // A GPU buffer (here a stand-in whose creation is counted) is allocated once: the next
    // frame's writer gets the released one back from the graph's pool.
    FrameGraph graph;
    int created = 0;
    const Resource<std::vector<float>> buffer{"buffer", ResourceType::gpuBuffer("floats", 64), [&] {
                                                  ++created;
                                                  return std::make_shared<std::vector<float>>(16,
                                                                                              0.0f);
                                              }};
    graph.addPass({.name = "fill", .writes = {buffer}}, [&](PassContext& ctx) {
        ctx.write(buffer).assign(16, float(ctx.frame()));
        return PassOutcome{};
    });
    float seen = -1.0f;
    graph.addPass({.name = "use", .reads = {buffer}, .writes = {"used"}}, [&](PassContext& ctx) {
        seen = ctx.read(buffer)[3];
        return PassOutcome{};
    });
    FrameOptions options;
    options.outputs = {"used"};
    graph.execute(options);
    EXPECT_EQ(graph.lastGpuAllocations(), 1);
    EXPECT_EQ(graph.lastGpuReuses(), 0);
    EXPECT_FALSE(graph.holds("buffer")) << "released after its last reader";
    options.frame = 1;
    graph.execute(options);
    EXPECT_EQ(graph.lastGpuAllocations(), 0);
    EXPECT_EQ(graph.lastGpuReuses(), 1);
    EXPECT_EQ(created, 1);
    EXPECT_EQ(seen, 1.0f) << "the writer overwrites what it reuses";
}

TEST(FrameGraph, KeepsPersistentResourcesAcrossFramesAndReusesWorkUnlessCullingIsOff)
{
    FrameGraph graph;
    const Resource<int> uploaded{"uploaded", ResourceType::value("int")};
    int uploads = 0;
    graph.addPass({.name = "upload",
                   .writes = {uploaded},
                   .persistent = {"uploaded"},
                   .reuse =
                       [&](const PassContext&) {
                           return uploads > 0 ? std::string("unchanged") : std::string();
                       }},
                  [&](PassContext& ctx) {
                      ctx.write(uploaded) = ++uploads;
                      return PassOutcome{};
                  });
    int last = 0;
    graph.addPass({.name = "draw", .reads = {uploaded}, .writes = {"image"}},
                  [&](PassContext& ctx) {
                      last = ctx.read(uploaded);
                      return PassOutcome{};
                  });
    graph.addPass({.name = "extra", .reads = {uploaded}, .writes = {"unused"}},
                  [] { return PassOutcome{}; });
    FrameOptions options;
    options.outputs = {"image"};
    graph.execute(options);
    options.frame = 1;
    const auto second = graph.execute(options);
    EXPECT_EQ(uploads, 1);
    EXPECT_EQ(last, 1) << "the persistent resource survives the frame";
    EXPECT_EQ(formatPassRecords(second), "upload:skipped(unchanged);draw:run;extra:skipped(no "
                                         "consumer: the run reads none of its outputs "
                                         "(unused))");
    options.culling = false;
    const auto all = graph.execute(options);
    EXPECT_EQ(uploads, 2) << "without culling nothing is reused";
    EXPECT_EQ(formatPassRecords(all), "upload:run;draw:run;extra:run");
}

} // namespace
} // namespace rtlab::pipeline
