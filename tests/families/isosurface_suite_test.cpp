// The isosurface family suite: every registered isosurface technique, at its default parameters,
// through the family's stress cases (families/isosurface/stress_cases.cpp, the same ones
// `rtlab stress` runs): closed shapes that must come out watertight and outward-oriented, the
// two-sided distance to the exact surface of a sphere and a torus within the cell diagonal,
// exact zeros on sample planes, spacings of 1e-5 and origins at 1e6, features thinner than a cell,
// a positive field (empty mesh) and random spheres. A new isosurface plugin inherits them by
// registering.

#include "stress_suite.h"

#include <gtest/gtest.h>

using namespace rtlab;

namespace {

class IsosurfaceSuite : public testing::TestWithParam<const plugin::TechniqueEntry*> {};

TEST_P(IsosurfaceSuite, EveryStressCasePasses)
{
    test::expectEveryStressCasePasses(plugin::builtinRegistry(), *GetParam(), nullptr);
}

std::vector<const plugin::TechniqueEntry*> getIsosurfaceTechniques()
{
    return plugin::builtinRegistry().techniques("isosurface");
}

INSTANTIATE_TEST_SUITE_P(Registered, IsosurfaceSuite, testing::ValuesIn(getIsosurfaceTechniques()),
                         [](const auto& info) { return info.param->info.name; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(IsosurfaceSuite);

} // namespace
