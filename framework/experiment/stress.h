#pragma once
// `rtlab stress`: every registered technique (or the chosen ones) through its family's stress
// cases (plugin/stress.h), one record per technique and case: pass or fail, NaN/inf and
// out-of-range counts, the worst deviation from the case's closed form and its tolerance, the
// time, and what failed. A throw from a technique is a failure carrying its message; the other
// cases still run.

#include "experiment/results.h"
#include "plugin/technique.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace rtlab::gpu {
class Context;
} // namespace rtlab::gpu

namespace rtlab::experiment {

struct StressOptions {
    std::vector<std::string> families;   //!< empty: every family with stress cases
    std::vector<std::string> techniques; //!< empty: every technique of those families
    std::vector<std::string> cases;      //!< empty: every case; otherwise case names
    std::uint64_t seed = 1;              //!< seeds the randomised cases
    gpu::Context* gpu = nullptr;         //!< Vulkan paths too when set
};

struct StressRecord {
    std::string family;
    std::string technique;
    std::string caseName;
    std::string group;
    std::string description;
    plugin::StressOutcome outcome;
    double milliseconds = 0.0; //!< wall-clock time of the case, all its devices and variants
};

//! The (family, technique, case) triples `options` selects, in registry order. Throws
//! rtlab::Error naming the valid choices for an unknown family, technique or case, and when the
//! selection is empty.
struct StressPlan {
    struct Item {
        const plugin::TechniqueEntry* technique;
        const plugin::StressCase* stressCase;
    };
    std::vector<plugin::StressCase> cases; //!< owned by the plan; items point into it
    std::vector<Item> items;
};
StressPlan planStress(const plugin::Registry& registry, const StressOptions& options);

//! Runs one item (catching a throw as a failure).
StressRecord runStressItem(const StressPlan::Item& item, const StressOptions& options);

//! Runs the plan, calling `onRecord` after each item (progress).
std::vector<StressRecord> runStress(const StressPlan& plan, const StressOptions& options,
                                    const std::function<void(const StressRecord&)>& onRecord = {});

//! One tidy row: family, technique, case, group, passed, values, non_finite, out_of_range,
//! deviation, tolerance, ms, failures (joined with "; "), note, description.
ResultRow makeStressRow(const StressRecord& record);

} // namespace rtlab::experiment
