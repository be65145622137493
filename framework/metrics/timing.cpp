#include "metrics/timing.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>

namespace rtlab::metrics {

namespace {

double elapsedMs(std::chrono::steady_clock::time_point since)
{
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - since).count();
}

} // namespace

double quantileSorted(const std::vector<double>& sorted, double q)
{
    if (sorted.empty())
        return std::numeric_limits<double>::quiet_NaN();
    const double h = (double(sorted.size()) - 1.0) * std::clamp(q, 0.0, 1.0);
    const auto lo = std::size_t(std::floor(h));
    const auto hi = std::min(lo + 1, sorted.size() - 1);
    return sorted[lo] + (h - double(lo)) * (sorted[hi] - sorted[lo]);
}

SampleStats computeStats(std::vector<double> values)
{
    SampleStats s;
    s.count = int(values.size());
    if (values.empty()) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        s.median = s.q1 = s.q3 = s.min = s.max = s.mean = nan;
        return s;
    }
    std::sort(values.begin(), values.end());
    s.median = quantileSorted(values, 0.5);
    s.q1 = quantileSorted(values, 0.25);
    s.q3 = quantileSorted(values, 0.75);
    s.min = values.front();
    s.max = values.back();
    s.mean = std::accumulate(values.begin(), values.end(), 0.0) / double(values.size());
    return s;
}

double TimingReport::gpuTotalMedianMs() const
{
    if (gpuMs.empty())
        return std::numeric_limits<double>::quiet_NaN();
    double total = 0;
    for (const auto& [pass, stats] : gpuMs)
        total += stats.median;
    return total;
}

TimingReport measure(const TimingOptions& options, const TimedWork& work,
                     const std::function<void()>& setup)
{
    TimingReport report;
    if (setup) {
        const auto t0 = std::chrono::steady_clock::now();
        setup();
        report.setupMs = elapsedMs(t0);
    }
    {
        const auto t0 = std::chrono::steady_clock::now();
        work();
        report.firstUseMs = elapsedMs(t0);
    }
    for (int i = 0; i < options.warmup; ++i)
        work();

    std::vector<double> cpu;
    std::map<std::string, std::vector<double>> gpu;
    for (int i = 0; i < std::max(1, options.repeats); ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const GpuPassTimes passes = work();
        cpu.push_back(elapsedMs(t0));
        for (const auto& [pass, ms] : passes)
            gpu[pass].push_back(ms);
    }
    report.cpuMs = computeStats(std::move(cpu));
    for (auto& [pass, samples] : gpu)
        report.gpuMs[pass] = computeStats(std::move(samples));
    return report;
}

} // namespace rtlab::metrics
