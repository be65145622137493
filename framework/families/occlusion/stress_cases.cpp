// The occlusion family's stress cases (plugin/stress.h): analytic G-buffers (synthetic_gbuffer.h)
// with floors, walls, depth steps, grazing planes, extreme depths, degenerate normals, tiny and odd
// image sizes, extreme radii and random planes; and two closed forms: a plane with nothing in
// front (ambient exactly 1) and the crease of a floor and a wall, whose occlusion is integrated
// from the planes with the technique's own definition. Every case runs the C++ path and, when a
// Vulkan device is given, the GPU path.

#include "families/occlusion/stress_cases.h"

#include "core/error.h"

#include "families/occlusion/occlusion.h"
#include "families/occlusion/synthetic_gbuffer.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>

namespace rtlab::occlusion {
namespace {

using plugin::StressCase;
using plugin::StressOutcome;
using plugin::StressSettings;
using plugin::TechniqueEntry;

//! A fresh instance at its defaults, with `radius` when the technique has that parameter.
std::unique_ptr<plugin::OcclusionTechnique> createTechnique(const TechniqueEntry& entry,
                                                            std::optional<double> radius)
{
    config::ParamSet p = config::ParamSet::defaultsOf(entry.schema);
    if (radius && entry.schema.find("radius"))
        p.set("radius", *radius);
    std::unique_ptr<plugin::Technique> t = entry.create(p);
    auto* o = dynamic_cast<plugin::OcclusionTechnique*>(t.get());
    if (o == nullptr)
        throw Error(entry.info.name + " is not an occlusion technique");
    t.release();
    return std::unique_ptr<plugin::OcclusionTechnique>(o);
}

plugin::OcclusionOutput compute(plugin::OcclusionTechnique& t, const SyntheticGBuffer& g,
                                gpu::Context* gpu)
{
    plugin::OcclusionOutput out;
    t.compute(makeOcclusionInput(g, gpu), out);
    return out;
}

//! The devices a case runs on: the C++ path, and Vulkan when given.
std::vector<std::pair<gpu::Context*, const char*>> getDevices(const StressSettings& s)
{
    std::vector<std::pair<gpu::Context*, const char*>> d{{nullptr, "cpu"}};
    if (s.gpu != nullptr)
        d.emplace_back(s.gpu, "gpu");
    return d;
}

bool isFinite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

//! The family's range: ambient and cone visibilities finite in [0, 1]; bent normals finite and
//! unit (1e-3) on surface pixels; apertures finite in [0, pi/2]; every image of the G-buffer's size.
void checkOutput(const plugin::OcclusionOutput& out, const SyntheticGBuffer& g, const std::string& what,
                 StressOutcome& o)
{
    const std::size_t n = g.depth.pixels.size();
    if (out.ambient.width != g.depth.width || out.ambient.height != g.depth.height) {
        o.fail(what + ": ambient is " + std::to_string(out.ambient.width) + "x" +
               std::to_string(out.ambient.height) + ", not the G-buffer's size");
        return;
    }
    std::size_t bad = 0, range = 0, count = n;
    for (float a : out.ambient.pixels) {
        bad += std::isfinite(a) ? 0 : 1;
        range += std::isfinite(a) && (a < 0.0f || a > 1.0f) ? 1 : 0;
    }
    if (out.bentNormal.size() == out.ambient.size())
        for (std::size_t i = 0; i < n; ++i) {
            const glm::vec3 b = out.bentNormal.pixels[i];
            count += 3;
            if (!isFinite(b)) {
                ++bad;
                continue;
            }
            const bool surface = std::isfinite(g.depth.pixels[i]) &&
                                 glm::dot(g.normal.pixels[i], g.normal.pixels[i]) > 0.0f;
            if (surface && std::abs(glm::length(b) - 1.0f) > 1e-3f)
                ++range;
        }
    if (out.coneAperture.size() == out.ambient.size())
        for (float c : out.coneAperture.pixels) {
            ++count;
            bad += std::isfinite(c) ? 0 : 1;
            range += std::isfinite(c) && (c < 0.0f || c > glm::half_pi<float>() + 1e-5f) ? 1 : 0;
        }
    for (const auto& v : out.coneVisibility) {
        if (v.size() != out.ambient.size())
            o.fail(what + ": a cone visibility image is not of the G-buffer's size");
        for (float x : v.pixels) {
            ++count;
            bad += std::isfinite(x) ? 0 : 1;
            range += std::isfinite(x) && (x < 0.0f || x > 1.0f) ? 1 : 0;
        }
    }
    o.countValues(count, bad, range, what);
}

//! A case that checks the range of every output at radii 0, 0.5 and 1e6 on every device. With
//! `invalidInput`, refusing the input with rtlab::Error (a clear error) also passes.
StressCase makeRangeCase(std::string name, std::string group, std::string description,
                         std::function<SyntheticGBuffer()> make, bool invalidInput = false)
{
    return {std::move(name), std::move(group),
            std::move(description) + "; every output in range at radius 0, 0.5, 1e6" +
                (invalidInput ? " (or a clear error: rtlab::Error, std::invalid_argument)" : ""),
            [make, invalidInput](const TechniqueEntry& e, const StressSettings& s) {
                StressOutcome o;
                const SyntheticGBuffer g = make();
                for (double radius : {0.0, 0.5, 1e6})
                    for (const auto& [gpu, device] : getDevices(s)) {
                        auto t = createTechnique(e, radius);
                        const auto run = [&] {
                            checkOutput(compute(*t, g, gpu), g,
                                        std::string(device) + " radius " + std::to_string(radius), o);
                        };
                        if (invalidInput)
                            plugin::runOrRefuse(o, run);
                        else
                            run();
                    }
                return o;
            }};
}

SyntheticGBuffer makeFloorAndWallGBuffer(int w, int h)
{
    return makePlanesGBuffer(w, h, 60.0f, makeFloorAndWall());
}

//! Random planes in front of the camera, a random image size, field of view and radius.
StressCase makeRandomCase(int index)
{
    return {"random_planes_" + std::to_string(index), "random",
            "1-3 random planes (distance 1e-2 to 1e4), image 1-80 x 1-60, field of view 10-120 "
            "degrees, radius 1e-3 to 1e4, from the seed; every output in range",
            [index](const TechniqueEntry& e, const StressSettings& s) {
                std::mt19937_64 rng(s.seed * 1000003u + std::uint64_t(index));
                std::uniform_real_distribution<double> unit(0.0, 1.0);
                auto logUniform = [&](double lo, double hi) {
                    return std::exp(std::log(lo) + unit(rng) * (std::log(hi) - std::log(lo)));
                };
                const int w = 1 + int(unit(rng) * 80.0), h = 1 + int(unit(rng) * 60.0);
                const float fov = float(10.0 + 110.0 * unit(rng));
                std::vector<Plane> planes;
                const int count = 1 + int(unit(rng) * 3.0);
                for (int i = 0; i < count; ++i) {
                    // A point ahead of the camera (within 60 degrees of -z) and any orientation.
                    glm::dvec3 dir(unit(rng) - 0.5, unit(rng) - 0.5, -1.0);
                    dir = glm::normalize(dir);
                    glm::dvec3 n(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
                    if (glm::dot(n, n) < 1e-6)
                        n = {0, 0, 1};
                    planes.push_back({dir * logUniform(1e-2, 1e4), glm::normalize(n)});
                }
                const double radius = logUniform(1e-3, 1e4);
                const SyntheticGBuffer g = makePlanesGBuffer(w, h, fov, planes);
                StressOutcome o;
                for (const auto& [gpu, device] : getDevices(s)) {
                    auto t = createTechnique(e, radius);
                    checkOutput(compute(*t, g, gpu), g,
                                std::string(device) + " " + std::to_string(w) + "x" + std::to_string(h) +
                                    " radius " + std::to_string(radius),
                                o);
                }
                return o;
            }};
}

//! The mean of `image` over the surface pixels of each image row of g that has any.
std::vector<double> computeRowMeans(const Image<float>& image, const SyntheticGBuffer& g)
{
    std::vector<double> means;
    for (int y = 0; y < g.depth.height; ++y) {
        double sum = 0.0;
        int n = 0;
        for (int x = 0; x < g.depth.width; ++x)
            if (std::isfinite(g.depth.at(x, y))) {
                sum += image.at(x, y);
                ++n;
            }
        if (n > 0)
            means.push_back(sum / n);
    }
    return means;
}

} // namespace

std::vector<plugin::StressCase> makeOcclusionStressCases()
{
    std::vector<StressCase> cases;
    cases.push_back(makeRangeCase("floor_and_wall_64x48", "geometry", "a floor and a wall (a crease), 64x48",
                                  [] { return makeFloorAndWallGBuffer(64, 48); }));
    cases.push_back(makeRangeCase("odd_size_17x9", "size", "the crease at 17x9",
                                  [] { return makeFloorAndWallGBuffer(17, 9); }));
    cases.push_back(makeRangeCase("one_pixel", "size", "the crease at 1x1",
                                  [] { return makeFloorAndWallGBuffer(1, 1); }));
    cases.push_back(makeRangeCase(
        "depth_discontinuity", "geometry", "a box face at depth 1 in front of a wall at depth 50", [] {
            return makeSyntheticGBuffer(48, 32, 60.0f, [](const glm::vec3& d) {
                if (std::abs(d.x / -d.z) < 0.2f && std::abs(d.y / -d.z) < 0.2f)
                    return hitPlanes(d, {{{0, 0, -1}, {0, 0, 1}}});
                return hitPlanes(d, {{{0, 0, -50}, {0, 0, 1}}});
            });
        }));
    cases.push_back(makeRangeCase("grazing_plane", "geometry", "a plane seen almost edge-on", [] {
        return makePlanesGBuffer(40, 30, 60.0f, {{{0, -0.05, 0}, glm::normalize(glm::dvec3(0, 1, 0.02))}});
    }));
    cases.push_back(makeRangeCase("near_plane_extreme", "scale", "a wall at depth 1e-3 (the near plane)", [] {
        return makePlanesGBuffer(32, 24, 60.0f, {{{0, 0, -1e-3}, {0, 0, 1}}});
    }));
    cases.push_back(makeRangeCase("far_plane_extreme", "scale", "a slope 1e5 away", [] {
        return makePlanesGBuffer(32, 24, 60.0f, {{{0, -1e4, -1e5}, glm::normalize(glm::dvec3(0, 1, 1))}});
    }));
    cases.push_back(makeRangeCase("zero_length_normals", "degenerate", "the crease with every third normal zero", [] {
        SyntheticGBuffer g = makeFloorAndWallGBuffer(32, 24);
        for (std::size_t i = 0; i < g.normal.pixels.size(); i += 3)
            g.normal.pixels[i] = glm::vec3(0.0f);
        return g;
    }));
    cases.push_back(makeRangeCase(
        "non_finite_inputs", "degenerate",
        "the crease with NaN depths (every 5th pixel), -inf depths (every 11th) and NaN normals (every 7th)",
        [] {
            SyntheticGBuffer g = makeFloorAndWallGBuffer(32, 24);
            const float nan = std::numeric_limits<float>::quiet_NaN();
            for (std::size_t i = 0; i < g.depth.pixels.size(); ++i) {
                if (i % 5 == 0)
                    g.depth.pixels[i] = nan;
                else if (i % 11 == 1)
                    g.depth.pixels[i] = -std::numeric_limits<float>::infinity();
                if (i % 7 == 3)
                    g.normal.pixels[i] = glm::vec3(nan);
            }
            return g;
        },
        true));
    cases.push_back(makeRangeCase("all_sky", "degenerate", "no surface at all", [] {
        return makeSyntheticGBuffer(16, 12, 60.0f,
                                    [](const glm::vec3&) { return std::pair{-1.0f, glm::vec3(0)}; });
    }));

    cases.push_back(
        {"unoccluded_plane", "closed_form",
         "a plane facing the camera with nothing in front: ambient 1 and bent normal = normal (1e-3, "
         "float accumulation)",
         [](const TechniqueEntry& e, const StressSettings& s) {
             const SyntheticGBuffer g = makePlanesGBuffer(32, 24, 50.0f, {{{0, 0, -3}, {0, 0, 1}}});
             StressOutcome o;
             for (const auto& [gpu, device] : getDevices(s)) {
                 auto t = createTechnique(e, 0.5);
                 const plugin::OcclusionOutput out = compute(*t, g, gpu);
                 checkOutput(out, g, device, o);
                 if (out.ambient.size() != g.depth.size())
                     continue;
                 double worst = 0.0;
                 for (std::size_t i = 0; i < out.ambient.pixels.size(); ++i) {
                     worst = std::max(worst, std::abs(double(out.ambient.pixels[i]) - 1.0));
                     if (out.bentNormal.size() == out.ambient.size())
                         worst = std::max(worst, std::abs(glm::dot(out.bentNormal.pixels[i], glm::vec3(0, 0, 1)) - 1.0));
                 }
                 o.compare(worst, 1e-3, std::string(device) + ": |ambient - 1| or |bent . n - 1|");
             }
             return o;
         }});

    cases.push_back(
        {"crease_closed_form", "closed_form",
         "a floor and a wall at radius 1.5 against the occlusion of the two planes, integrated with the technique's "
         "own definition: the error of the row means at most half that of answering 1 (no occlusion)",
         [](const TechniqueEntry& e, const StressSettings& s) {
             // Both planes are invariant along x, so the exact occlusion is the same along every
             // image row of one plane, and the case compares row means: that averages out the
             // noise of stochastic estimators (one row holds 64 pixels) and keeps what a stub
             // gets wrong, the occlusion profile across the crease. The tolerance: the RMSE of
             // the row means is at most half that of answering 1 everywhere, so a technique must
             // recover at least half the occlusion that the planes cast (a technique that finds
             // none scores exactly 1). The integration's own error (a 64 x 64 midpoint rule,
             // checked against Embree in occlusion_closed_form_test) is below 5e-3 per pixel.
             const SyntheticGBuffer g = makeFloorAndWallGBuffer(64, 48);
             StressOutcome o;
             for (const auto& [gpu, device] : getDevices(s)) {
                 auto t = createTechnique(e, 1.5);
                 const plugin::OcclusionOutput out = compute(*t, g, gpu);
                 checkOutput(out, g, device, o);
                 if (out.ambient.size() != g.depth.size())
                     continue;
                 const Image<float> truth = integrateOcclusion(g, makeFloorAndWall(), t->definition());
                 const std::vector<double> exact = computeRowMeans(truth, g);
                 const std::vector<double> estimate = computeRowMeans(out.ambient, g);
                 double signal = 0.0, error = 0.0, bias = 0.0;
                 for (std::size_t r = 0; r < exact.size(); ++r) {
                     signal += (1.0 - exact[r]) * (1.0 - exact[r]);
                     error += (estimate[r] - exact[r]) * (estimate[r] - exact[r]);
                     bias += estimate[r] - exact[r];
                 }
                 const double rows = double(std::max<std::size_t>(exact.size(), 1));
                 signal = std::sqrt(signal / rows);
                 error = std::sqrt(error / rows);
                 o.check(signal > 0.05, std::string(device) + ": the planes cast too little occlusion to test");
                 o.compare(error / signal, 0.5,
                           std::string(device) + ": RMSE of the row means / that of answering 1 (mean signed error " +
                               std::to_string(bias / rows) + ", RMSE of answering 1 " + std::to_string(signal) + ")");
             }
             return o;
         }});

    cases.push_back(
        {"more_radius_never_brightens", "closed_form",
         "the crease at radius 0, 0.1, 0.5, 2: the mean ambient never grows (1e-3) and is 1 at radius 0",
         [](const TechniqueEntry& e, const StressSettings&) {
             // Per-pixel monotonicity is not required of estimators that rotate samples; the
             // image mean must hold to 1e-3 (float accumulation). The radii stop at 2 (half the
             // distance to the wall): beyond that, a fixed number of samples spread over a larger
             // radius may miss near occluders, which is sampling error the studies measure.
             const SyntheticGBuffer g = makeFloorAndWallGBuffer(64, 48);
             StressOutcome o;
             double previous = 1.0;
             for (double radius : {0.0, 0.1, 0.5, 2.0}) {
                 auto t = createTechnique(e, radius);
                 const plugin::OcclusionOutput out = compute(*t, g, nullptr);
                 checkOutput(out, g, "radius " + std::to_string(radius), o);
                 if (out.ambient.size() != g.depth.size())
                     return o;
                 double mean = 0.0;
                 for (float a : out.ambient.pixels)
                     mean += a;
                 mean /= double(out.ambient.size());
                 if (radius == 0.0)
                     o.compare(std::abs(mean - 1.0), 1e-3, "radius 0 leaves nothing to occlude: |mean - 1|");
                 else
                     o.compare(std::max(0.0, mean - previous), 1e-3,
                               "mean ambient grew from the smaller radius at radius " + std::to_string(radius));
                 previous = mean;
             }
             return o;
         }});

    for (int i = 0; i < 4; ++i)
        cases.push_back(makeRandomCase(i));
    return cases;
}

} // namespace rtlab::occlusion
