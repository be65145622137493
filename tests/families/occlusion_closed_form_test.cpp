// The occlusion stress cases' closed form (occlusion::integrateOcclusion: the planes' occlusion
// by a midpoint rule over the hemisphere) against the Embree ground truth of the same quantity on
// a triangle scene holding the same planes (two large boxes), at the same pixels.

#include "families/occlusion/synthetic_gbuffer.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"
#include "reference/reference.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace rtlab;

namespace {

TEST(OcclusionClosedForm, TheCreaseIntegralMatchesEmbreeForEveryQuantity)
{
    // The floor y = -1 and the wall z = -4 as the top and front faces of boxes 2000 units wide:
    // with radius 1.5 nothing beyond them matters.
    scene::RenderScene s;
    const auto m = voxelgi::testing::addMaterial(s, glm::vec3(0.5f));
    voxelgi::testing::addBox(s, {-1000, -2, -1000}, {1000, -1, 1000}, m);
    voxelgi::testing::addBox(s, {-1000, -1000, -5}, {1000, 1000, -4}, m);
    scene::Camera camera;
    camera.position = {0, 0, 0};
    camera.target = {0, 0, -1};
    camera.verticalFovDegrees = 60.0f;
    camera.nearPlane = 1e-3f;
    camera.farPlane = 1e6f;
    const int w = 32, h = 24;
    const scene::GBuffer g = reference::castGBuffer(s, camera, w, h);
    const auto planes = occlusion::makeFloorAndWall();
    // The camera looks down -z from the origin, so world space is view space: the planes'
    // integral at Embree's own G-buffer points and normals.
    const Image<glm::vec3> normals = g.normal;
    struct Quantity {
        plugin::OcclusionDefinition definition;
        reference::Quantity reference;
        reference::Falloff falloff;
    };
    const double radius = 1.5;
    for (const Quantity& q :
         {Quantity{{plugin::OcclusionQuantity::CosineAo, radius}, reference::Quantity::Ao, reference::Falloff::Linear},
          Quantity{{plugin::OcclusionQuantity::UniformAo, radius}, reference::Quantity::AoUniform, reference::Falloff::Linear},
          Quantity{{plugin::OcclusionQuantity::Obscurance, radius, plugin::OcclusionFalloff::Linear},
                   reference::Quantity::Obscurance, reference::Falloff::Linear},
          Quantity{{plugin::OcclusionQuantity::Obscurance, radius, plugin::OcclusionFalloff::Smoothstep},
                   reference::Quantity::Obscurance, reference::Falloff::Smoothstep}}) {
        reference::ReferenceSettings settings;
        settings.quantity = q.reference;
        settings.radius = radius;
        settings.falloff = q.falloff;
        settings.maxSamples = 4096;
        settings.batchSize = 4096;
        settings.targetStdErr = 0.0;
        settings.targetRelStdErr = 0.0;
        settings.useCache = false;
        const reference::ReferenceResult truth = reference::computeReference(s, g, settings);
        const Image<float> integral = occlusion::integrateOcclusion(g.position, normals, planes, q.definition);
        // Per pixel: 4 standard errors of the 4096-sample estimate, plus 5e-3 for the 64 x 64
        // midpoint rule, whose error is concentrated on the few cells the visibility boundary
        // crosses (about 2 k of k^2 cells, each wrong by at most 1 / k^2: 2 / k = 3e-2 at worst,
        // far less where the boundary crosses cells partly). The mean over the image must agree
        // to 2e-3.
        double sumTruth = 0.0, sumIntegral = 0.0, occluded = 0.0;
        for (int i = 0; i < w * h; ++i) {
            const double t = truth.occlusion.pixels[i], v = integral.pixels[i];
            EXPECT_NEAR(v, t, 4.0 * truth.occlusionStdErr.pixels[i] + 5e-3)
                << reference::getQuantityName(q.reference) << " pixel " << i;
            sumTruth += t;
            sumIntegral += v;
            occluded += 1.0 - t;
        }
        EXPECT_NEAR(sumIntegral / (w * h), sumTruth / (w * h), 2e-3) << reference::getQuantityName(q.reference);
        // Not vacuous: the occlusion in the image is 2.5 times the mean's tolerance or more (the
        // obscurances, weighted down by their falloff, hold the least: 0.009 with smoothstep).
        EXPECT_GT(occluded / (w * h), 0.005) << "the crease must hold occlusion to compare";
    }
}

} // namespace
