// Temporal metrics (metrics/temporal_metrics.h) on constructed camera paths whose answers are
// exact: surfaces are analytic, values are functions of the surface point, and the techniques'
// errors are constructed.

#include "metrics/temporal_metrics.h"

#include "core/error.h"
#include "plugin/screen_space.h"
#include "scene/camera.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/trigonometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <random>

using namespace rtlab;

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

//! A surface hit: distance along the ray and the value the images hold there.
struct Hit {
    float t = kInfF;
    int surface = -1;
};
using SceneHit = std::function<Hit(const glm::vec3& origin, const glm::vec3& dir)>;
using SurfaceValue = std::function<float(const glm::vec3& point, int surface)>;

struct FrameImages {
    Image<float> depth;
    Image<float> technique;
    Image<float> reference;
    glm::mat4 projection{1.0f};
    glm::mat4 view{1.0f};

    metrics::TemporalFrame getFrame() const
    {
        metrics::TemporalFrame f;
        f.technique = &technique;
        f.reference = &reference;
        f.linearDepth = &depth;
        f.projection = projection;
        f.view = view;
        return f;
    }
};

//! Renders `scene` from `camera`: the depth, the reference value(point) and the technique
//! value(point) + error(x, y).
FrameImages render(const scene::Camera& camera, int w, int h, const SceneHit& scene,
                   const SurfaceValue& value, const std::function<float(int, int)>& error)
{
    FrameImages f;
    f.projection = camera.projectionMatrix(float(w) / float(h), glm::vec2(0.0f), {w, h});
    f.view = camera.viewMatrix();
    f.depth = Image<float>(w, h, kInfF);
    f.technique = Image<float>(w, h, 1.0f);
    f.reference = Image<float>(w, h, 1.0f);
    const auto sp = plugin::ScreenProjection::fromMatrix(f.projection, w, h);
    const glm::mat3 toWorld = glm::transpose(glm::mat3(f.view));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::vec3 viewDir = sp.toView({x + 0.5f, y + 0.5f}, 1.0f);
            const glm::vec3 dir = toWorld * viewDir; // t = 1 at linear depth 1
            const Hit hit = scene(camera.position, dir);
            if (!(hit.t > 0.0f && std::isfinite(hit.t)))
                continue;
            const glm::vec3 p = camera.position + hit.t * dir;
            f.depth.at(x, y) = hit.t; // dir has unit depth
            f.reference.at(x, y) = value(p, hit.surface);
            f.technique.at(x, y) = value(p, hit.surface) + error(x, y);
        }
    return f;
}

//! Infinite planes and an optional rectangle: nearest hit.
std::optional<float> intersectPlane(const glm::vec3& o, const glm::vec3& d, const glm::vec3& p,
                                    const glm::vec3& n)
{
    const float den = glm::dot(d, n);
    if (std::abs(den) < 1e-9f)
        return std::nullopt;
    const float t = glm::dot(p - o, n) / den;
    return t > 0.0f ? std::optional<float>(t) : std::nullopt;
}

Hit hitFloorAndWall(const glm::vec3& o, const glm::vec3& d)
{
    Hit best;
    if (auto t = intersectPlane(o, d, {0, 0, 0}, {0, 1, 0}); t && *t < best.t)
        best = {*t, 0};
    if (auto t = intersectPlane(o, d, {0, 0, -6}, {0, 0, 1}); t && *t < best.t)
        best = {*t, 1};
    return best;
}

float pattern(const glm::vec3& p, int surface)
{
    return 0.5f + 0.3f * std::sin(2.0f * p.x) * std::cos(1.5f * p.z + p.y) + 0.05f * surface;
}

scene::Camera makeCamera(glm::vec3 position, glm::vec3 target)
{
    scene::Camera c;
    c.position = position;
    c.target = target;
    c.verticalFovDegrees = 50.0f;
    c.nearPlane = 0.05f;
    c.farPlane = 100.0f;
    return c;
}

auto noError = [](int, int) { return 0.0f; };

TEST(TemporalMetrics, StaticCameraIdenticalFramesIsZero)
{
    const auto camera = makeCamera({0, 1.5f, 2}, {0, 0.5f, -3});
    const FrameImages a = render(camera, 48, 32, hitFloorAndWall, pattern, [](int x, int y) {
        return 0.01f * float((x * 7 + y * 3) % 5); // a technique error constant over time
    });
    const auto c = metrics::computeTemporalChange(a.getFrame(), a.getFrame());
    EXPECT_EQ(c.techniqueChangeRms, 0.0);
    EXPECT_EQ(c.referenceChangeRms, 0.0);
    EXPECT_EQ(c.flickerRms, 0.0);
    EXPECT_EQ(c.usedPixels, c.candidatePixels);
    EXPECT_EQ(c.usedShare, 1.0);
    EXPECT_EQ(c.offScreenPixels + c.disoccludedPixels, 0);
    EXPECT_TRUE(std::isnan(c.referenceNoiseFloorRms));
}

TEST(TemporalMetrics, AlternatingNoiseFlickersByTwiceItsAmplitude)
{
    // T_t = R + (-1)^t e s(p), s(p) = +-1 at random per pixel: every used pixel's error changes
    // by exactly 2e, so flicker = technique change = 2e, reference change = 0.
    const float e = 0.03f;
    const auto camera = makeCamera({0, 1.5f, 2}, {0, 0.5f, -3});
    std::mt19937 rng(3);
    Image<float> sign(40, 30);
    for (float& s : sign.pixels)
        s = (rng() & 1u) ? 1.0f : -1.0f;
    std::vector<FrameImages> frames;
    for (int t = 0; t < 5; ++t)
        frames.push_back(render(camera, 40, 30, hitFloorAndWall, pattern,
                                [&](int x, int y) { return (t % 2 ? -e : e) * sign.at(x, y); }));
    std::vector<metrics::TemporalFrame> path;
    for (const auto& f : frames)
        path.push_back(f.getFrame());
    const auto summary = metrics::computeTemporalSummary(path);
    ASSERT_EQ(summary.pairs.size(), 4u);
    for (const auto& c : summary.pairs) {
        EXPECT_NEAR(c.flickerRms, 2.0 * e, 1e-6);
        EXPECT_NEAR(c.techniqueChangeRms, 2.0 * e, 1e-6);
        EXPECT_EQ(c.referenceChangeRms, 0.0);
        EXPECT_EQ(c.usedShare, 1.0);
    }
    EXPECT_NEAR(summary.pooled.flickerRms, 2.0 * e, 1e-6);
    EXPECT_EQ(summary.pooled.usedPixels, 4 * summary.pairs[0].usedPixels);

    // The same with a moving camera and a uniform alternating error: the true change (the
    // pattern under a new view, nearest fetch) is nonzero but explained, flicker stays 2e.
    std::vector<FrameImages> moving;
    for (int t = 0; t < 3; ++t)
        moving.push_back(render(makeCamera({0.1f * t, 1.5f, 2 - 0.07f * t}, {0.05f * t, 0.5f, -3}),
                                64, 40, hitFloorAndWall, pattern,
                                [&](int, int) { return t % 2 ? -e : e; }));
    for (int t = 1; t < 3; ++t) {
        const auto c =
            metrics::computeTemporalChange(moving[t - 1].getFrame(), moving[t].getFrame());
        EXPECT_NEAR(c.flickerRms, 2.0 * e, 1e-6);
        EXPECT_GT(c.referenceChangeRms, 1e-3) << "nearest fetch of a varying pattern";
        EXPECT_GT(c.usedShare, 0.8);
    }
}

TEST(TemporalMetrics, CorrectlyReprojectedTranslationIsZero)
{
    // A fronto-parallel plane at depth 5 and a sideways move by exactly 3 pixels: every pixel
    // of frame t sees the very point that a pixel centre of frame t-1 saw, so any value
    // attached to the surface reprojects exactly; the first 3 columns' points were off-screen.
    const int w = 48, h = 32;
    const float depth = 5.0f;
    const float pixel = 2.0f * depth * std::tan(glm::radians(25.0f)) / float(h);
    auto plane = [&](const glm::vec3& o, const glm::vec3& d) {
        Hit hit;
        if (auto t = intersectPlane(o, d, {0, 0, -depth}, {0, 0, 1}))
            hit = {*t, 0};
        return hit;
    };
    const auto a = render(makeCamera({0, 0, 0}, {0, 0, -1}), w, h, plane, pattern, noError);
    const glm::vec3 shift(-3.0f * pixel, 0, 0); // the image content moves right by 3 pixels
    const auto b =
        render(makeCamera(shift, shift + glm::vec3(0, 0, -1)), w, h, plane, pattern, noError);
    const auto c = metrics::computeTemporalChange(a.getFrame(), b.getFrame());
    EXPECT_EQ(c.candidatePixels, w * h);
    EXPECT_EQ(c.offScreenPixels, 3 * h);
    EXPECT_EQ(c.disoccludedPixels, 0);
    EXPECT_EQ(c.usedPixels, (w - 3) * h);
    EXPECT_LE(c.techniqueChangeRms, 1e-5);
    EXPECT_LE(c.referenceChangeRms, 1e-5);
    EXPECT_LE(c.flickerRms, 1e-5);

    // A constant image under a general move (translation and turn) over the floor and wall.
    auto constant = [](const glm::vec3&, int) { return 0.7f; };
    const auto p =
        render(makeCamera({0, 1.5f, 2}, {0, 0.5f, -3}), 64, 40, hitFloorAndWall, constant, noError);
    const auto q = render(makeCamera({0.4f, 1.6f, 1.5f}, {0.3f, 0.4f, -3}), 64, 40, hitFloorAndWall,
                          constant, noError);
    const auto general = metrics::computeTemporalChange(p.getFrame(), q.getFrame());
    EXPECT_EQ(general.techniqueChangeRms, 0.0);
    EXPECT_EQ(general.flickerRms, 0.0);
    EXPECT_GT(general.usedShare, 0.8);
    EXPECT_EQ(general.usedPixels + general.offScreenPixels + general.disoccludedPixels,
              general.candidatePixels);
}

TEST(TemporalMetrics, DisoccludedPixelsAreExcluded)
{
    // A plate (value 0.2) 2 units in front of a wall (value 0.8); the camera moves sideways and
    // reveals wall that the plate hid. Values are attached to the surfaces, so every pixel that
    // is kept changes by exactly 0; a revealed wall pixel fetched from the plate would change by
    // 0.6. With an enormous tolerance those pixels are kept and the change shows.
    auto scene = [](const glm::vec3& o, const glm::vec3& d) {
        Hit best;
        if (auto t = intersectPlane(o, d, {0, 0, -6}, {0, 0, 1}))
            best = {*t, 1};
        if (auto t = intersectPlane(o, d, {0, 0, -2}, {0, 0, 1})) {
            const glm::vec3 p = o + *t * d;
            if (std::abs(p.x) < 0.5f && std::abs(p.y) < 0.5f && *t < best.t)
                best = {*t, 0};
        }
        return best;
    };
    auto value = [](const glm::vec3&, int surface) { return surface == 0 ? 0.2f : 0.8f; };
    const auto a = render(makeCamera({0, 0, 0}, {0, 0, -1}), 64, 48, scene, value, noError);
    const auto b = render(makeCamera({0.3f, 0, 0}, {0.3f, 0, -1}), 64, 48, scene, value, noError);
    metrics::TemporalChangeImages images;
    const auto c = metrics::computeTemporalChange(a.getFrame(), b.getFrame(), {}, &images);
    EXPECT_GT(c.disoccludedPixels, 20);
    EXPECT_EQ(c.techniqueChangeRms, 0.0);
    EXPECT_EQ(c.flickerRms, 0.0);
    EXPECT_EQ(c.usedPixels + c.offScreenPixels + c.disoccludedPixels, c.candidatePixels);
    int marked = 0;
    for (float v : images.techniqueChange.pixels)
        marked += std::isnan(v) ? 1 : 0;
    EXPECT_EQ(marked, 64 * 48 - c.usedPixels);

    metrics::TemporalOptions loose;
    loose.depthTolerance = 1e9;
    const auto kept = metrics::computeTemporalChange(a.getFrame(), b.getFrame(), loose);
    EXPECT_EQ(kept.disoccludedPixels, 0);
    EXPECT_GT(kept.techniqueChangeRms, 0.05);
    EXPECT_EQ(kept.flickerRms, 0.0) << "technique and reference change alike";
}

TEST(TemporalMetrics, NoiseFloorAndErrors)
{
    const auto camera = makeCamera({0, 1.5f, 2}, {0, 0.5f, -3});
    FrameImages a = render(camera, 16, 12, hitFloorAndWall, pattern, noError);
    const Image<float> se(16, 12, 0.01f);
    auto fa = a.getFrame();
    fa.referenceStdErr = &se;
    const auto c = metrics::computeTemporalChange(fa, fa);
    EXPECT_NEAR(c.referenceNoiseFloorRms, std::sqrt(2.0) * 0.01, 1e-7);

    const Image<float> small(8, 12, 0.0f);
    auto bad = a.getFrame();
    bad.technique = &small;
    EXPECT_THROW(metrics::computeTemporalChange(fa, bad), Error);
    bad = a.getFrame();
    bad.reference = nullptr;
    EXPECT_THROW(metrics::computeTemporalChange(bad, fa), Error);
    metrics::TemporalOptions zero;
    zero.depthTolerance = 0.0;
    EXPECT_THROW(metrics::computeTemporalChange(fa, fa, zero), Error);
    EXPECT_TRUE(std::isnan(metrics::computeTemporalSummary({fa}).pooled.flickerRms));
}

} // namespace
