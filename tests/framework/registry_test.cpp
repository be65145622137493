// The registry and the registration of every compiled-in technique.

#include "plugin/technique.h"
#include "test_registry.h"

#include <gtest/gtest.h>

using namespace rtlab;

TEST(Registry, BuiltinFamiliesArePresent)
{
    const auto& r = plugin::builtinRegistry();
    EXPECT_EQ(r.familyNames(), (std::vector<std::string>{"isosurface", "occlusion", "voxel_gi"}));
}

TEST(Registry, DuplicatesAndUnknownFamiliesAreRejected)
{
    auto r = test::makeTestRegistry();
    EXPECT_THROW(plugin::registerTechnique<test::FakeMesher>(r, "isosurface", "fake_mesher"), std::logic_error);
    EXPECT_THROW(plugin::registerTechnique<test::FakeMesher>(r, "occlusion", "other"), std::logic_error);
    EXPECT_THROW(r.addFamily({.name = "occlusion"}), std::logic_error);
}

TEST(Registry, SchemaRejectsInvalidDefaults)
{
    config::ParamSchema s;
    EXPECT_THROW(s.addInt("n", 0, 1, 10, "", ""), std::logic_error);
    EXPECT_THROW(s.addEnum("m", "c", {"a", "b"}, ""), std::logic_error);
    s.addFloat("x", 1.0, 0.0, 2.0, "", "");
    EXPECT_THROW(s.addFloat("x", 1.0, 0.0, 2.0, "", ""), std::logic_error);
}

// Every technique compiled into rtlab: its defaults are valid, it builds from them, and it
// reports every declared parameter as effective. A new plugin inherits these checks.
class EveryTechnique : public testing::TestWithParam<const plugin::TechniqueEntry*> {};

TEST_P(EveryTechnique, BuildsFromDefaultsAndReportsEffectiveParameters)
{
    const auto* entry = GetParam();
    EXPECT_FALSE(entry->info.summary.empty()) << "a one-line summary is required";
    for (const auto& spec : entry->schema.specs())
        EXPECT_FALSE(spec.doc.empty()) << entry->info.name << "." << spec.name << " needs a doc line";
    const auto technique = entry->create(config::ParamSet::defaultsOf(entry->schema));
    ASSERT_NE(technique, nullptr);
    const auto effective = technique->effectiveParams();
    for (const auto& spec : entry->schema.specs()) {
        ASSERT_TRUE(effective.has(spec.name)) << entry->info.name << " does not report " << spec.name;
        EXPECT_EQ(spec.checkValue(effective.get(spec.name)), "") << entry->info.name << "." << spec.name;
    }
}

static std::vector<const plugin::TechniqueEntry*> allTechniques()
{
    std::vector<const plugin::TechniqueEntry*> all;
    for (const auto& f : plugin::builtinRegistry().familyNames())
        for (const auto* t : plugin::builtinRegistry().techniques(f))
            all.push_back(t);
    return all;
}

INSTANTIATE_TEST_SUITE_P(Registered, EveryTechnique, testing::ValuesIn(allTechniques()),
                         [](const auto& info) { return info.param->info.family + "_" + info.param->info.name; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(EveryTechnique);
