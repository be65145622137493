// The shared cone machinery: irradiance weights (exact for a constant radiance, zero below the
// surface), the sky per cone, the march's step-length-corrected opacity, and the sky a cone sees
// past the voxels (sky start, the surface's own occupancy, emitters).

#include "families/voxel_gi/cone_tracing.h"

#include "core/error.h"

#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

using namespace rtlab;
using namespace rtlab::voxelgi;

namespace {

TEST(ConeTracing, IrradianceWeightsIntegrateAConstantRadianceExactly)
{
    const ConeSet cones = ConeSet::make(29.0);
    const glm::dvec3 normals[] = {{0, 1, 0}, {1, 0, 0}, {0, 0, -1},
                                  glm::normalize(glm::dvec3(1, 2, 3)),
                                  glm::normalize(glm::dvec3(-0.3, -1, 0.2))};
    for (const auto& n : normals) {
        const auto w = computeIrradianceWeights(cones, n);
        double sum = 0.0;
        for (int k = 0; k < kConeCount; ++k) {
            EXPECT_GE(w[std::size_t(k)], 0.0);
            // A cone whose axis is below the surface gets no weight.
            if (glm::dot(cones.directions[std::size_t(k)], n) <= 0.0) {
                EXPECT_EQ(w[std::size_t(k)], 0.0);
            }
            sum += w[std::size_t(k)];
        }
        // E = pi L for a constant radiance L (the furnace).
        EXPECT_NEAR(sum, glm::pi<double>(), 1e-12);
    }
    EXPECT_THROW(ConeSet::make(0.0), Error);
    EXPECT_THROW(ConeSet::make(90.0), Error);
}

TEST(ConeTracing, SkyPerConeOfAConstantSkyIsThatConstant)
{
    scene::Sky sky;
    sky.kind = scene::Sky::Kind::Constant;
    sky.constant = {0.5f, 1.0f, 2.0f};
    const auto perCone = computeSkyPerCone(sky, ConeSet::make(29.0));
    for (const auto& l : perCone) {
        EXPECT_NEAR(l.x, 0.5f, 1e-6f);
        EXPECT_NEAR(l.z, 2.0f, 1e-6f);
    }
    // A gradient sky: a cone wholly above the horizon sees more than any cone lower down.
    sky.kind = scene::Sky::Kind::Gradient;
    sky.zenith = glm::vec3(1.0f);
    sky.horizon = glm::vec3(0.2f);
    sky.ground = glm::vec3(0.0f);
    const ConeSet cones = ConeSet::make(29.0);
    const auto g = computeSkyPerCone(sky, cones);
    for (int k = 0; k < kConeCount; ++k)
        for (int j = 0; j < kConeCount; ++j)
            if (cones.directions[std::size_t(k)].y > 0.5 &&
                cones.directions[std::size_t(k)].y > cones.directions[std::size_t(j)].y + 0.3) {
                EXPECT_GT(g[std::size_t(k)].x, g[std::size_t(j)].x);
            }
}

// A homogeneous medium of occupancy `alpha` per voxel of size 1, radiance 1 in field kDirect,
// that ends at distance `extent`.
struct UniformMedium {
    float alpha = 0.2f;
    double extent = 8.0;
    bool sample(const glm::dvec3& p, double, int, const glm::dvec3&, ConeSample& out) const
    {
        if (glm::length(p) > extent)
            return false;
        out = ConeSample{};
        out.alpha = alpha;
        out.depth = computeOpticalDepth(alpha);
        out.light[kDirect] = glm::vec3(alpha); // premultiplied radiance 1
        out.voxelSize = 1.0;
        return true;
    }
};

TEST(ConeTracing, OpacityIsCorrectedForTheStepLength)
{
    // A ray (zero aperture) through 4 voxels of the medium: transmittance (1 - a)^4 whatever the
    // step, and the radiance gathered is 1 - transmittance (radiance 1 everywhere).
    const UniformMedium medium{0.2f, 1e9};
    for (const double stepScale : {0.125, 0.25, 0.5, 1.0}) {
        ConeMarchSettings s;
        s.tanHalfAngle = 0.0;
        s.stepScale = stepScale;
        s.maxDistance = 4.0;
        const ConeResult r = marchCone(medium, glm::dvec3(0.0), glm::dvec3(1, 0, 0), 0, s);
        const double expected = std::pow(1.0 - double(medium.alpha), 4.0);
        EXPECT_NEAR(r.transmittance, expected, 1e-12) << stepScale;
        EXPECT_NEAR(r.light[kDirect].x, 1.0 - expected, 1e-6) << stepScale;
        EXPECT_FALSE(r.escaped);
    }
}

TEST(ConeTracing, AConeThatLeavesTheStructureEscapes)
{
    const UniformMedium medium{0.0f, 3.0};
    ConeMarchSettings s;
    s.tanHalfAngle = 0.5;
    const ConeResult r = marchCone(medium, glm::dvec3(0.0), glm::dvec3(0, 1, 0), 0, s);
    EXPECT_TRUE(r.escaped);
    EXPECT_EQ(r.transmittance, 1.0);
    // An opaque medium stops the cone at the opacity limit, before the end.
    const UniformMedium opaque{1.0f, 1e9};
    const ConeResult o = marchCone(opaque, glm::dvec3(0.0), glm::dvec3(0, 1, 0), 0, s);
    EXPECT_FALSE(o.escaped);
    EXPECT_LE(o.transmittance, 1.0 - s.maxOpacity);
    EXPECT_TRUE(std::isfinite(o.light[kDirect].x));
}

// A wall of occupancy 1 (emission `emission` in field kEmission) across [wall, wall + 1] in y,
// nothing else, the structure ending at y = 10.
struct Wall {
    double wall = 2.0;
    glm::vec3 emission{0.0f};
    bool sample(const glm::dvec3& p, double, int, const glm::dvec3&, ConeSample& out) const
    {
        if (p.y > 10.0)
            return false;
        out = ConeSample{};
        out.voxelSize = 0.25;
        if (p.y >= wall && p.y <= wall + 1.0) {
            out.alpha = 1.0f;
            out.depth = kOpaqueOpticalDepth;
            out.light[kEmission] = emission;
        }
        return true;
    }
};

TEST(ConeTracing, TheSkyIsSeenPastTheVoxelsFromSkyStartOn)
{
    const glm::vec3 skyOfCone(2.0f, 1.0f, 0.5f);
    ConeMarchSettings s;
    s.tanHalfAngle = 0.0;
    s.stepScale = 0.5;
    s.sky = true;
    // No occluder: the sky, whole.
    const ConeResult open = marchCone(Wall{20.0}, glm::dvec3(0.0), glm::dvec3(0, 1, 0), 0, s);
    EXPECT_TRUE(open.skyEscaped);
    EXPECT_EQ(computeConeSkyRadiance(open, skyOfCone), skyOfCone);
    // A wall beyond sky start hides it, and its emission is seen instead.
    const Wall glowing{2.0, glm::vec3(3.0f)};
    const ConeResult hidden = marchCone(glowing, glm::dvec3(0.0), glm::dvec3(0, 1, 0), 0, s);
    EXPECT_FALSE(hidden.skyEscaped);
    // (premultiplied emission 3 composited until the wall is opaque: 3 times its occupancy)
    EXPECT_NEAR(computeConeSkyRadiance(hidden, skyOfCone).x, 3.0 * (1.0 - hidden.transmittance), 1e-5);
    EXPECT_GT(hidden.transmittance, 0.0);
    EXPECT_LE(hidden.transmittance, 1.0 - s.maxOpacity);
    // The same wall nearer than sky start is the occlusion family's: the cone's light stops
    // there, its sky does not (it marches on to the end of the structure).
    s.skyStartDistance = 4.0;
    const ConeResult near = marchCone(Wall{2.0}, glm::dvec3(0.0), glm::dvec3(0, 1, 0), 0, s);
    EXPECT_FALSE(near.escaped);
    EXPECT_TRUE(near.skyEscaped);
    EXPECT_LE(near.transmittance, 1.0 - s.maxOpacity);
    EXPECT_EQ(near.skyTransmittance, 1.0);
    EXPECT_EQ(computeConeSkyRadiance(near, skyOfCone), skyOfCone);
}

TEST(ConeTracing, TheSurfaceTheConeLeavesDoesNotHideItsSky)
{
    // A cone along a floor's plane at height h reads the floor's own occupancy as the filtered
    // half-space, (1 - h/v)^2 / 2 for 0 <= h <= v (cone_tracing.h); a floor read exactly so is
    // taken out, and the sky stays whole. A real occluder on top of it still hides the sky.
    struct Floor {
        double extra = 0.0; // occupancy of something else in every sample (union)
        bool sample(const glm::dvec3& p, double, int, const glm::dvec3&, ConeSample& out) const
        {
            if (p.x > 20.0)
                return false;
            out = ConeSample{};
            out.voxelSize = 1.0;
            const double u = std::clamp(p.y / out.voxelSize, 0.0, 1.0);
            const double floor = 0.5 * (1.0 - u) * (1.0 - u);
            out.alpha = float(1.0 - (1.0 - floor) * (1.0 - extra));
            // The floor's opaque voxels weigh `floor`; the rest is the other occupancy's.
            out.depth = float(floor) * kOpaqueOpticalDepth + computeOpticalDepth(float(extra));
            return true;
        }
    };
    ConeMarchSettings s;
    s.tanHalfAngle = 0.0;
    s.sky = true;
    s.skyPlaneNormal = glm::dvec3(0, 1, 0);
    s.skyPlaneHeight = 0.25;
    const glm::dvec3 along(1, 0, 0);
    const ConeResult own = marchCone(Floor{}, glm::dvec3(0, 0.25, 0), along, 0, s);
    EXPECT_TRUE(own.skyEscaped);
    EXPECT_NEAR(own.skyTransmittance, 1.0, 1e-5); // float occupancy
    EXPECT_LT(own.transmittance, 0.5);           // the light's march still sees it
    const ConeResult other = marchCone(Floor{0.1}, glm::dvec3(0, 0.25, 0), along, 0, s);
    // 0.1 more per voxel along 20 voxels: (1 - 0.1)^20 of the sky left.
    EXPECT_NEAR(other.skyTransmittance, std::pow(0.9, 20.0), 0.01);
    // The same in optical depth (the floor's opaque voxels weigh b, the rest -ln(0.9) a voxel).
    s.skyOpticalDepth = true;
    EXPECT_NEAR(marchCone(Floor{}, glm::dvec3(0, 0.25, 0), along, 0, s).skyTransmittance, 1.0, 1e-5);
    EXPECT_NEAR(marchCone(Floor{0.1}, glm::dvec3(0, 0.25, 0), along, 0, s).skyTransmittance,
                std::pow(0.9, 20.0), 0.01);
}

// One opaque voxel (size 1, centre y = 3.5) in an empty lattice, sampled as the structures do:
// occupancy and optical depth interpolated with the same tent weights along y.
struct OpaqueVoxel {
    bool sample(const glm::dvec3& p, double, int, const glm::dvec3&, ConeSample& out) const
    {
        if (p.y > 10.0)
            return false;
        out = ConeSample{};
        out.voxelSize = 1.0;
        const double w = std::max(0.0, 1.0 - std::abs(p.y - 3.5));
        out.alpha = float(w);
        out.depth = float(w) * kOpaqueOpticalDepth;
        return true;
    }
};

TEST(ConeTracing, TheSkyDoesNotLeakThroughAnOpaqueVoxelWhateverTheSamplesOffset)
{
    // Half-voxel steps whose samples fall at offsets 0, 1/8, 1/4, 3/8 from the voxel's centre: the
    // light's occupancy lets up to sqrt(0.75 * 0.25 * 0.25 * 0.75) = 0.1875 through (offset 1/4,
    // the samples read 0.25, 0.75, 0.75, 0.25: the leak cone_tracing.h describes); the sky's
    // optical depth crosses the voxel's whole, exp(-kOpaqueOpticalDepth) = 1e-4, at every offset
    // (the tent weights at half-voxel spacing sum to 2, times the step's half voxel).
    ConeMarchSettings s;
    s.tanHalfAngle = 0.0;
    s.stepScale = 0.5;
    s.maxOpacity = 0.999999;
    s.sky = true;
    s.skyOpticalDepth = true;
    double worstLight = 0.0;
    for (const double offset : {0.0, 0.125, 0.25, 0.375}) {
        const glm::dvec3 origin(0.0, offset, 0.0); // samples at y = offset + k/2
        const ConeResult r = marchCone(OpaqueVoxel{}, origin, glm::dvec3(0, 1, 0), 0, s);
        EXPECT_NEAR(r.skyTransmittance, 1e-4, 1e-6) << offset;
        worstLight = std::max(worstLight, r.transmittance);
    }
    EXPECT_NEAR(worstLight, 0.1875, 1e-6);
}

} // namespace
