#include "metrics/structure_metrics.h"

#include "core/error.h"

#include <limits>

namespace rtlab::metrics {

StructureMetrics measureStructure(const StructureBenchmark& benchmark,
                                  const TimingOptions& buildOptions,
                                  const TimingOptions& queryOptions)
{
    if (!benchmark.build)
        throw Error("metrics: structure benchmark: no build function was given");
    if (benchmark.queryBatch && benchmark.queriesPerBatch == 0)
        throw Error("metrics: structure benchmark: queriesPerBatch must be positive");

    StructureMetrics m;
    m.buildTiming = measure(buildOptions, [&] {
        benchmark.build();
        return GpuPassTimes{};
    });
    m.buildMs = m.buildTiming.cpuMs.median;
    m.buildIqrMs = m.buildTiming.cpuMs.iqr();
    if (benchmark.footprint) {
        const StructureFootprint f = benchmark.footprint();
        m.topologyBytes = f.topologyBytes;
        m.payloadBytes = f.payloadBytes;
        m.nodeCount = f.nodeCount;
    }
    if (!benchmark.queryBatch) {
        m.queryNsPerQuery = m.queryIqrNsPerQuery = std::numeric_limits<double>::quiet_NaN();
        return m;
    }
    m.queryCount = benchmark.queriesPerBatch;
    m.queryTiming = measure(queryOptions, [&] {
        m.queryChecksum = benchmark.queryBatch();
        return GpuPassTimes{};
    });
    const double nsPerMsPerQuery = 1e6 / double(m.queryCount);
    m.queryNsPerQuery = m.queryTiming.cpuMs.median * nsPerMsPerQuery;
    m.queryIqrNsPerQuery = m.queryTiming.cpuMs.iqr() * nsPerMsPerQuery;
    return m;
}

} // namespace rtlab::metrics
