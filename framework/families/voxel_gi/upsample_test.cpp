// Reduced-resolution gathering: representative pixels, constant fields stay constant, and light
// does not bleed across a depth discontinuity.

#include "families/voxel_gi/upsample.h"

#include "core/error.h"

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
