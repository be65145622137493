#pragma once
// The base of every technique plugin, the registry that holds them, and the registration macro.
//
// A technique is one folder techniques/<family>/<name>/ whose main .cpp ends with
//     RTLAB_REGISTER_TECHNIQUE(<family>, <name>, <Class>)
// CMake discovers the folder (rtlab_add_technique in its CMakeLists.txt) and generates the one file
// that calls every registration function, so nothing central is edited and no self-registering
// static can be dropped by the linker.

#include "config/param.h"

#include <concepts>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace rtlab::plugin {

//! What a technique is, for listings, reports and doc generation.
struct TechniqueInfo {
    std::string name;       //!< registry key = folder name = config name (filled in at registration)
    std::string family;     //!< family key (filled in at registration)
    std::string summary;    //!< one line
    std::string reference;  //!< the paper or talk it implements
    std::string seed;       //!< the talk transcript in shared seeds it follows, if any
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
    std::string name;  //!< snake_case, as written in experiment files
    std::string doc;   //!< one line: what it measures and its columns
};

//! A technique family: one interface, interchangeable plugins, one ground-truth definition.
struct FamilyInfo {
    std::string name;         //!< "occlusion", "isosurface", "voxel_gi", ...
    std::string summary;      //!< one line
    std::string input;        //!< what every technique of the family consumes
    std::string output;       //!< what it produces
    std::string groundTruth;  //!< what it is compared with
    std::vector<MetricInfo> metrics;  //!< what its driver can measure (all by default)
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

//! Adds the built-in families (occlusion, isosurface, voxel_gi) to `registry`.
void registerBuiltinFamilies(Registry& registry);

//! Calls the registration function of every technique compiled into this program. Defined in
//! the file CMake generates from the discovered technique folders (target rtlab_techniques).
void registerAllTechniques(Registry& registry);

//! The registry with the built-in families and all compiled-in techniques (built on first use).
//! Defined beside registerAllTechniques, so programs get it by linking rtlab_techniques.
const Registry& builtinRegistry();

//! What a technique class must provide.
template <class T>
concept TechniquePlugin = std::derived_from<T, Technique> && requires(const config::ParamSet& p) {
    { T::describe() } -> std::convertible_to<TechniqueInfo>;          // summary, reference, seed
    { T::declareParams() } -> std::convertible_to<config::ParamSchema>;
    { T::kFamily } -> std::convertible_to<const char*>;                  // from the family base
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
        throw std::logic_error(std::string("technique '") + name + "' is registered in family '" + family +
                               "' but derives from the interface of family '" + T::kFamily + "'");
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
#define RTLAB_REGISTER_TECHNIQUE(family, name, Class)                                                  \
    void rtlabRegisterTechnique_##family##_##name(::rtlab::plugin::Registry& registry)                 \
    {                                                                                                  \
        ::rtlab::plugin::registerTechnique<Class>(registry, #family, #name);                           \
    }
