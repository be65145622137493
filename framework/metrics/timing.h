#pragma once
// The timing harness every experiment uses. Techniques never time themselves: the harness runs
// the work `warmup` times (not measured), then `repeats` times, and reports the median and the
// interquartile range of CPU wall time and of each GPU pass's timestamp time, side by side.
// The first call is timed on its own ("first use": shader compilation, pipeline and buffer
// creation, caches) and is never part of the statistics.

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace rtlab::metrics {

//! Order statistics of a sample; quantiles by linear interpolation between order statistics
//! (Hyndman & Fan type 7, the default of R and NumPy).
struct SampleStats {
    int count = 0;
    double median = 0;
    double q1 = 0;   //!< 25th percentile
    double q3 = 0;   //!< 75th percentile
    double min = 0;
    double max = 0;
    double mean = 0;
    double iqr() const { return q3 - q1; }
};

//! Statistics of `values`; an empty input gives count 0 and NaN elsewhere.
SampleStats computeStats(std::vector<double> values);
//! The q-quantile (0..1) of sorted values, type 7.
double quantileSorted(const std::vector<double>& sorted, double q);

struct TimingOptions {
    int warmup = 1;   //!< unmeasured runs after the first use, [0, 100]
    int repeats = 5;  //!< measured runs, [1, 10000]
};

//! GPU time of each labelled pass of one execution, in milliseconds.
using GpuPassTimes = std::map<std::string, double>;

struct TimingReport {
    double firstUseMs = 0;        //!< CPU wall time of the very first run (includes setup costs)
    double setupMs = 0;           //!< reported by the work itself: shader compilation, uploads
    SampleStats cpuMs;            //!< CPU wall time of the measured runs
    std::map<std::string, SampleStats> gpuMs;  //!< per pass, when the work ran GPU passes
    //! Sum of the per-pass GPU medians (NaN when there were no GPU passes).
    double gpuTotalMedianMs() const;
};

//! One execution of the work being timed. It returns the GPU pass times of that execution
//! (empty for CPU-only work); the harness measures the CPU wall time around it.
using TimedWork = std::function<GpuPassTimes()>;

//! Runs `work` once (first use), `warmup` times, then `repeats` times, and reports.
//! `setup`, when given, runs before the first use and its wall time is reported as setupMs
//! (shader compilation, allocation): it is excluded from every statistic.
TimingReport measure(const TimingOptions& options, const TimedWork& work,
                     const std::function<void()>& setup = {});

} // namespace rtlab::metrics
