// rtlab stress: every registered technique (or the chosen ones) through its family's stress
// cases (plugin/stress.h); writes the table, a heat map per family and a page.

#include "cli/commands.h"

#include "core/error.h"
#include "experiment/stress.h"
#include "gpu/context.h"
#include "report/stress_report.h"

#include <fmt/core.h>

#include <memory>
#include <optional>

namespace rtlab::cli {

int stressCommand(const StressCommandOptions& options)
{
    experiment::StressOptions stress;
    stress.families = options.families;
    stress.techniques = options.techniques;
    stress.cases = options.cases;
    stress.seed = options.seed;
    experiment::StressPlan plan;
    try {
        plan = experiment::planStress(plugin::builtinRegistry(), stress);
    } catch (const Error& e) {
        fmt::print(stderr, "rtlab stress: {}\n", e.what());
        return kExitBadInput;
    }

    std::unique_ptr<gpu::Context> context;
    if (!options.cpuOnly) {
        try {
            gpu::ContextOptions contextOptions;
            contextOptions.deviceName = options.device;
            context = std::make_unique<gpu::Context>(contextOptions);
            stress.gpu = context.get();
        } catch (const EnvironmentError& e) {
            fmt::print(stderr, "rtlab stress: no Vulkan device ({}); run with --cpu-only to stress the C++ paths alone\n",
                       e.what());
            return kExitEnvironment;
        }
    }
    fmt::print("stress: {} technique x case pair(s), seed {}, {}\n", plan.items.size(), options.seed,
               context ? "C++ and Vulkan paths" : "C++ paths only");

    std::size_t done = 0, failed = 0;
    const auto records = experiment::runStress(plan, stress, [&](const experiment::StressRecord& r) {
        ++done;
        failed += r.outcome.passed() ? 0 : 1;
        fmt::print("[{:>4}/{}] {:<5} {}/{} on {} ({:.0f} ms){}\n", done, plan.items.size(),
                   r.outcome.passed() ? "ok" : "FAIL", r.family, r.technique, r.caseName, r.milliseconds,
                   r.outcome.passed() ? "" : ": " + r.outcome.failures.front());
        std::fflush(stdout);
    });
    try {
        const report::StressReportFiles files =
            report::writeStressReport(records, options.outputDirectory, options.commandLine);
        fmt::print("stress: {} of {} passed, {} failed\n", records.size() - failed, records.size(), failed);
        fmt::print("table:  {}\nreport: {} ({} heat map(s), each .png and .pdf)\n", files.csv, files.html,
                   files.heatMaps.size());
    } catch (const Error& e) {
        fmt::print(stderr, "rtlab stress: {}\n", e.what());
        return kExitFailed;
    }
    return failed == 0 ? kExitOk : kExitFailed;
}

} // namespace rtlab::cli
