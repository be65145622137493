#pragma once
// A family's runtime: what it adds to the frame graph of a run. Families are plugins like
// techniques: one folder framework/families/<name>/ holds the technique interface, the family's
// passes and metrics, and its report columns (plugin::FamilyReport); the folder's main .cpp ends
// with RTLAB_REGISTER_FAMILY(<name>, <function returning its plugin::FamilyInfo>). CMake discovers
// the folder and generates the registration, so the runner, loader, report and CLI name no family.
//
// A run builds one frame graph (pipeline/frame_graph.h) from:
//   - for screen families: the shared frame start (pipeline/frame_start.h: edits, characters,
//     geometry, upload, G-buffer, read-back, view inputs), built once and shared by every screen
//     family of the run;
//   - each of the run's families' passes (Family::beginRun), one technique per family;
// and executes it once per frame; the graph times every pass and the runner writes one row per
// frame with every family's columns and the pass log.

#include "experiment/experiment.h"
#include "experiment/results.h"
#include "plugin/technique.h"

#include <memory>
#include <string>
#include <vector>

namespace rtlab::pipeline {
class FrameGraph;
struct PassRecord;
class FrameStart;
} // namespace rtlab::pipeline

namespace rtlab::experiment {

class DriverContext;

//! What a family gets to set up its part of one run.
struct RunSetup {
    const RunConfig& run;
    const plugin::FamilyInfo& family; //!< this family's registration
    DriverContext& context;           //!< registry, run folder, Vulkan device
    pipeline::FrameGraph& graph;      //!< add the family's passes here
    pipeline::FrameStart* frameStart; //!< the shared start (screen families), else null
    std::vector<std::string>&
        outputs; //!< resources the run keeps: add the family's metrics, images
    //! Prefix of the family's parameter columns: "param." when the run has one family,
    //! "param.<family>." when it has several (their parameter names may repeat).
    std::string paramPrefix = "param.";
};

//! One family's state through one run (all its frames).
class FamilyRun {
public:
    virtual ~FamilyRun() = default;
    //! Columns every row of the run carries: effective parameters, declared quantities.
    virtual void describe(ResultRow& row) const = 0;
    //! Before the frame runs: the row its passes write into, externals' availability.
    virtual void beginFrame(int frame, ResultRow& row) = 0;
    //! After the frame ran: columns derived from pass records (a technique's time), state kept
    //! for the next frame.
    virtual void endFrame(int frame, const std::vector<pipeline::PassRecord>& records,
                          ResultRow& row) = 0;
};

//! A family's runtime, shared by all runs (stateless).
class Family {
public:
    virtual ~Family() = default;
    //! Creates the technique named by setup.run for this family, adds the family's passes to
    //! setup.graph and its outputs to setup.outputs. Throws rtlab::Error for a run it cannot do.
    virtual std::unique_ptr<FamilyRun> beginRun(RunSetup& setup) const = 0;
};

//! The technique a run chose for `family`, created from its parameters, as the family's
//! interface T; throws rtlab::Error when the technique does not implement it.
template <class T>
std::unique_ptr<T> createTechnique(const RunConfig& run, const plugin::Registry& registry,
                                   const std::string& family)
{
    const TechniqueChoice& choice = run.techniques.at(family);
    auto technique = registry.findTechnique(family, choice.technique)->create(choice.params);
    if (!dynamic_cast<T*>(technique.get()))
        throw std::logic_error("technique '" + choice.technique + "' does not implement the " +
                               family + " interface");
    return std::unique_ptr<T>(static_cast<T*>(technique.release()));
}

//! Adds "<prefix><name>" columns of a technique's effective parameters.
void addParamColumns(ResultRow& row, const plugin::Technique& technique, const std::string& prefix);

} // namespace rtlab::experiment
