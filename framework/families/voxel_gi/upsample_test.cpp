// Reduced-resolution gathering: representative pixels, constant fields stay constant, and light
// does not bleed across a depth discontinuity.

#include "families/voxel_gi/upsample.h"

#include "core/error.h"
#include "families/voxel_gi/cone_tracing.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

using namespace rtlab;
using namespace rtlab::voxelgi;

namespace {

// A 13 x 9 G-buffer: the left part (x < 6) a floor at depth 1, the right part a wall at depth 5
// facing the camera; row 0 is sky.
scene::GBuffer makeStep()
{
    scene::GBuffer g;
    g.width = 13;
    g.height = 9;
    g.depth = Image<float>(13, 9, INFINITY);
    g.position = Image<glm::vec3>(13, 9, glm::vec3(0.0f));
    g.normal = Image<glm::vec3>(13, 9, glm::vec3(0.0f));
    g.materialId = Image<std::uint32_t>(13, 9, scene::kNoMaterial);
    for (int y = 1; y < 9; ++y)
        for (int x = 0; x < 13; ++x) {
            const bool near = x < 6;
            g.depth.at(x, y) = near ? 1.0f : 5.0f;
            g.position.at(x, y) = near ? glm::vec3(0.1f * x, 0.0f, -1.0f - 0.1f * y)
                                       : glm::vec3(0.1f * x, 0.1f * y, -5.0f);
            g.normal.at(x, y) = near ? glm::vec3(0, 1, 0) : glm::vec3(0, 0, 1);
            g.materialId.at(x, y) = 0;
        }
    return g;
}

TEST(Upsample, RepresentativesAreSurfacePixelsOfTheirBlock)
{
    const scene::GBuffer g = makeStep();
    const ReducedGBuffer r = reduceGBuffer(g, 4);
    ASSERT_EQ(r.gbuffer.width, 4);
    ASSERT_EQ(r.gbuffer.height, 3);
    for (int by = 0; by < 3; ++by)
        for (int bx = 0; bx < 4; ++bx) {
            const int p = r.representative[std::size_t(by * 4 + bx)];
            ASSERT_GE(p, 0);
            EXPECT_EQ((p % 13) / 4, bx);
            EXPECT_EQ((p / 13) / 4, by);
            EXPECT_TRUE(g.hasSurface(p % 13, p / 13));
        }
    EXPECT_THROW(reduceGBuffer(g, 0), Error);
}

TEST(Upsample, LightDoesNotBleedAcrossADepthDiscontinuity)
{
    const scene::GBuffer g = makeStep();
    const ReducedGBuffer r = reduceGBuffer(g, 4);
    // Irradiance 1 on the floor, 3 on the wall, at the representative pixels.
    Image<glm::vec3> low(r.gbuffer.width, r.gbuffer.height, glm::vec3(0.0f));
    for (std::size_t i = 0; i < low.pixels.size(); ++i)
        low.pixels[i] = glm::vec3((r.representative[i] % 13) < 6 ? 1.0f : 3.0f);
    const Image<glm::vec3> up = upsampleIrradiance(low, r, g);
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 13; ++x) {
            const float expected = !g.hasSurface(x, y) ? 0.0f : (x < 6 ? 1.0f : 3.0f);
            EXPECT_NEAR(up.at(x, y).x, expected, 1e-4f) << x << " " << y;
        }
    // Factor 1 is the identity.
    const ReducedGBuffer same = reduceGBuffer(g, 1);
    Image<glm::vec3> values(13, 9, glm::vec3(0.5f));
    EXPECT_EQ(upsampleIrradiance(values, same, g).pixels, values.pixels);
}

} // namespace

namespace {

TEST(CapsuleOcclusion, CoversAConeItFillsAndNothingBehindOrAside)
{
    const double cone = 0.5; // radians
    const glm::dvec3 p(0.0), up(0.0, 1.0, 0.0);
    // A vertical capsule straight above, wide enough to fill the cone: radius 2 at 3 (the cap's
    // half-angle asin(2/3) = 0.73 > 0.5).
    EXPECT_NEAR(computeCapsuleConeOcclusion(p, up, cone, {0, 3, -1}, {0, 3, 1}, 2.0f), 1.0, 1e-12);
    // Behind the cone (below the point) and far aside: nothing.
    EXPECT_EQ(computeCapsuleConeOcclusion(p, up, cone, {-1, -3, 0}, {1, -3, 0}, 0.5f), 0.0);
    EXPECT_EQ(computeCapsuleConeOcclusion(p, up, cone, {10, 0, -1}, {10, 0, 1}, 0.5f), 0.0);
    // The point on the capsule's own surface: its character is not occluded by itself.
    EXPECT_EQ(computeCapsuleConeOcclusion(p, up, cone, {0.3, -1, 0}, {0.3, 1, 0}, 0.3f), 0.0);
    // Farther away hides less, and the share stays in [0, 1].
    double previous = 1.0;
    for (const double d : {1.5, 2.0, 3.0, 5.0, 10.0, 40.0}) {
        const double o = computeCapsuleConeOcclusion(p, up, cone, {-1, d, 0}, {1, d, 0}, 0.4f);
        EXPECT_GE(o, 0.0);
        EXPECT_LE(o, previous + 1e-12) << d;
        previous = o;
    }
    EXPECT_LT(previous, 0.01);
}

// A floor at y = 0 seen from above: w x h pixels 0.25 apart, normals up, depth 2.
scene::GBuffer makeFloor(int w, int h)
{
    scene::GBuffer g;
    g.width = w;
    g.height = h;
    g.depth = Image<float>(w, h, 2.0f);
    g.position = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    g.normal = Image<glm::vec3>(w, h, glm::vec3(0.0f, 1.0f, 0.0f));
    g.materialId = Image<std::uint32_t>(w, h, 0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            g.position.at(x, y) = glm::vec3(-3.0f + 0.25f * x, 0.0f, -2.0f + 0.25f * y);
    return g;
}

// The combine skips the capsule test for cones that miss a capsule's bounding sphere and for
// capsules farther than 40 radii; the result must equal testing every capsule in every cone.
TEST(CapsuleOcclusion, CombineMatchesTestingEveryCapsuleInEveryCone)
{
    const int w = 24, h = 16;
    scene::GBuffer g = makeFloor(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if ((x + y) % 5 == 0) // some tilted normals
                g.normal.at(x, y) = glm::normalize(glm::vec3(0.6f, 1.0f, -0.3f));
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<scene::PosedCapsule> capsules;
    for (int i = 0; i < 12; ++i) {
        scene::PosedCapsule c;
        const glm::vec3 base(-4.0f + 8.0f * unit(rng), 0.1f + 1.5f * unit(rng), -3.0f + 6.0f * unit(rng));
        c.capsule.a = base;
        c.capsule.b = base + glm::vec3(unit(rng) - 0.5f, 1.2f * unit(rng), unit(rng) - 0.5f);
        c.capsule.radius = 0.03f + 0.25f * unit(rng);
        capsules.push_back(c);
    }
    const ReducedGBuffer reduced = reduceGBuffer(g, 1);
    std::vector<glm::vec3> radiance(std::size_t(w * h) * kConeCount);
    for (glm::vec3& r : radiance)
        r = glm::vec3(unit(rng), unit(rng), unit(rng));
    const double half = 0.52;
    ConeCombineInputs in;
    in.coneRadiance = &radiance;
    in.reduced = &reduced;
    in.full = &g;
    in.capsules = &capsules;
    in.coneHalfAngle = half;
    const Image<glm::vec3> combined = combineCones(in);

    ConeSet cones;
    cones.directions = scene::getConeDirections();
    cones.halfAngle = half;
    cones.tanHalfAngle = std::tan(half);
    int occludedPixels = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::dvec3 p(g.position.at(x, y)), n(g.normal.at(x, y));
            const auto weights = computeIrradianceWeights(cones, n);
            glm::dvec3 e(0.0), open(0.0);
            for (int k = 0; k < kConeCount; ++k) {
                double visible = 1.0;
                for (const auto& c : capsules) {
                    const glm::dvec3 a(c.capsule.a), u = glm::dvec3(c.capsule.b) - a;
                    const glm::dvec3 q = a + std::clamp(glm::dot(p - a, u) / glm::dot(u, u), 0.0, 1.0) * u;
                    if (glm::length(p - q) < 40.0 * double(c.capsule.radius))
                        visible *= 1.0 - computeCapsuleConeOcclusion(p, cones.directions[std::size_t(k)], half,
                                                                     c.capsule.a, c.capsule.b, c.capsule.radius);
                }
                const glm::dvec3 l(radiance[std::size_t(y * w + x) * kConeCount + std::size_t(k)]);
                e += weights[std::size_t(k)] * visible * l;
                open += weights[std::size_t(k)] * l;
            }
            if (glm::length(open - e) > 1e-3)
                ++occludedPixels;
            for (int i = 0; i < 3; ++i) // float output of a double sum: 1e-6 relative
                EXPECT_NEAR(combined.at(x, y)[i], e[i], 1e-6 * std::max(1.0, e[i])) << x << "," << y;
        }
    // The capsules do hide part of the hemisphere for many of the pixels (the test means something).
    EXPECT_GT(occludedPixels, w * h / 4);
}

// The capsules at the traced pixels: with every pixel traced (reduction 1) the visibility
// multiplied into the cone before the combine is the one the combine multiplies after it, so
// both placements agree to float rounding (the cone radiance is stored as float in between:
// 1e-6 relative).
TEST(CapsuleOcclusion, TracedPixelsGiveTheFullCombineWhenEveryPixelIsTraced)
{
    const int w = 24, h = 16;
    const scene::GBuffer g = makeFloor(w, h);
    std::vector<scene::PosedCapsule> capsules(1);
    capsules[0].capsule.a = {0.0f, 0.4f, 0.0f};
    capsules[0].capsule.b = {0.0f, 1.4f, 0.2f};
    capsules[0].capsule.radius = 0.3f;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    // Random cone radiances at the reduced G-buffer's pixels, and the combine's inputs over them.
    const auto randomCones = [&](const ReducedGBuffer& r) {
        std::vector<glm::vec3> cones(std::size_t(r.gbuffer.width * r.gbuffer.height) * kConeCount);
        for (glm::vec3& c : cones)
            c = glm::vec3(unit(rng), unit(rng), unit(rng));
        return cones;
    };
    const auto describe = [&](const ReducedGBuffer& r, const std::vector<glm::vec3>& cones) {
        ConeCombineInputs in;
        in.coneRadiance = &cones;
        in.reduced = &r;
        in.full = &g;
        in.capsules = &capsules;
        in.coneHalfAngle = 0.52;
        return in;
    };
    const ReducedGBuffer reduced = reduceGBuffer(g, 1);
    const std::vector<glm::vec3> radiance = randomCones(reduced);
    ConeCombineInputs in = describe(reduced, radiance);
    const Image<glm::vec3> full = combineCones(in);
    in.capsuleResolution = CapsuleResolution::Traced;
    const Image<glm::vec3> traced = combineCones(in);
    in.capsules = nullptr;
    const Image<glm::vec3> open = combineCones(in);
    int shadowed = 0;
    for (std::size_t i = 0; i < full.pixels.size(); ++i) {
        shadowed += glm::length(open.pixels[i] - full.pixels[i]) > 1e-2f ? 1 : 0;
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(traced.pixels[i][c], full.pixels[i][c],
                        1e-6 * std::max(1.0f, full.pixels[i][c]))
                << i;
    }
    EXPECT_GT(shadowed, 50); // the capsule's shadow covers part of the plane

    // Reduced by 4: the capsule still darkens part of the plane, and no pixel gets more light than
    // without it or less than none.
    const ReducedGBuffer quarter = reduceGBuffer(g, 4);
    const std::vector<glm::vec3> low = randomCones(quarter);
    ConeCombineInputs q = describe(quarter, low);
    q.capsuleResolution = CapsuleResolution::Traced;
    const Image<glm::vec3> quarterTraced = combineCones(q);
    q.capsules = nullptr;
    const Image<glm::vec3> quarterOpen = combineCones(q);
    int darker = 0;
    for (std::size_t i = 0; i < quarterTraced.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            EXPECT_GE(quarterTraced.pixels[i][c], 0.0f);
            EXPECT_LE(quarterTraced.pixels[i][c], quarterOpen.pixels[i][c] * (1.0f + 1e-6f));
            darker += quarterTraced.pixels[i][c] < 0.99f * quarterOpen.pixels[i][c] ? 1 : 0;
        }
    EXPECT_GT(darker, 50);
}

} // namespace
