// The stress cases are strict enough that a stub fails them: a registry holding each built-in
// family with one stub technique of the simplest kind that satisfies the family's interface
// and range (occlusion: no occlusion anywhere; isosurface: a closed, outward box around the grid;
// voxel_gi: a constant irradiance, zero and non-zero). Each stub must fail at least one case, and
// the case expected to catch it by name. Also: the runner's selection errors, a thrown technique
// recorded as a failure, and the files `rtlab stress` writes.

#include "core/error.h"
#include "experiment/stress.h"
#include "families/isosurface/isosurface.h"
#include "families/occlusion/occlusion.h"
#include "families/voxel_gi/voxel_gi.h"
#include "report/stress_report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

using namespace rtlab;

namespace {

class StubOcclusion final : public plugin::OcclusionTechnique {
public:
    config::ParamSet effectiveParams() const override { return {}; }
    plugin::OcclusionDefinition definition() const override { return {}; }
    void compute(const plugin::OcclusionInput& in, plugin::OcclusionOutput& out) override
    {
        // Unoccluded everywhere: ambient 1, bent normal = normal (unit where there is a surface).
        out.ambient = Image<float>(in.linearDepth->width, in.linearDepth->height, 1.0f);
        out.bentNormal = *in.normal;
        out.coneAperture = Image<float>(in.linearDepth->width, in.linearDepth->height, 1.5707963f);
    }
};

class StubMesher final : public plugin::IsosurfaceTechnique {
public:
    config::ParamSet effectiveParams() const override { return {}; }
    void extract(const plugin::IsosurfaceInput& in, TriangleMesh& out) override
    {
        // A closed, outward-facing box just inside the grid, whatever the field holds.
        out = TriangleMesh{};
        const SampledField& f = *in.field;
        const glm::dvec3 lo = f.origin + 0.25 * f.spacing;
        const glm::dvec3 hi = f.origin + f.spacing * (glm::dvec3(f.samples - 1) - 0.25);
        for (int i = 0; i < 8; ++i)
            out.positions.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
        out.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                       2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
    }
};

class StubVoxelGi final : public plugin::VoxelGiTechnique {
public:
    explicit StubVoxelGi(float value) : mValue(value) {}
    config::ParamSet effectiveParams() const override { return {}; }
    plugin::VoxelGiDefinition definition() const override { return {}; }
    plugin::VoxelGiStep voxelize(const plugin::VoxelGiFrame&) override { return plugin::VoxelGiStep::done(""); }
    plugin::VoxelGiStep injectLight(const plugin::VoxelGiFrame&) override { return plugin::VoxelGiStep::done(""); }
    void gather(const plugin::VoxelGiInput& in, Image<glm::vec3>& e) override
    {
        const scene::GBuffer& g = *in.gbuffer;
        e = Image<glm::vec3>(g.width, g.height, glm::vec3(0.0f));
        for (int y = 0; y < g.height; ++y)
            for (int x = 0; x < g.width; ++x)
                if (g.hasSurface(x, y))
                    e.at(x, y) = glm::vec3(mValue);
    }
    plugin::VoxelGiMemory memory() const override { return {}; }

private:
    float mValue;
};

class Throwing final : public plugin::IsosurfaceTechnique {
public:
    config::ParamSet effectiveParams() const override { return {}; }
    void extract(const plugin::IsosurfaceInput&, TriangleMesh&) override { throw std::runtime_error("boom"); }
};

//! The built-in families (with their stress cases) and the stubs.
plugin::Registry makeStubRegistry()
{
    plugin::Registry r;
    for (const std::string name : {"occlusion", "isosurface", "voxel_gi"}) {
        plugin::FamilyInfo info = *plugin::builtinRegistry().findFamily(name);
        if (!info.stressCases)
            throw std::logic_error(name + " declares no stress cases");
        r.addFamily(info);
    }
    auto add = [&](std::string family, std::string name, std::function<std::unique_ptr<plugin::Technique>()> make) {
        plugin::TechniqueEntry e;
        e.info.name = std::move(name);
        e.info.family = std::move(family);
        e.create = [make](const config::ParamSet&) { return make(); };
        r.addTechnique(std::move(e));
    };
    add("occlusion", "unoccluded", [] { return std::make_unique<StubOcclusion>(); });
    add("isosurface", "grid_box", [] { return std::make_unique<StubMesher>(); });
    add("isosurface", "throwing", [] { return std::make_unique<Throwing>(); });
    add("voxel_gi", "constant_zero", [] { return std::make_unique<StubVoxelGi>(0.0f); });
    // pi (a + a^2) at a = 0.5: the white furnace's answer everywhere.
    add("voxel_gi", "constant_furnace", [] { return std::make_unique<StubVoxelGi>(float(3.14159265358979 * 0.75)); });
    return r;
}

//! Runs every case of the stub and returns the names of the failed ones.
std::vector<std::string> runStub(const plugin::Registry& registry, const std::string& name)
{
    experiment::StressOptions options;
    options.techniques = {name};
    const auto plan = experiment::planStress(registry, options);
    std::vector<std::string> failed;
    for (const auto& r : experiment::runStress(plan, options))
        if (!r.outcome.passed())
            failed.push_back(r.caseName);
    return failed;
}

bool contains(const std::vector<std::string>& v, const std::string& s)
{
    return std::find(v.begin(), v.end(), s) != v.end();
}

} // namespace

TEST(StressStubs, AnUnoccludedStubFailsTheCreaseClosedForm)
{
    const auto registry = makeStubRegistry();
    const auto failed = runStub(registry, "unoccluded");
    // It is in range everywhere, so only the closed form can catch it.
    EXPECT_TRUE(contains(failed, "crease_closed_form"));
    EXPECT_FALSE(contains(failed, "floor_and_wall_64x48"));
    EXPECT_FALSE(contains(failed, "unoccluded_plane")); // it happens to be right there
}

TEST(StressStubs, AClosedBoxAroundTheGridFailsTheDistanceToTheSurface)
{
    const auto registry = makeStubRegistry();
    const auto failed = runStub(registry, "grid_box");
    // Closed and outward-oriented, so only the distance to the exact surface catches it.
    EXPECT_TRUE(contains(failed, "sphere"));
    EXPECT_TRUE(contains(failed, "torus"));
    EXPECT_FALSE(contains(failed, "box_rotated_off_grid"));
}

TEST(StressStubs, ConstantIrradianceFailsTheDarkRoomOrTheFurnace)
{
    const auto registry = makeStubRegistry();
    const auto zero = runStub(registry, "constant_zero");
    EXPECT_TRUE(contains(zero, "white_furnace"));
    EXPECT_FALSE(contains(zero, "closed_dark_room"));
    const auto furnace = runStub(registry, "constant_furnace");
    EXPECT_TRUE(contains(furnace, "closed_dark_room"));
    EXPECT_FALSE(contains(furnace, "white_furnace"));
}

TEST(StressRunner, AThrowIsAFailureWithItsMessageAndTheOtherCasesStillRun)
{
    const auto registry = makeStubRegistry();
    experiment::StressOptions options;
    options.techniques = {"throwing"};
    const auto plan = experiment::planStress(registry, options);
    const auto records = experiment::runStress(plan, options);
    ASSERT_EQ(records.size(), plan.items.size());
    ASSERT_GT(records.size(), 1u);
    for (const auto& r : records) {
        ASSERT_FALSE(r.outcome.passed()) << r.caseName;
        EXPECT_EQ(r.outcome.failures.front(), "threw: boom");
    }
}

TEST(StressRunner, UnknownNamesAreErrorsListingTheChoices)
{
    const auto registry = makeStubRegistry();
    experiment::StressOptions options;
    options.families = {"occlusoin"};
    try {
        experiment::planStress(registry, options);
        FAIL() << "no error for an unknown family";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("occlusion, isosurface, voxel_gi"), std::string::npos) << e.what();
    }
    options.families = {"isosurface"};
    options.techniques = {"unoccluded"}; // exists, but not in the chosen family
    EXPECT_THROW(experiment::planStress(registry, options), Error);
    options.techniques = {};
    options.cases = {"no_such_case"};
    EXPECT_THROW(experiment::planStress(registry, options), Error);
    options.cases = {"sphere"};
    EXPECT_EQ(experiment::planStress(registry, options).items.size(), 2u); // grid_box and throwing
}

TEST(StressReport, WritesTheTableHeatMapsAndPage)
{
    const auto registry = makeStubRegistry();
    experiment::StressOptions options;
    options.families = {"isosurface"};
    options.cases = {"sphere", "all_positive", "plane_z_on_samples"};
    const auto records = experiment::runStress(experiment::planStress(registry, options), options);
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_stress_report_test";
    std::filesystem::remove_all(dir);
    const auto files = report::writeStressReport(records, dir.string(), "rtlab stress --family isosurface");
    ASSERT_EQ(files.heatMaps.size(), 1u);
    EXPECT_GT(std::filesystem::file_size(files.heatMaps[0]), 1000u);
    EXPECT_TRUE(std::filesystem::exists(dir / "heatmap_isosurface.pdf"));
    std::ifstream csv(files.csv);
    std::string header;
    std::getline(csv, header);
    EXPECT_EQ(header.rfind("family,technique,case,group,passed,values,non_finite,out_of_range,deviation,tolerance,ms", 0), 0u)
        << header;
    std::size_t lines = 0;
    for (std::string line; std::getline(csv, line);)
        ++lines;
    EXPECT_EQ(lines, records.size());
    std::stringstream html;
    html << std::ifstream(files.html).rdbuf();
    EXPECT_NE(html.str().find("heatmap_isosurface.png"), std::string::npos);
    EXPECT_NE(html.str().find("threw: boom"), std::string::npos) << "the failures are listed";
    // Written again: replaced, not appended.
    report::writeStressReport(records, dir.string(), "again");
    std::ifstream again(files.csv);
    std::size_t againLines = 0;
    for (std::string line; std::getline(again, line);)
        ++againLines;
    EXPECT_EQ(againLines, records.size() + 1);
}
