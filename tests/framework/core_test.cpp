// Core helpers: names, hashing, progress formatting, timing statistics.

#include "core/hash.h"
#include "core/progress.h"
#include "core/strings.h"
#include "metrics/timing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

using namespace rtlab;

TEST(Strings, EditDistance)
{
    EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
    EXPECT_EQ(editDistance("", "abc"), 3u);
    EXPECT_EQ(editDistance("radius", "radius"), 0u);
}

TEST(Strings, ClosestNamesBestFirstAndOnlyPlausible)
{
    const std::vector<std::string> names = {"radius", "directions", "steps", "falloff"};
    EXPECT_EQ(closestNames("radus", names), std::vector<std::string>{"radius"});
    EXPECT_EQ(closestNames("step", names), std::vector<std::string>{"steps"});
    EXPECT_TRUE(closestNames("zzzzzz", names).empty());
}

TEST(Hash, StableAndSensitive)
{
    EXPECT_EQ(hashHex("abc"), hashHex("abc"));
    EXPECT_NE(hashHex("abc"), hashHex("abd"));
    EXPECT_EQ(hashHex("abc").size(), 32u);
    // Length prefixes keep concatenations apart.
    EXPECT_NE(Hasher().add("ab").add("c").hexDigest(), Hasher().add("a").add("bc").hexDigest());
}

TEST(Progress, BarShowsFractionAndEta)
{
    const std::string bar = Progress::formatBar(5, 10, 10.0, "run 5", 10);
    EXPECT_EQ(bar, "[#####.....] 5/10  50% ETA 10.0s  run 5");
    EXPECT_EQ(Progress::formatBar(10, 10, 65.0, "", 4), "[####] 10/10 100% in 1m05s");
}

TEST(Progress, PlainLinesWhenNotATerminal)
{
    std::FILE* f = std::tmpfile();
    {
        Progress p("job", 3, f);
        EXPECT_FALSE(p.interactive());
        p.advance();
        p.advance();
        p.advance();
    }
    std::rewind(f);
    char buf[512] = {};
    const std::size_t n = std::fread(buf, 1, sizeof buf - 1, f);
    std::fclose(f);
    const std::string out(buf, n);
    EXPECT_NE(out.find("job: 0/3\n"), std::string::npos) << out;
    EXPECT_NE(out.find("job: 3/3 100% in"), std::string::npos) << out;
    EXPECT_EQ(out.find('\r'), std::string::npos) << "no carriage returns in logs";
}

TEST(Timing, QuantilesAreType7)
{
    // NumPy: np.percentile([1,2,3,4,5,6,7,8], [25,50,75]) = [2.75, 4.5, 6.25]
    const auto s = metrics::computeStats({8, 1, 7, 2, 6, 3, 5, 4});
    EXPECT_DOUBLE_EQ(s.q1, 2.75);
    EXPECT_DOUBLE_EQ(s.median, 4.5);
    EXPECT_DOUBLE_EQ(s.q3, 6.25);
    EXPECT_DOUBLE_EQ(s.iqr(), 3.5);
    EXPECT_DOUBLE_EQ(s.mean, 4.5);
    EXPECT_TRUE(std::isnan(metrics::computeStats({}).median));
}

TEST(Timing, FirstUseWarmupAndRepeatsAreSeparated)
{
    int calls = 0, setups = 0;
    const auto report = metrics::measure(
        {.warmup = 2, .repeats = 5},
        [&] {
            ++calls;
            // The GPU time of pass "a" is the call number, so the statistics are known exactly:
            // measured calls are 4..8 (1 = first use, 2..3 = warm-up).
            return metrics::GpuPassTimes{{"a", double(calls)}, {"b", 1.0}};
        },
        [&] { ++setups; });
    EXPECT_EQ(setups, 1);
    EXPECT_EQ(calls, 1 + 2 + 5);
    EXPECT_EQ(report.cpuMs.count, 5);
    ASSERT_EQ(report.gpuMs.count("a"), 1u);
    EXPECT_DOUBLE_EQ(report.gpuMs.at("a").median, 6.0);
    EXPECT_DOUBLE_EQ(report.gpuMs.at("a").min, 4.0);
    EXPECT_DOUBLE_EQ(report.gpuTotalMedianMs(), 7.0);
    EXPECT_TRUE(std::isnan(metrics::measure({}, [] { return metrics::GpuPassTimes{}; }).gpuTotalMedianMs()));
}
