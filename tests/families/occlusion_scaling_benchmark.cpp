// How every registered occlusion technique's cost scales with the image size and with its own
// direction / sample count. Each technique runs on a synthetic G-buffer (a floor, two walls and a
// sphere: planes, a crease, a curved surface, silhouettes) at 3 resolutions x 3 values of its
// knob (the first of `slices`, `directions`, `samples`, `samples_per_pixel` in its schema:
// default / 2, default, default x 2), timed by the experiments' harness: metrics::measure around
// compute(), GPU pass times from the context's run log (experiment/gpu_timing.h: timestamps on a GPU, submit-to-fence
// wall time on a CPU device such as lavapipe). The scaling exponents come from one least-squares
// fit per technique over all 9 runs:
//   log(time) = a + b log(pixels) + c log(knob)
// b = 1 means linear in the pixel count, c = 1 linear in the directions.
//
//   occlusion_scaling_benchmark [--quick] [--csv path] [--repeats n] [--warmup n]
//                               [--technique name] [--cpu]
// --quick: 2 tiny resolutions x 2 knob values, 1 repeat (the ctest that keeps this compiling and
// running). Every technique with a `radius` is also timed at the largest size with radius
// default / 2, default and default x 2, and the slope of log(time) on log(radius) is printed. --cpu: time the plain C++ path (input.gpu = null) by its CPU wall time instead.

#include "experiment/gpu_timing.h"
#include "gpu/context.h"
#include "metrics/timing.h"
#include "families/occlusion/occlusion.h"
#include "families/occlusion/synthetic_gbuffer.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

using namespace rtlab;

namespace {

//! Nearest hit of a view-space ray from the origin: distance and normal facing the camera.
std::optional<std::pair<float, glm::vec3>> hitScene(const glm::vec3& d)
{
    std::optional<std::pair<float, glm::vec3>> best;
    auto plane = [&](const glm::vec3& p, const glm::vec3& n) {
        const float den = glm::dot(d, n);
        if (std::abs(den) < 1e-8f)
            return;
        const float t = glm::dot(p, n) / den;
        if (t > 0.0f && (!best || t < best->first))
            best = std::pair{t, den > 0.0f ? -n : n};
    };
    plane({0, -1, 0}, {0, 1, 0}); // floor
    plane({0, 0, -8}, {0, 0, 1}); // back wall
    plane({-3, 0, 0}, {1, 0, 0}); // side wall
    const glm::vec3 centre(0.8f, -0.4f, -4.0f);
    const float radius = 0.6f;
    const float b = glm::dot(d, centre);
    const float disc = b * b - (glm::dot(centre, centre) - radius * radius);
    if (disc >= 0.0f) {
        const float t = b - std::sqrt(disc);
        if (t > 0.0f && (!best || t < best->first))
            best = std::pair{t, glm::normalize(d * t - centre)};
    }
    return best;
}

//! The scene above seen through a 60-degree camera at the origin.
occlusion::SyntheticGBuffer makeGBuffer(int w, int h)
{
    return occlusion::makeSyntheticGBuffer(w, h, 60.0f, [](const glm::vec3& d) {
        const auto hit = hitScene(d);
        return hit ? *hit : std::pair{-1.0f, glm::vec3(0.0f)};
    });
}

struct Options {
    bool quick = false;
    bool cpu = false;
    std::string csv;
    std::string technique;
    int repeats = 3;
    int warmup = 1;
};

struct Run {
    std::string technique;
    std::string knob;
    std::int64_t knobValue = 0;
    int width = 0;
    int height = 0;
    double timeMs = 0.0; //!< the fitted time: GPU total median (or CPU median with --cpu)
    double iqrMs = 0.0;
    double cpuMedianMs = 0.0;
    double firstUseMs = 0.0;
};

struct Fit {
    double pixelExponent = std::nan("");
    double knobExponent = std::nan("");
    double rSquared = std::nan("");
};

//! Least squares for log t = a + b log P (+ c log K when the knob varies), normal equations.
Fit fitExponents(const std::vector<Run>& runs)
{
    Fit fit;
    std::vector<std::array<double, 3>> x;
    std::vector<double> y;
    for (const Run& r : runs) {
        if (!(r.timeMs > 0.0) || !std::isfinite(r.timeMs))
            continue;
        x.push_back({1.0, std::log(double(r.width) * r.height),
                     std::log(double(std::max<std::int64_t>(1, r.knobValue)))});
        y.push_back(std::log(r.timeMs));
    }
    bool knobVaries = false;
    for (const auto& row : x)
        knobVaries = knobVaries || row[2] != x.front()[2];
    const int k = knobVaries ? 3 : 2;
    if (int(x.size()) < k + 1)
        return fit;
    double a[3][4] = {};
    for (std::size_t i = 0; i < x.size(); ++i)
        for (int r = 0; r < k; ++r) {
            for (int c = 0; c < k; ++c)
                a[r][c] += x[i][r] * x[i][c];
            a[r][k] += x[i][r] * y[i];
        }
    for (int col = 0; col < k; ++col) { // Gauss-Jordan with partial pivoting
        int pivot = col;
        for (int r = col + 1; r < k; ++r)
            if (std::abs(a[r][col]) > std::abs(a[pivot][col]))
                pivot = r;
        for (int c = 0; c <= k; ++c)
            std::swap(a[col][c], a[pivot][c]);
        if (std::abs(a[col][col]) < 1e-12)
            return fit;
        for (int r = 0; r < k; ++r) {
            if (r == col)
                continue;
            const double f = a[r][col] / a[col][col];
            for (int c = col; c <= k; ++c)
                a[r][c] -= f * a[col][c];
        }
    }
    std::array<double, 3> beta{};
    for (int r = 0; r < k; ++r)
        beta[r] = a[r][k] / a[r][r];
    double mean = 0.0;
    for (double v : y)
        mean += v;
    mean /= double(y.size());
    double ssRes = 0.0, ssTot = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        double predicted = 0.0;
        for (int r = 0; r < k; ++r)
            predicted += beta[r] * x[i][r];
        ssRes += (y[i] - predicted) * (y[i] - predicted);
        ssTot += (y[i] - mean) * (y[i] - mean);
    }
    fit.pixelExponent = beta[1];
    fit.knobExponent = knobVaries ? beta[2] : std::nan("");
    fit.rSquared = ssTot > 0.0 ? 1.0 - ssRes / ssTot : std::nan("");
    return fit;
}

std::optional<Options> parseOptions(int argc, char** argv)
{
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::fprintf(stderr, "%s needs a value\n", arg.c_str());
                std::exit(2);
            }
            return argv[++i];
        };
        if (arg == "--quick")
            o.quick = true;
        else if (arg == "--cpu")
            o.cpu = true;
        else if (arg == "--csv")
            o.csv = next();
        else if (arg == "--technique")
            o.technique = next();
        else if (arg == "--repeats")
            o.repeats = std::max(1, std::atoi(next().c_str()));
        else if (arg == "--warmup")
            o.warmup = std::max(0, std::atoi(next().c_str()));
        else {
            std::fprintf(stderr,
                         "unknown argument '%s'\nusage: occlusion_scaling_benchmark [--quick] "
                         "[--csv path] [--repeats n] [--warmup n] [--technique name] [--cpu]\n",
                         arg.c_str());
            return std::nullopt;
        }
    }
    if (o.quick) {
        o.repeats = 1;
        o.warmup = 0;
    }
    return o;
}

//! The technique's direction / sample knob and the three values to time.
std::pair<std::string, std::vector<std::int64_t>> chooseKnob(const config::ParamSchema& schema,
                                                             bool quick)
{
    for (const char* name : {"slices", "directions", "samples", "samples_per_pixel"}) {
        const config::ParamSpec* spec = schema.find(name);
        if (!spec || spec->type != config::ParamType::Int)
            continue;
        const std::int64_t d = std::get<std::int64_t>(spec->defaultValue);
        std::vector<std::int64_t> values;
        for (std::int64_t v : {d / 2, d, d * 2})
            values.push_back(
                std::clamp<std::int64_t>(v, std::int64_t(spec->min), std::int64_t(spec->max)));
        if (quick)
            values.pop_back();
        values.erase(std::unique(values.begin(), values.end()), values.end());
        return {name, values};
    }
    return {"", {0}};
}

} // namespace

int main(int argc, char** argv)
{
    const auto parsed = parseOptions(argc, argv);
    if (!parsed)
        return 2;
    const Options options = *parsed;
    const std::vector<std::pair<int, int>> sizes =
        options.quick ? std::vector<std::pair<int, int>>{{32, 18}, {64, 36}}
                      : std::vector<std::pair<int, int>>{{320, 180}, {640, 360}, {1280, 720}};

    std::unique_ptr<gpu::Context> gpu;
    if (!options.cpu)
        gpu = std::make_unique<gpu::Context>();
    const char* source =
        options.cpu ? "CPU wall time of the C++ path"
                    : experiment::toString(experiment::chooseGpuTimeSource(gpu->getDeviceInfo()));
    std::printf("device: %s\ntime: %s, median of %d (warm-up %d, first use excluded)\n",
                options.cpu ? "CPU (plain C++ path)" : gpu->getDeviceInfo().name.c_str(), source,
                options.repeats, options.warmup);

    std::vector<occlusion::SyntheticGBuffer> gbuffers;
    for (const auto& [w, h] : sizes)
        gbuffers.push_back(makeGBuffer(w, h));

    metrics::TimingOptions timing;
    timing.repeats = options.repeats;
    timing.warmup = options.warmup;

    // Times one configuration of a technique on G-buffer s.
    const auto timeRun = [&](const plugin::TechniqueEntry& entry, const config::ParamSet& params,
                             std::size_t s) {
        auto technique = entry.create(params);
        auto& occlusion = dynamic_cast<plugin::OcclusionTechnique&>(*technique);
        const occlusion::SyntheticGBuffer& g = gbuffers[s];
        plugin::OcclusionInput input;
        input.linearDepth = &g.depth;
        input.normal = &g.normal;
        input.projection = g.projection;
        input.view = g.view;
        input.gpu = gpu.get();
        plugin::OcclusionOutput out;
        if (gpu)
            gpu->takeRunLog();
        const metrics::TimingReport report = metrics::measure(timing, [&] {
            occlusion.compute(input, out);
            return gpu ? experiment::collectGpuPassTimes(*gpu) : metrics::GpuPassTimes{};
        });
        Run run;
        run.technique = entry.info.name;
        run.width = sizes[s].first;
        run.height = sizes[s].second;
        run.cpuMedianMs = report.cpuMs.median;
        run.firstUseMs = report.firstUseMs;
        const double gpuMs = report.gpuTotalMedianMs();
        if (gpu && std::isfinite(gpuMs)) {
            run.timeMs = gpuMs;
            double iqr = 0.0;
            for (const auto& [label, stats] : report.gpuMs)
                iqr += stats.iqr();
            run.iqrMs = iqr;
        } else {
            run.timeMs = report.cpuMs.median;
            run.iqrMs = report.cpuMs.iqr();
        }
        return run;
    };

    std::vector<Run> runs;
    std::vector<std::pair<std::string, Fit>> fits;
    // The radius axis: each technique with a `radius` at the largest size and its default knob,
    // radius default / 2, default, default x 2 (LSAO's claim is a cost independent of it).
    struct RadiusRun {
        std::string technique;
        double radius = 0.0;
        Run run;
    };
    std::vector<RadiusRun> radiusRuns;
    std::printf("\n%-14s %-11s %5s %11s %12s %10s %12s\n", "technique", "knob", "value", "size",
                "time ms", "iqr ms", "first use ms");
    for (const plugin::TechniqueEntry* entry : plugin::builtinRegistry().techniques("occlusion")) {
        if (!options.technique.empty() && entry->info.name != options.technique)
            continue;
        const auto [knob, values] = chooseKnob(entry->schema, options.quick);
        std::vector<Run> techniqueRuns;
        for (std::int64_t value : values) {
            config::ParamSet params = config::ParamSet::defaultsOf(entry->schema);
            if (!knob.empty())
                params.set(knob, value);
            for (std::size_t s = 0; s < sizes.size(); ++s) {
                Run run = timeRun(*entry, params, s);
                run.knob = knob;
                run.knobValue = value;
                std::printf("%-14s %-11s %5lld %5dx%-5d %12.3f %10.3f %12.3f\n",
                            run.technique.c_str(), knob.empty() ? "-" : knob.c_str(),
                            (long long)value, run.width, run.height, run.timeMs, run.iqrMs,
                            run.firstUseMs);
                std::fflush(stdout);
                techniqueRuns.push_back(run);
            }
        }
        fits.emplace_back(entry->info.name, fitExponents(techniqueRuns));
        runs.insert(runs.end(), techniqueRuns.begin(), techniqueRuns.end());
        if (const config::ParamSpec* spec = entry->schema.find("radius");
            spec != nullptr && spec->type == config::ParamType::Float) {
            const double d = std::get<double>(spec->defaultValue);
            for (const double factor : {0.5, 1.0, 2.0}) {
                const double radius = std::clamp(d * factor, spec->min, spec->max);
                config::ParamSet params = config::ParamSet::defaultsOf(entry->schema);
                params.set("radius", radius);
                radiusRuns.push_back({entry->info.name, radius, timeRun(*entry, params, sizes.size() - 1)});
            }
        }
    }

    std::printf("\ntime against the radius (%dx%d, default knob), slope of log(time) on log(radius):\n",
                sizes.back().first, sizes.back().second);
    std::printf("%-14s %10s %10s %10s %8s\n", "technique", "r / 2 ms", "r ms", "2r ms", "slope");
    for (std::size_t i = 0; i + 2 < radiusRuns.size(); i += 3) {
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        for (std::size_t k = i; k < i + 3; ++k) {
            const double lx = std::log(radiusRuns[k].radius), ly = std::log(radiusRuns[k].run.timeMs);
            sx += lx;
            sy += ly;
            sxx += lx * lx;
            sxy += lx * ly;
        }
        const double slope = (3 * sxy - sx * sy) / (3 * sxx - sx * sx);
        std::printf("%-14s %10.3f %10.3f %10.3f %8.3f\n", radiusRuns[i].technique.c_str(),
                    radiusRuns[i].run.timeMs, radiusRuns[i + 1].run.timeMs, radiusRuns[i + 2].run.timeMs, slope);
    }

    std::printf("\nleast squares log(time) = a + b log(pixels) + c log(knob):\n");
    std::printf("%-14s %-11s %12s %14s %8s\n", "technique", "knob", "b (pixels)", "c (knob)",
                "R^2");
    for (const auto& [name, fit] : fits) {
        std::string knob;
        for (const Run& r : runs)
            if (r.technique == name)
                knob = r.knob;
        std::printf("%-14s %-11s %12.3f %14.3f %8.4f\n", name.c_str(),
                    knob.empty() ? "-" : knob.c_str(), fit.pixelExponent, fit.knobExponent,
                    fit.rSquared);
    }

    if (!options.csv.empty()) {
        std::ofstream csv(options.csv);
        if (!csv) {
            std::fprintf(stderr, "cannot write %s\n", options.csv.c_str());
            return 1;
        }
        csv << "technique,knob,knob_value,width,height,pixels,time_ms,iqr_ms,cpu_median_ms,first_"
               "use_ms,"
               "time_source,exponent_pixels,exponent_knob,r_squared\n";
        for (const Run& r : runs) {
            Fit fit;
            for (const auto& [name, f] : fits)
                if (name == r.technique)
                    fit = f;
            csv << r.technique << ',' << r.knob << ',' << r.knobValue << ',' << r.width << ','
                << r.height << ',' << std::int64_t(r.width) * r.height << ',' << r.timeMs << ','
                << r.iqrMs << ',' << r.cpuMedianMs << ',' << r.firstUseMs << ",\"" << source
                << "\"," << fit.pixelExponent << ',' << fit.knobExponent << ',' << fit.rSquared
                << '\n';
        }
        std::printf("\nwrote %s\n", options.csv.c_str());
    }
    return runs.empty() ? 1 : 0;
}
