#pragma once
// The manifest written beside every study's results: what produced them. Git revision (and
// whether the tree had uncommitted changes), the experiment file and its expanded runs, the
// Vulkan device and driver, the CPU and thread count, the seeds, and the versions of the
// libraries rtlab was built with.

#include "experiment/experiment.h"

#include <string>

namespace rtlab::experiment {

struct BuildInfo {
    std::string gitRevision; //!< "unknown" outside a git checkout
    bool gitDirty = false;   //!< uncommitted changes in the checkout at run time
    std::string cpuModel;
    unsigned hardwareThreads = 0;
    std::string vulkanDevice; //!< "" when no Vulkan device could be opened
    std::string vulkanDriver;
    std::string dependencies; //!< JSON object name -> version
};

//! Collects the information once (git is asked in the source tree rtlab was built from, or in
//! $RTLAB_SOURCE_DIR). Opening a Vulkan device for its name takes a few tens of milliseconds.
BuildInfo collectBuildInfo(bool queryVulkan = true);

//! Writes directory/manifest.json atomically (temporary file + rename).
void writeManifest(const Experiment& experiment, const BuildInfo& info,
                   const std::string& directory, const std::string& shard = "");

} // namespace rtlab::experiment
