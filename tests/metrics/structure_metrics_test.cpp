#include "metrics/structure_metrics.h"

#include "core/error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace rtlab::metrics {
namespace {

//! A toy structure: sorted keys (the topology) with one value each (the payload); a query finds a
//! key by binary search and returns its value.
class SortedTable {
public:
    void build(std::size_t count)
    {
        mKeys.clear();
        mValues.clear();
        for (std::size_t i = 0; i < count; ++i)
            mKeys.push_back(std::uint32_t((i * 2654435761u) % 1000003u));
        std::sort(mKeys.begin(), mKeys.end());
        for (const std::uint32_t k : mKeys)
            mValues.push_back(double(k) * 0.5);
        mKeys.shrink_to_fit();
    }
    StructureFootprint measureFootprint() const
    {
        return {usedBytes(mKeys), usedBytes(mValues), mKeys.size()};
    }
    double findValue(std::uint32_t key) const
    {
        const auto it = std::lower_bound(mKeys.begin(), mKeys.end(), key);
        return it != mKeys.end() && *it == key ? mValues[std::size_t(it - mKeys.begin())] : -1.0;
    }
    std::uint32_t keyAt(std::size_t i) const { return mKeys[i]; }

private:
    std::vector<std::uint32_t> mKeys;
    std::vector<double> mValues;
};

TEST(StructureMetrics, ToyTableReportsExactBytesAndPositiveTimes)
{
    constexpr std::size_t kCount = 20000, kQueries = 50000;
    SortedTable table;
    StructureBenchmark benchmark;
    benchmark.build = [&] { table.build(kCount); };
    benchmark.footprint = [&] { return table.measureFootprint(); };
    benchmark.queriesPerBatch = kQueries;
    double expected = 0;  // every query hits: the sum of value = key / 2 over the queried keys
    benchmark.queryBatch = [&] {
        double sum = 0;
        for (std::size_t i = 0; i < kQueries; ++i)
            sum += table.findValue(table.keyAt((i * 7919) % kCount));
        return sum;
    };
    const StructureMetrics m = measureStructure(benchmark, {.warmup = 1, .repeats = 5},
                                                {.warmup = 1, .repeats = 7});
    EXPECT_EQ(m.topologyBytes, kCount * sizeof(std::uint32_t));  // 80000
    EXPECT_EQ(m.payloadBytes, kCount * sizeof(double));          // 160000
    EXPECT_EQ(m.totalBytes(), 240000u);
    EXPECT_EQ(m.nodeCount, kCount);
    EXPECT_EQ(m.buildTiming.cpuMs.count, 5);
    EXPECT_EQ(m.queryTiming.cpuMs.count, 7);
    EXPECT_GT(m.buildMs, 0.0);
    EXPECT_GE(m.buildIqrMs, 0.0);
    EXPECT_EQ(m.queryCount, kQueries);
    EXPECT_GT(m.queryNsPerQuery, 0.0);
    EXPECT_DOUBLE_EQ(m.queryNsPerQuery, m.queryTiming.cpuMs.median * 1e6 / double(kQueries));
    for (std::size_t i = 0; i < kQueries; ++i)
        expected += 0.5 * double(table.keyAt((i * 7919) % kCount));
    EXPECT_EQ(m.queryChecksum, expected);
}

TEST(StructureMetrics, BuildOnlyAndInvalidBenchmarks)
{
    std::vector<int> data;
    StructureBenchmark buildOnly;
    buildOnly.build = [&] { data.assign(1000, 1); };
    const StructureMetrics m = measureStructure(buildOnly);
    EXPECT_EQ(m.totalBytes(), 0u);  // no footprint callable
    EXPECT_EQ(m.queryCount, 0u);
    EXPECT_TRUE(std::isnan(m.queryNsPerQuery));
    EXPECT_EQ(data.size(), 1000u);

    EXPECT_THROW(measureStructure(StructureBenchmark{}), Error);
    StructureBenchmark noCount = buildOnly;
    noCount.queryBatch = [] { return 0.0; };
    EXPECT_THROW(measureStructure(noCount), Error);
}

} // namespace
} // namespace rtlab::metrics
