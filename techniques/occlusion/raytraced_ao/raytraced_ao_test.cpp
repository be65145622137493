// raytraced_ao: the ground truth's estimator at N rays, with its own seed.

#include "raytraced_ao.h"

#include "reference/reference.h"
#include "scene/procedural.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <gtest/gtest.h>

#include <cmath>

namespace rtlab::occlusion {
namespace {

struct Frame {
    scene::RenderScene scene;
    scene::GBuffer g;
    Image<glm::vec3> viewNormal;
    plugin::OcclusionInput input;
};

Frame makeFrame(int width, int height)
{
    Frame f;
    const scene::Scene testbed = scene::makeProceduralScene("ao_testbed");
    f.scene = testbed.buildRenderScene(0);
    f.g = reference::castGBuffer(f.scene, testbed.camera, width, height);
    f.viewNormal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    const glm::mat3 toView(f.g.view);
    for (std::size_t i = 0; i < f.viewNormal.pixels.size(); ++i)
        if (glm::dot(f.g.normal.pixels[i], f.g.normal.pixels[i]) > 0.0f)
            f.viewNormal.pixels[i] = glm::normalize(toView * f.g.normal.pixels[i]);
    f.input.linearDepth = &f.g.depth;
    f.input.normal = &f.viewNormal;
    f.input.projection = f.g.projection;
    f.input.view = f.g.view;
    f.input.scene = &f.scene;
    f.input.gbuffer = &f.g;
    return f;
}

config::ParamSet makeParams(int spp, double radius = 0.5)
{
    config::ParamSet p = config::ParamSet::defaultsOf(RaytracedAo::declareParams());
    p.set("samples_per_pixel", std::int64_t(spp));
    p.set("radius", radius);
    return p;
}

double rmse(const Image<float>& a, const Image<float>& b, const scene::GBuffer& g)
{
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
        if (g.materialId.pixels[i] != scene::kNoMaterial) {
            sum += double(a.pixels[i] - b.pixels[i]) * double(a.pixels[i] - b.pixels[i]);
            ++n;
        }
    return std::sqrt(sum / double(n));
}

TEST(RaytracedAo, ConvergesToTheGroundTruthAsOneOverTheSquareRootOfTheRays)
{
    Frame f = makeFrame(48, 32);
    reference::ReferenceSettings settings;
    settings.quantity = reference::Quantity::Ao;
    settings.radius = 0.5;
    settings.targetStdErr = 0.002;
    settings.maxSamples = 4096;
    settings.useCache = false;
    const auto truth = reference::computeReference(f.scene, f.g, settings);
    std::vector<double> errors;
    for (int spp : {4, 64}) {
        RaytracedAo technique(makeParams(spp));
        plugin::OcclusionOutput out;
        technique.compute(f.input, out);
        errors.push_back(rmse(out.ambient, truth.occlusion, f.g));
        for (float a : out.ambient.pixels)
            ASSERT_TRUE(a >= 0.0f && a <= 1.0f);
    }
    // 16x the rays: the Monte Carlo error falls by ~4 (Sobol points do at least as well); a factor
    // of 2.5 leaves room for the ground truth's own noise (standard error <= 0.002).
    EXPECT_LT(errors[1], errors[0] / 2.5) << errors[0] << " -> " << errors[1];
    EXPECT_GT(errors[0], 0.0) << "4 rays cannot be exact";
}

TEST(RaytracedAo, UsesOtherDirectionsThanTheGroundTruthAndNewOnesEachFrame)
{
    Frame f = makeFrame(24, 16);
    reference::ReferenceSettings settings;
    settings.quantity = reference::Quantity::Ao;
    settings.radius = 0.5;
    settings.maxSamples = 8;
    settings.batchSize = 8;
    settings.targetStdErr = 0.0;
    settings.targetRelStdErr = 0.0;
    settings.useCache = false;
    const auto sameBudgetTruth =
        reference::computeReference(f.scene, f.g, settings); // seed 0, 8 rays
    RaytracedAo technique(makeParams(8));
    plugin::OcclusionOutput frame0, frame1;
    technique.compute(f.input, frame0);
    f.input.frameIndex = 1;
    technique.compute(f.input, frame1);
    EXPECT_GT(rmse(frame0.ambient, sameBudgetTruth.occlusion, f.g), 0.0)
        << "correlated with the ground truth";
    EXPECT_GT(rmse(frame0.ambient, frame1.ambient, f.g), 0.0)
        << "the same directions in two frames";
}

TEST(RaytracedAo, BentNormalsAreUnitViewSpaceVectorsInTheNormalsHemisphere)
{
    Frame f = makeFrame(24, 16);
    RaytracedAo technique(makeParams(16));
    plugin::OcclusionOutput out;
    technique.compute(f.input, out);
    for (std::size_t i = 0; i < out.bentNormal.pixels.size(); ++i) {
        const glm::vec3 n = f.viewNormal.pixels[i], b = out.bentNormal.pixels[i];
        if (glm::dot(n, n) == 0.0f)
            continue;
        EXPECT_NEAR(glm::length(b), 1.0f, 1e-4f);
        EXPECT_GT(glm::dot(b, n), -1e-4f);
        EXPECT_GE(out.coneAperture.pixels[i], 0.0f);
        EXPECT_LE(out.coneAperture.pixels[i], 1.5708f);
    }
}

TEST(RaytracedAo, WithoutASceneTracesTheDepthBuffer)
{
    Frame f = makeFrame(24, 16);
    f.input.scene = nullptr;
    f.input.gbuffer = nullptr;
    RaytracedAo technique(makeParams(8));
    plugin::OcclusionOutput out;
    technique.compute(f.input, out);
    double traced = 0;
    for (const auto& [name, value] : technique.counters())
        if (name == "traced_scene")
            traced = value;
    EXPECT_EQ(traced, 0.0);
    for (float a : out.ambient.pixels)
        ASSERT_TRUE(std::isfinite(a) && a >= 0.0f && a <= 1.0f);
}

} // namespace
} // namespace rtlab::occlusion
