#pragma once
// The base of every technique plugin, the registry that holds them, and the registration macro.
//
// A technique is one folder techniques/<family>/<name>/ whose main .cpp ends with
//     RTLAB_REGISTER_TECHNIQUE(<family>, <name>, <Class>)
// CMake discovers the folder (rtlab_add_technique in its CMakeLists.txt) and generates the one file
// that calls every registration function, so nothing central is edited and no self-registering
// static can be dropped by the linker.

#include "config/param.h"
#include "plugin/stress.h"

#include <concepts>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace rtlab::plugin {

//! What a technique is, for listings, reports and doc generation.
struct TechniqueInfo {
    std::string name;      //!< registry key = folder name = config name (filled in at registration)
    std::string family;    //!< family key (filled in at registration)
    std::string summary;   //!< one line
    std::string reference; //!< the paper or talk it implements
    std::string seed;      //!< the talk transcript in shared seeds it follows, if any
};

//! Common base of all techniques. Family interfaces (occlusion.h, isosurface.h, voxel_gi.h)
//! derive from it and add the per-frame / per-build call.
class Technique {
public:
    virtual ~Technique() = default;
    //! The parameters actually in effect: every declared parameter, after defaults and any
    //! clamping or derivation the technique applies. Stored beside every result.
    virtual config::ParamSet effectiveParams() const = 0;
    //! Named counts or ratios from the last call (e.g. "vertices_left_cell_share"), which the
    //! harness stores as `counter.<name>` columns. Most techniques have none.
    virtual std::vector<std::pair<std::string, double>> counters() const { return {}; }
};

//! A registered technique: its description, declared parameters and factory.
struct TechniqueEntry {
    TechniqueInfo info;
    config::ParamSchema schema;
    //! Builds an instance from validated parameters (every declared key present).
    std::function<std::unique_ptr<Technique>(const config::ParamSet&)> create;
};

//! A metric (group) a family's driver can compute; experiments choose them with `metrics:`.
struct MetricInfo {
    std::string name; //!< snake_case, as written in experiment files
    std::string doc;  //!< one line: what it measures and its columns
};

//! What a family's runs are made of, which decides the run keys that apply and the run's frame.
enum class FamilyDomain {
    Volume, //!< a sampled field of `grid` samples per axis; one frame of its own passes
    Screen, //!< images of `resolution` over `frames` frames, on the shared frame start
            //!< (pipeline/frame_start.h): several screen families share one frame
};

//! A histogram the report draws per technique from a column of space-separated bin counts.
struct HistogramFigure {
    std::string column; //!< e.g. "angle.histogram_10deg"
    std::string name;   //!< file name stem, e.g. "angles"
    std::string title;  //!< e.g. "triangle angles"
    std::string xLabel; //!< the bins span [0, xRange]
    double xRange = 1.0;
    std::string caption;
};

//! A figure over every scene of a study: column y against column x (numeric, e.g. a scene
//! parameter scene.<name>), one line per technique, the mean of the runs with the same x.
struct AcrossScenesFigure {
    std::string x;      //!< e.g. "scene.wall_voxels"
    std::string xLabel;
    std::string y;      //!< e.g. "indirect.mean_signed_error"
    std::string yLabel;
    std::string name;   //!< file name stem
    std::string title;
    std::string caption;
    //! Columns that split a technique's line, e.g. {"param.anti_leak"}: a run's line is
    //! "technique (anti_leak=false)"; runs on one line at the same x are averaged.
    std::vector<std::string> seriesBy;
};

//! Which columns a family's figures and tables use (report/report.h).
struct FamilyReport {
    std::string cost;      //!< e.g. "technique_ms"
    std::string costLabel; //!< axis label with unit
    std::string error;     //!< e.g. "ao.rmse"
    std::string errorLabel;
    std::vector<std::string> passes; //!< per-pass time columns, stacked in this order
    std::string passTimeLabel;       //!< y label of the stacked per-pass times
    //! More error columns, each with its own time-against-error plot when the study has it.
    std::vector<std::pair<std::string, std::string>> extraErrors; //!< (column, axis label)
    //! More columns drawn against each swept parameter beside the main error (error-against-
    //! parameter charts over matched runs), e.g. a ratio that time-against-error plots cannot
    //! rank. (column, axis label)
    std::vector<std::pair<std::string, std::string>> paramErrors;
    //! Further columns of the report's run tables (topology counts, masked errors, ...).
    std::vector<std::string> tableColumns;
    bool convergence = false; //!< error against cell size with fitted order (grid sweeps)
    std::vector<HistogramFigure> histograms; //!< per-technique histograms
    std::vector<AcrossScenesFigure> acrossScenes; //!< figures over all scenes of the study
    //! The family's sampling baseline: a technique of its own that converges to the ground truth
    //! as its sample count grows (Embree path tracing, ray-traced AO). Where a study has its
    //! runs, the report gives every other run the baseline's time at the same error and the
    //! speed-up (report_detail.h computeEqualError, equal_error.csv); empty for none.
    std::string baseline;
};

} // namespace rtlab::plugin
namespace rtlab::experiment {
class Family;
}
namespace rtlab::plugin {

//! A technique family: one interface, interchangeable plugins, one ground-truth definition. A
//! family is one folder framework/families/<name>/ whose runtime (experiment/family.h) adds its
//! passes to a run's frame graph; it registers itself like a technique (RTLAB_REGISTER_FAMILY).
struct FamilyInfo {
    std::string name;                //!< "occlusion", "isosurface", "voxel_gi", ...
    std::string summary;             //!< one line
    std::string input;               //!< what every technique of the family consumes
    std::string output;              //!< what it produces
    std::string groundTruth;         //!< what it is compared with
    std::vector<MetricInfo> metrics; //!< what its passes can measure (all by default)
    FamilyDomain domain = FamilyDomain::Screen;
    FamilyReport report;
    //! Adds the family's passes to runs; null for a family that describes techniques only
    //! (registries built by hand in tests).
    std::shared_ptr<const experiment::Family> runtime;
    //! The family's stress cases (plugin/stress.h), run by `rtlab stress` and the family suite
    //! over every registered technique; empty for a family that declares none.
    std::function<std::vector<StressCase>()> stressCases;
};

class Registry {
public:
    //! Throws std::logic_error on a repeated family name.
    void addFamily(FamilyInfo family);
    //! Throws std::logic_error if the family is unknown or the name repeats within the family.
    void addTechnique(TechniqueEntry entry);

    const FamilyInfo* findFamily(const std::string& name) const;
    const TechniqueEntry* findTechnique(const std::string& family, const std::string& name) const;

    std::vector<std::string> familyNames() const;
    std::vector<std::string> techniqueNames(const std::string& family) const;
    std::vector<const TechniqueEntry*> techniques(const std::string& family) const;

private:
    std::vector<FamilyInfo> mFamilies;
    std::vector<std::unique_ptr<TechniqueEntry>> mTechniques;
};

//! Adds every family compiled into this program (the folders framework/families/<name>/). Defined
//! in the file CMake generates from them (target rtlab_families).
void registerBuiltinFamilies(Registry& registry);

//! Calls the registration function of every technique compiled into this program. Defined in
//! the file CMake generates from the discovered technique folders (target rtlab_techniques).
void registerAllTechniques(Registry& registry);

//! The registry with the built-in families and all compiled-in techniques (built on first use).
//! Defined beside registerAllTechniques, so programs get it by linking rtlab_techniques.
const Registry& builtinRegistry();

//! What a technique class must provide.
template <class T>
concept TechniquePlugin = std::derived_from<T, Technique> && requires(const config::ParamSet& p)
{
    {
        T::describe()
        } -> std::convertible_to<TechniqueInfo>; // summary, reference, seed
    {
        T::declareParams()
        } -> std::convertible_to<config::ParamSchema>;
    {
        T::kFamily
        } -> std::convertible_to<const char*>; // from the family base
    requires std::constructible_from<T, const config::ParamSet&>;
};

template <TechniquePlugin T>
void registerTechnique(Registry& registry, const char* family, const char* name)
{
    TechniqueEntry entry;
    entry.info = T::describe();
    entry.info.family = family;
    entry.info.name = name;
    if (entry.info.family != T::kFamily)
        throw std::logic_error(std::string("technique '") + name + "' is registered in family '" +
                               family + "' but derives from the interface of family '" +
                               T::kFamily + "'");
    entry.schema = T::declareParams();
    entry.create = [](const config::ParamSet& params) -> std::unique_ptr<Technique> {
        return std::make_unique<T>(params);
    };
    registry.addTechnique(std::move(entry));
}

} // namespace rtlab::plugin

//! Registers technique class `Class` as `name` in `family`. Put it once, at the bottom of the
//! technique's main .cpp, outside any namespace. `family` and `name` must match the folder
//! techniques/<family>/<name>/ (CMake checks the folder, the compiler checks the class).
#define RTLAB_REGISTER_TECHNIQUE(family, name, Class)                                              \
    void rtlabRegisterTechnique_##family##_##name(::rtlab::plugin::Registry& registry)             \
    {                                                                                              \
        ::rtlab::plugin::registerTechnique<Class>(registry, #family, #name);                       \
    }

//! Registers a family: `info` (a FamilyInfo with its runtime) as `name`. Put it once, at the
//! bottom of the family's main .cpp (framework/families/<name>/<name>_family.cpp), outside any
//! namespace; `name` must match the folder.
#define RTLAB_REGISTER_FAMILY(familyName, makeInfo)                                                \
    void rtlabRegisterFamily_##familyName(::rtlab::plugin::Registry& registry)                     \
    {                                                                                              \
        ::rtlab::plugin::FamilyInfo info = makeInfo();                                             \
        if (info.name != #familyName)                                                              \
            throw std::logic_error("family folder '" #familyName "' registers a family named '" +  \
                                   info.name + "'");                                               \
        registry.addFamily(std::move(info));                                                       \
    }
