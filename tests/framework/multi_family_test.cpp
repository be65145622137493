// Several families in one run and one frame: the occlusion family and a small probe family
// defined here, which reads the occlusion family's slot of the frame (pipeline/compose.h). The
// G-buffer is rasterised once; rows carry both families' parameters.

#include "core/error.h"
#include "experiment/analysis.h"
#include "experiment/family.h"
#include "experiment/runner.h"
#include "pipeline/compose.h"
#include "pipeline/frame_graph.h"
#include "pipeline/frame_start.h"
#include "plugin/technique.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

void rtlabRegisterTechnique_occlusion_gtao(rtlab::plugin::Registry&);
void rtlabRegisterTechnique_isosurface_marching_cubes(rtlab::plugin::Registry&);

namespace rtlab {
namespace {

class ProbeTechnique : public plugin::Technique {
public:
    static constexpr const char* kFamily = "probe";
};

class ProbeA final : public ProbeTechnique {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "reads the frame's ambient occlusion"};
    }
    static config::ParamSchema declareParams()
    {
        config::ParamSchema schema;
        schema.addFloat("radius", 2.0, 0.0, std::numeric_limits<double>::infinity(), "world units",
                        "named like the occlusion technique's radius on purpose");
        return schema;
    }
    explicit ProbeA(const config::ParamSet& params) : mRadius(params.getFloat("radius")) {}
    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p;
        p.set("radius", mRadius);
        return p;
    }

private:
    double mRadius;
};

class ProbeRun final : public experiment::FamilyRun {
public:
    explicit ProbeRun(experiment::RunSetup& setup) : mPrefix(setup.paramPrefix)
    {
        mTechnique = experiment::createTechnique<ProbeTechnique>(setup.run,
                                                                 setup.context.registry(), "probe");
        const auto view = setup.frameStart->viewInputs();
        const auto ao = pipeline::Compose::ambientOcclusionSlot(setup.run.width, setup.run.height);
        setup.graph.addPass({.name = "probe", .reads = {view, ao}, .writes = {"metric.probe"}},
                            [this, view, ao](pipeline::PassContext& ctx) {
                                const auto& surface = ctx.read(view).surface;
                                const auto& a = ctx.read(ao);
                                double sum = 0.0;
                                int n = 0;
                                for (std::size_t i = 0; i < a.pixels.size(); ++i)
                                    if (surface.pixels[i]) {
                                        sum += a.pixels[i];
                                        ++n;
                                    }
                                mRow->set("probe.mean_ao", n ? sum / n : std::nan(""));
                                return pipeline::PassOutcome{};
                            });
        setup.outputs.push_back("metric.probe");
    }
    void describe(experiment::ResultRow& row) const override
    {
        experiment::addParamColumns(row, *mTechnique, mPrefix);
    }
    void beginFrame(int, experiment::ResultRow& row) override { mRow = &row; }
    void endFrame(int, const std::vector<pipeline::PassRecord>&, experiment::ResultRow&) override {}

private:
    std::string mPrefix;
    std::unique_ptr<ProbeTechnique> mTechnique;
    experiment::ResultRow* mRow = nullptr;
};

class ProbeFamily final : public experiment::Family {
public:
    std::unique_ptr<experiment::FamilyRun> beginRun(experiment::RunSetup& setup) const override
    {
        return std::make_unique<ProbeRun>(setup);
    }
};

plugin::Registry makeRegistry()
{
    plugin::Registry r;
    plugin::registerBuiltinFamilies(r);
    rtlabRegisterTechnique_occlusion_gtao(r);
    rtlabRegisterTechnique_isosurface_marching_cubes(r);
    plugin::FamilyInfo probe{.name = "probe",
                             .summary = "test family",
                             .metrics = {{"probe", "mean of the frame's ambient occlusion"}}};
    probe.domain = plugin::FamilyDomain::Screen;
    probe.report = {.cost = "technique_ms", .error = "probe.mean_ao"};
    probe.runtime = std::make_shared<ProbeFamily>();
    r.addFamily(std::move(probe));
    plugin::registerTechnique<ProbeA>(r, "probe", "probe_a");
    return r;
}

TEST(MultiFamily, TwoScreenFamiliesShareOneFrameAndMeetThroughASlot)
{
    const auto registry = makeRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: ao_testbed
  resolution: [24, 16]
  metrics: [error, probe]
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.05, max_samples: 16}
  techniques:
    occlusion: {technique: gtao, params: {radius: 0.5}}
    probe: {technique: probe_a}
)",
                                               "two.yaml", registry);
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_multi_family";
    std::filesystem::remove_all(dir);
    experiment::runExperiment(
        e, registry,
        {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    const auto rows = experiment::loadResults(dir.string());
    ASSERT_EQ(rows.size(), 1u);
    const auto& row = rows[0];
    ASSERT_EQ(row.at("status"), "ok") << row.at("error");
    EXPECT_EQ(row.at("family"), "occlusion+probe");
    EXPECT_EQ(row.at("technique"), "gtao+probe_a");
    EXPECT_EQ(row.at("param.occlusion.radius"), "0.5");
    EXPECT_EQ(row.at("param.probe.radius"), "2");
    const std::string& passes = row.at("passes");
    EXPECT_EQ(passes.find("gbuffer:run"), passes.rfind("gbuffer:run"))
        << "one G-buffer for both families";
    EXPECT_NE(passes.find("occlusion_slots:run"), std::string::npos) << passes;
    const double meanAo = experiment::getNumber(row, "probe.mean_ao");
    EXPECT_GT(meanAo, 0.0);
    EXPECT_LT(meanAo, 1.0) << "ao_testbed has creases and occluders";
    EXPECT_TRUE(std::isfinite(experiment::getNumber(row, "ao.rmse")));
}

TEST(MultiFamily, SweepsCrossTheParametersOfBothFamilies)
{
    const auto registry = makeRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: ao_testbed
  techniques:
    occlusion: {technique: gtao}
    probe: {technique: probe_a}
sweep:
  occlusion.radius: [0.5, 1.0]
  probe.radius: [1.0, 2.0, 3.0]
)",
                                               "sweep.yaml", registry);
    ASSERT_EQ(e.runs.size(), 6u);
    std::set<std::string> hashes;
    for (const auto& run : e.runs) {
        hashes.insert(run.hash());
        EXPECT_EQ(run.techniques.size(), 2u);
    }
    EXPECT_EQ(hashes.size(), 6u);
    EXPECT_EQ(e.runs[5].techniques.at("occlusion").params.getFloat("radius"), 1.0);
    EXPECT_EQ(e.runs[5].techniques.at("probe").params.getFloat("radius"), 3.0);
}

TEST(MultiFamily, AVolumeFamilyCannotShareARunAndTheErrorSaysWhere)
{
    const auto registry = makeRegistry();
    try {
        experiment::parseExperiment(R"(base:
  scene: ao_testbed
  techniques:
    occlusion: {technique: gtao}
    isosurface: {technique: marching_cubes}
)",
                                    "mixed.yaml", registry);
        FAIL() << "expected an error";
    } catch (const InputError& error) {
        const std::string m = error.what();
        EXPECT_NE(m.find("mixed.yaml:4:"), std::string::npos) << m;
        EXPECT_NE(m.find("family 'isosurface' works on a sampled volume and cannot share a run"),
                  std::string::npos)
            << m;
    }
}

} // namespace
} // namespace rtlab
