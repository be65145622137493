// The voxel_gi family suite: every registered voxel_gi technique, at its defaults, through the
// family's stress cases (families/voxel_gi/stress_cases.cpp, the same ones `rtlab stress` runs):
// an empty scene, a single voxel's worth of geometry, a fully solid region, a room 1e5 from the
// origin, geometry on voxel boundaries, a light inside a wall and random boxes must give finite,
// non-negative irradiance that is zero where a pixel has no surface; a closed dark room gives
// exactly zero; a white furnace its closed form within the stated tolerance; 1 and 2 threads the
// same bits; a technique with a resident Vulkan gather gives from the G-buffer's GPU images what
// it gives from the uploaded G-buffer (on lavapipe here, with Vulkan validation on). A new
// voxel_gi plugin inherits them by registering.

#include "stress_suite.h"

#include "gpu/context.h"

#include <gtest/gtest.h>

using namespace rtlab;

namespace {

std::vector<const plugin::TechniqueEntry*> getTechniques()
{
    return plugin::builtinRegistry().techniques("voxel_gi");
}

TEST(VoxelGiSuite, EveryTechniqueIsRegistered)
{
    EXPECT_GE(getTechniques().size(), 2u); // cascades and the path-traced baseline at least
}

class VoxelGiSuite : public testing::TestWithParam<const plugin::TechniqueEntry*> {
public:
    static gpu::Context& context()
    {
        static gpu::Context ctx(gpu::ContextOptions{.enableValidation = true, .echoValidationMessages = true});
        return ctx;
    }
};

TEST_P(VoxelGiSuite, EveryStressCasePasses)
{
    test::expectEveryStressCasePasses(plugin::builtinRegistry(), *GetParam(), &context());
    EXPECT_EQ(context().getValidationLog()->countMessages(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Registered, VoxelGiSuite, testing::ValuesIn(getTechniques()),
                         [](const auto& info) { return info.param->info.name; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(VoxelGiSuite);

} // namespace
