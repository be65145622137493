#pragma once
// Data-structure metrics measured the same way for every spatial structure (voxel grids, sparse
// trees, hash maps, BVHs): memory split into topology and payload, build time, query time.
//
// - Topology bytes: what organises the data (nodes, child pointers or masks, offsets, hash
//   slots, keys). Payload bytes: the data itself (samples, colours, normals, bricks). A structure
//   reports both from its own containers; usedBytes() counts the elements in use (size, not
//   capacity) so that the numbers are exact and independent of allocator slack.
// - Times come from the timing harness (metrics/timing.h): the median and interquartile range
//   of `repeats` runs after the first use and `warmup` unmeasured runs.

#include "metrics/timing.h"

#include <cstddef>
#include <functional>
#include <vector>

namespace rtlab::metrics {

//! Bytes of the elements in use, size() x sizeof(T).
template <class T>
std::size_t usedBytes(const std::vector<T>& v)
{
    return v.size() * sizeof(T);
}

//! Bytes allocated, capacity() x sizeof(T).
template <class T>
std::size_t reservedBytes(const std::vector<T>& v)
{
    return v.capacity() * sizeof(T);
}

//! Memory of a built structure, as the structure itself reports it.
struct StructureFootprint {
    std::size_t topologyBytes = 0;  //!< bytes of the organisation: nodes, pointers, offsets, keys
    std::size_t payloadBytes = 0;   //!< bytes of the stored data
    std::size_t nodeCount = 0;      //!< nodes as the structure defines them (0 when flat)
};

//! What measureStructure needs from a structure, as callables over the caller's state.
struct StructureBenchmark {
    //! Builds the structure from scratch, replacing any previous build. Required.
    std::function<void()> build;
    //! Memory of the structure as last built. Optional (zeros when absent).
    std::function<StructureFootprint()> footprint;
    //! Runs queriesPerBatch queries against the built structure and returns a checksum of their
    //! results (kept in StructureMetrics so that the work cannot be optimised away). Optional.
    std::function<double()> queryBatch;
    std::size_t queriesPerBatch = 0;
};

struct StructureMetrics {
    std::size_t topologyBytes = 0;
    std::size_t payloadBytes = 0;
    std::size_t nodeCount = 0;
    double buildMs = 0;             //!< median CPU wall time of a build, milliseconds
    double buildIqrMs = 0;          //!< interquartile range of the build time, milliseconds
    std::size_t queryCount = 0;     //!< queries per batch
    double queryNsPerQuery = 0;     //!< median batch time / queryCount, nanoseconds; NaN if none
    double queryIqrNsPerQuery = 0;  //!< interquartile range / queryCount, nanoseconds; NaN if none
    double queryChecksum = 0;       //!< what the last query batch returned
    TimingReport buildTiming;       //!< the full report of the build runs
    TimingReport queryTiming;       //!< the full report of the query batches (empty if none)
    std::size_t totalBytes() const { return topologyBytes + payloadBytes; }
};

//! Times `build` with the harness (each run rebuilds), reads the footprint of the last build, then
//! times `queryBatch` on it. Throws rtlab::Error when build is missing, or when queryBatch is
//! given with queriesPerBatch 0.
StructureMetrics measureStructure(const StructureBenchmark& benchmark,
                                  const TimingOptions& buildOptions = {},
                                  const TimingOptions& queryOptions = {});

} // namespace rtlab::metrics
