#pragma once
// The family suites' use of the stress cases (plugin/stress.h): every case of a family, for one
// technique, through the same runner as `rtlab stress`; each failing case is one test failure
// listing what failed.

#include "experiment/stress.h"
#include "plugin/technique.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

namespace rtlab::test {

//! A case a technique fails by the design of its algorithm (not a defect of the implementation),
//! with the reason; the suite requires it to keep failing, so that a fix removes the entry.
struct KnownFailure {
    std::string technique;
    std::string caseName;
    std::string reason;
};

inline void expectEveryStressCasePasses(const plugin::Registry& registry, const plugin::TechniqueEntry& technique,
                                        gpu::Context* gpu, const std::vector<KnownFailure>& knownFailures = {},
                                        std::uint64_t seed = 1)
{
    experiment::StressOptions options;
    options.families = {technique.info.family};
    options.techniques = {technique.info.name};
    options.gpu = gpu;
    options.seed = seed;
    const experiment::StressPlan plan = experiment::planStress(registry, options);
    ASSERT_FALSE(plan.items.empty()) << technique.info.family << " declares no stress cases";
    for (const auto& item : plan.items) {
        const experiment::StressRecord r = experiment::runStressItem(item, options);
        std::string failures;
        for (const auto& f : r.outcome.failures)
            failures += "\n  " + f;
        const auto known = std::find_if(knownFailures.begin(), knownFailures.end(), [&](const KnownFailure& k) {
            return k.technique == technique.info.name && k.caseName == r.caseName;
        });
        if (known != knownFailures.end()) {
            EXPECT_FALSE(r.outcome.passed()) << technique.info.name << " now passes " << r.caseName
                                             << ", a known failure: remove it from the list";
            std::printf("known failure: %s on %s (%s):%s\n", technique.info.name.c_str(), r.caseName.c_str(),
                        known->reason.c_str(), failures.c_str());
            continue;
        }
        EXPECT_TRUE(r.outcome.passed()) << technique.info.name << " on " << r.caseName << " (" << r.description
                                        << "):" << failures;
    }
}

} // namespace rtlab::test
