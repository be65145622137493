#pragma once
// The frame graph: a frame is a list of passes, each declaring the resources it reads and writes
// and the scene features it needs. Before a frame runs the graph is culled (ARCHITECTURE.md,
// "skip what a scene doesn't need"; the rule of the UE4 VR talk in
// shared/seeds/001_5c6096db92814698.txt: "the fastest code is that which does not run"):
//   1. a pass whose required feature the scene lacks is skipped;
//   2. a pass that reads a resource no available producer makes is skipped (and so on downstream);
//   3. a pass none of whose outputs is read by a pass that runs, or requested by the run, is
//      skipped (walking backwards from the requested outputs).
// The rest run in declaration order. A pass may still find at run time that its work is already
// done (a cache hit, unchanged geometry) and report itself skipped with that reason; its outputs
// then count as available. Every pass ends with a record: ran, or skipped and why.
//
//   FrameGraph graph;
//   graph.addExternal("scene");
//   graph.addExternal("previous_frame", frame > 0, "first frame of the run");
//   graph.addPass({.name = "gbuffer", .reads = {"scene"}, .writes = {"gbuffer"}}, [&] { ...; return
//   PassOutcome{}; }); graph.addPass({.name = "character_pose", .writes = {"characters"}, .needs =
//   {SceneFeature::Characters}}, ...); const auto records = graph.execute(scene.computeFeatures(),
//   {"ao_metrics", "images"});

#include "scene/scene.h"

#include <functional>
#include <string>
#include <vector>

namespace rtlab::pipeline {

//! What a pass reports after its callback: ran (the default), or found its work already done.
struct PassOutcome {
    bool ran = true;
    std::string reason; //!< why it did nothing, when !ran

    static PassOutcome skipped(std::string why) { return {false, std::move(why)}; }
};

struct PassDesc {
    std::string name;                       //!< unique in the graph, snake_case
    std::vector<std::string> reads;         //!< required inputs
    std::vector<std::string> optionalReads; //!< used when available, never a reason to skip
    std::vector<std::string> writes;        //!< each resource has exactly one producer
    std::vector<scene::SceneFeature> needs; //!< every one must be in the frame's features
};

//! How a pass ended in one frame.
struct PassRecord {
    std::string name;
    bool ran = false;
    std::string reason; //!< why it was skipped; empty when it ran
};

class FrameGraph {
public:
    //! A resource that exists before the first pass (the scene, the camera, ...). One that is not
    //! available this frame makes its readers skip with `reason`.
    void addExternal(const std::string& resource, bool available = true, std::string reason = "");
    //! Declares a pass. Passes run in declaration order, so every resource a pass reads must be
    //! an external or written by an earlier pass; throws rtlab::Error otherwise, for a duplicate
    //! name, or for a resource with two producers.
    void addPass(PassDesc desc, std::function<PassOutcome()> run);

    //! Decides which passes run for `features` and the requested `outputs` (resource names the
    //! run keeps: metrics, images), without running anything. Throws for an unknown output.
    std::vector<PassRecord> plan(const scene::FeatureSet& features,
                                 const std::vector<std::string>& outputs) const;
    //! plan(), then runs the passes that survive in order. Exceptions from a pass propagate.
    std::vector<PassRecord> execute(const scene::FeatureSet& features,
                                    const std::vector<std::string>& outputs);

    const std::vector<PassDesc>& passes() const { return mPasses; }

private:
    struct External {
        std::string name;
        bool available = true;
        std::string reason;
    };
    const External* findExternal(const std::string& resource) const;
    int findProducer(const std::string& resource) const; //!< pass index, -1 when none

    std::vector<External> mExternals;
    std::vector<PassDesc> mPasses;
    std::vector<std::function<PassOutcome()>> mCallbacks;
};

//! "gbuffer:run;reference:skipped(read from the cache)" (the results table's `passes` column).
std::string formatPassRecords(const std::vector<PassRecord>& records);

} // namespace rtlab::pipeline
