// The frame graph's culling rules, on small graphs whose answer is known.

#include "core/error.h"
#include "pipeline/frame_graph.h"

#include <algorithm>

#include <gtest/gtest.h>

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

} // namespace
} // namespace rtlab::pipeline
