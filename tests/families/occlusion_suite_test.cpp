// The occlusion family suite: every registered occlusion technique, on its plain C++ path and on
// Vulkan (lavapipe here), through the family's stress cases (families/occlusion/stress_cases.cpp,
// the same ones `rtlab stress` runs): analytic G-buffers with floors, walls, depth steps, grazing
// planes, extreme depths, degenerate normals, tiny and odd image sizes, extreme and random radii;
// every output finite and in range; an unoccluded plane gives 1; the crease of a floor and a wall
// against its integrated closed form; more radius never brightens. A new occlusion plugin
// inherits them by registering. Below them, the checks of the GPU read-back contract.

#include "families/occlusion/occlusion.h"
#include "families/occlusion/synthetic_gbuffer.h"
#include "gpu/context.h"
#include "render/image_transfer.h"
#include "stress_suite.h"

#include <gtest/gtest.h>

#include <memory>

using namespace rtlab;

namespace {

using occlusion::SyntheticGBuffer;

class OcclusionSuite : public testing::TestWithParam<const plugin::TechniqueEntry*> {
protected:
    std::unique_ptr<plugin::Technique> make(double radius) const
    {
        config::ParamSet p = config::ParamSet::defaultsOf(GetParam()->schema);
        if (GetParam()->schema.find("radius"))
            p.set("radius", radius);
        return GetParam()->create(p);
    }
    static gpu::Context& context()
    {
        static gpu::Context ctx(gpu::ContextOptions{.enableValidation = true, .echoValidationMessages = true});
        return ctx;
    }
};

void run(plugin::Technique& t, const SyntheticGBuffer& g, gpu::Context* gpu, plugin::OcclusionOutput& out)
{
    dynamic_cast<plugin::OcclusionTechnique&>(t).compute(occlusion::makeOcclusionInput(g, gpu), out);
}

SyntheticGBuffer makeCrease() { return occlusion::makePlanesGBuffer(64, 48, 60.0f, occlusion::makeFloorAndWall()); }

} // namespace

TEST_P(OcclusionSuite, EveryStressCasePassesCpuAndGpu)
{
    test::expectEveryStressCasePasses(plugin::builtinRegistry(), *GetParam(), &context());
    EXPECT_EQ(context().getValidationLog()->countMessages(), 0u);
}

TEST_P(OcclusionSuite, ResultsLeftOnTheGpuReadBackToWhatAnImmediateReadBackGives)
{
    // A technique that keeps its result on the GPU (outputsOnGpu) must give, with the read-back
    // deferred, GPU images of the G-buffer's size holding exactly its CPU outputs, and readBack()
    // must return bitwise what compute() with the read-back gives. Others must refuse readBack().
    const SyntheticGBuffer g = makeCrease();
    auto t = make(0.5);
    auto& technique = dynamic_cast<plugin::OcclusionTechnique&>(*t);
    if (!technique.outputsOnGpu()) {
        plugin::OcclusionOutput out;
        EXPECT_THROW(technique.readBack(out), Error);
        return;
    }
    plugin::OcclusionOutput immediate, deferred;
    run(technique, g, &context(), immediate);
    plugin::OcclusionInput in = occlusion::makeOcclusionInput(g, &context());
    in.readBack = false;
    technique.compute(in, deferred);
    EXPECT_TRUE(deferred.ambient.pixels.empty()) << "nothing read back yet";
    const plugin::OcclusionGpuOutput images = deferred.gpu;
    ASSERT_TRUE(images.ambient != nullptr || images.coneVisibility[0] != nullptr);
    technique.readBack(deferred);
    EXPECT_EQ(deferred.ambient.pixels, immediate.ambient.pixels);
    EXPECT_EQ(deferred.coneAperture.pixels, immediate.coneAperture.pixels);
    EXPECT_TRUE(deferred.bentNormal.pixels == immediate.bentNormal.pixels);
    ASSERT_EQ(deferred.coneVisibility.size(), immediate.coneVisibility.size());
    for (std::size_t k = 0; k < deferred.coneVisibility.size(); ++k)
        EXPECT_EQ(deferred.coneVisibility[k].pixels, immediate.coneVisibility[k].pixels) << k;
    if (images.ambient != nullptr) {
        const Image<float> onGpu = render::downloadScalar(*images.ambient, 0);
        ASSERT_EQ(onGpu.width, g.depth.width);
        ASSERT_EQ(onGpu.height, g.depth.height);
        EXPECT_EQ(onGpu.pixels, immediate.ambient.pixels);
    }
    if (images.coneVisibility[0] != nullptr) {
        ASSERT_EQ(immediate.coneVisibility.size(), 16u);
        for (std::size_t k = 0; k < 16; ++k) {
            ASSERT_NE(images.coneVisibility[k / 4], nullptr);
            const Image<float> onGpu = render::downloadScalar(*images.coneVisibility[k / 4], int(k % 4));
            EXPECT_EQ(onGpu.pixels, immediate.coneVisibility[k].pixels) << "cone " << k;
        }
    }
}

static std::vector<const plugin::TechniqueEntry*> getOcclusionTechniques()
{
    return plugin::builtinRegistry().techniques("occlusion");
}

INSTANTIATE_TEST_SUITE_P(Registered, OcclusionSuite, testing::ValuesIn(getOcclusionTechniques()),
                         [](const auto& info) { return info.param->info.name; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(OcclusionSuite);
