// The occlusion family's experiment driver end to end on lavapipe: G-buffer, technique, Embree
// ground truth of the declared quantity, metrics and images. The technique is a test double that
// reports "no occlusion" (ambient 1), so its error against the ground truth is known: the mean
// signed error is the mean occlusion of the reference, 1 - mean(reference AO).

#include "experiment/analysis.h"
#include "experiment/image_files.h"
#include "experiment/runner.h"
#include "families/occlusion/occlusion.h"
#include "test_registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace rtlab;

namespace {

class Unoccluded final : public plugin::OcclusionTechnique {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "test double: no occlusion anywhere"};
    }
    static config::ParamSchema declareParams()
    {
        config::ParamSchema s;
        s.addFloat("radius", 0.5, 0.0, 100.0, "world units", "radius the ground truth uses");
        return s;
    }
    explicit Unoccluded(const config::ParamSet& p) : mRadius(p.getFloat("radius")) {}
    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p;
        p.set("radius", mRadius);
        return p;
    }
    plugin::OcclusionDefinition definition() const override
    {
        return {plugin::OcclusionQuantity::CosineAo, mRadius};
    }
    void compute(const plugin::OcclusionInput& in, plugin::OcclusionOutput& out) override
    {
        out.ambient = Image<float>(in.normal->width, in.normal->height, 1.0f);
        out.bentNormal = *in.normal;
        out.coneAperture = Image<float>(in.normal->width, in.normal->height, 1.5707964f);
    }

private:
    double mRadius;
};

// bentcone_ssdo as a technique that keeps nothing on the GPU: its result reaches the lit frame
// through the CPU slots and the compose pass's upload, as a CPU technique's does.
class BentConeThroughTheCpu final : public plugin::OcclusionTechnique {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "test double: bentcone_ssdo read back and uploaded again"};
    }
    static const plugin::TechniqueEntry& inner()
    {
        for (const auto* e : plugin::builtinRegistry().techniques("occlusion"))
            if (e->info.name == "bentcone_ssdo")
                return *e;
        throw Error("bentcone_ssdo is not registered");
    }
    static config::ParamSchema declareParams() { return inner().schema; }
    explicit BentConeThroughTheCpu(const config::ParamSet& p)
        : mInner(inner().create(p)), mTechnique(dynamic_cast<plugin::OcclusionTechnique&>(*mInner))
    {
    }
    config::ParamSet effectiveParams() const override { return mInner->effectiveParams(); }
    plugin::OcclusionDefinition definition() const override { return mTechnique.definition(); }
    bool acceptsGpuInputs() const override { return true; }
    void compute(const plugin::OcclusionInput& in, plugin::OcclusionOutput& out) override
    {
        mTechnique.compute(in, out); // in.readBack is true: the CPU images are filled
        out.gpu = {};
    }

private:
    std::unique_ptr<plugin::Technique> mInner;
    plugin::OcclusionTechnique& mTechnique;
};

// Runs the experiment quietly into `directory` and returns its rows.
std::vector<experiment::Row> runAndLoad(const experiment::Experiment& e,
                                        const plugin::Registry& registry,
                                        const std::string& directory)
{
    experiment::runExperiment(
        e, registry,
        {.outputDirectory = directory, .quiet = true, .queryVulkanForManifest = false});
    return experiment::loadResults(directory);
}

} // namespace

TEST(OcclusionDriver, RunsTheFramePipelineAgainstTheGroundTruth)
{
    auto registry = test::makeTestRegistry();
    plugin::registerTechnique<Unoccluded>(registry, "occlusion", "unoccluded");
    const auto e = experiment::parseExperiment(R"(name: occlusion_driver_test
base:
  scene: ao_testbed
  resolution: [48, 32]
  frames: 1
  timing: {warmup: 0, repeats: 2}
  reference: {target_stderr: 0.02, max_samples: 64}
  techniques: {occlusion: {technique: unoccluded, params: {radius: 0.5}}}
)",
                                               "occlusion.yaml", registry);
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_test";
    std::filesystem::remove_all(dir);
    const auto s = experiment::runExperiment(
        e, registry,
        {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    const auto rows = experiment::loadResults(dir.string());
    ASSERT_EQ(rows.size(), 1u);
    const auto& row = rows[0];
    ASSERT_EQ(s.failed, 0u) << row.at("error");
    EXPECT_EQ(row.at("quantity"), "cosine_ao");
    EXPECT_EQ(row.at("frame"), "0");
    // Ambient 1 everywhere: the signed error is the reference's mean occlusion, positive, and the
    // RMSE is at least its absolute value.
    const double mse = experiment::getNumber(row, "ao.mean_signed_error");
    const double rmse = experiment::getNumber(row, "ao.rmse");
    EXPECT_GT(mse, 0.0);
    EXPECT_GE(rmse, mse - 1e-12);
    EXPECT_GT(experiment::getNumber(row, "ao.pixels"), 48 * 32 / 4);
    EXPECT_GT(experiment::getNumber(row, "gbuffer.cpu_ms"), 0.0);
    EXPECT_TRUE(std::isfinite(experiment::getNumber(row, "bent.angle_error_deg")));
    EXPECT_TRUE(std::filesystem::exists(row.at("image.error")));
    EXPECT_TRUE(std::filesystem::exists(row.at("image.reference")));
    // The G-buffer draw's GPU time came from the timestamps, through the context's run log.
    EXPECT_GT(experiment::getNumber(row, "gbuffer.gpu_ms"), 0.0);
}

TEST(OcclusionDriver, AnAnalyticShapeIsARecordedFailure)
{
    auto registry = test::makeTestRegistry();
    plugin::registerTechnique<Unoccluded>(registry, "occlusion", "unoccluded");
    const auto e = experiment::parseExperiment(
        "base: {scene: sphere, techniques: {occlusion: {technique: unoccluded}}}\n", "bad.yaml",
        registry);
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_bad";
    std::filesystem::remove_all(dir);
    const auto s = experiment::runExperiment(
        e, registry,
        {.outputDirectory = dir.string(), .quiet = true, .queryVulkanForManifest = false});
    EXPECT_EQ(s.failed, 1u);
    const auto rows = experiment::loadResults(dir.string());
    ASSERT_EQ(rows.size(), 1u);
    EXPECT_NE(rows[0].at("error").find("analytic shape"), std::string::npos) << rows[0].at("error");
}

TEST(OcclusionDriver, RecordsSkippedPassesAndWhy)
{
    // Two frames of a still scene: frame 1 does not upload the scene again, and its ground truth
    // (same G-buffer, same settings) comes from the cache. Both are recorded as skipped, with why.
    auto registry = test::makeTestRegistry();
    plugin::registerTechnique<Unoccluded>(registry, "occlusion", "unoccluded");
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_passes";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "still.yaml") << "scene: still\nbase: ao_testbed\nframes: 2\n";
    const auto e = experiment::parseExperiment(R"(base:
  scene: still.yaml
  resolution: [24, 16]
  frames: 2
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.05, max_samples: 16}
  techniques: {occlusion: {technique: unoccluded}}
)",
                                               (dir / "passes.yaml").string(), registry);
    const auto rows = runAndLoad(e, registry, (dir / "out").string());
    ASSERT_EQ(rows.size(), 2u) << (rows.empty() ? "" : rows[0].at("error"));
    const std::string& first = rows[0].at("passes");
    EXPECT_NE(first.find("character_pose:skipped(the scene has no characters)"), std::string::npos)
        << first;
    EXPECT_NE(first.find("assemble_geometry:run;scene_upload:run;gbuffer:run;gbuffer_readback:run;"
                         "view_inputs:run;view_inputs_gpu:skipped(no consumer"),
              std::string::npos)
        << first << "\n(a technique without GPU inputs reads the CPU copy)";
    EXPECT_NE(first.find("occlusion:run"), std::string::npos) << first;
    // The graph timed the passes that ran: the repeated ones with their statistics, the others
    // once.
    EXPECT_TRUE(rows[0].count("gbuffer.cpu_ms_iqr")) << "gbuffer is timed with the run's repeats";
    EXPECT_TRUE(rows[0].count("occlusion.cpu_ms_iqr"));
    EXPECT_TRUE(rows[0].count("gbuffer_readback.cpu_ms"));
    EXPECT_TRUE(rows[0].count("technique_ms"));
    // A still camera over unchanged geometry: frame 1 neither redraws the G-buffer nor reads it
    // back.
    EXPECT_NE(rows[1].at("passes").find(
                  "gbuffer:skipped(camera, geometry and size unchanged since frame 0"),
              std::string::npos)
        << rows[1].at("passes");
    EXPECT_NE(rows[1].at("passes").find(
                  "gbuffer_readback:skipped(the G-buffer is unchanged since frame 0"),
              std::string::npos)
        << rows[1].at("passes");
    EXPECT_FALSE(rows[1].count("gbuffer.cpu_ms")) << "a skipped pass has no time";
    EXPECT_NE(rows[1].at("passes").find("scene_upload:skipped(geometry unchanged since frame 0"),
              std::string::npos)
        << rows[1].at("passes");
    EXPECT_NE(rows[1].at("passes").find("reference:skipped(read from the reference cache"),
              std::string::npos)
        << rows[1].at("passes");
    EXPECT_NE(rows[1].at("passes").find("reference_bent:skipped(read from the reference cache"),
              std::string::npos)
        << rows[1].at("passes");
    EXPECT_GT(experiment::getNumber(rows[0], "memory.peak_rss_mb"), 1.0);
}

TEST(OcclusionDriver, WithoutCullingEveryPassRunsAndTheImagesAreBitwiseTheSame)
{
    // frame: {culling: false} runs every pass of every frame (no reuse, no unread output dropped);
    // the technique's and the reference's images must not change by a bit.
    const auto& registry = plugin::builtinRegistry();
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_culling";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "still.yaml") << "scene: still\nbase: ao_testbed\nframes: 2\n";
    auto run = [&](const std::string& culling) {
        const auto e =
            experiment::parseExperiment(R"(base:
  scene: still.yaml
  resolution: [24, 16]
  frames: 2
  metrics: [error]
  frame: {culling: )" + culling + R"(}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.05, max_samples: 16}
  techniques: {occlusion: {technique: gtao}}
)",
                                        (dir / ("culling_" + culling + ".yaml")).string(),
                                        registry);
        const auto out = dir / ("out_" + culling);
        return runAndLoad(e, registry, out.string());
    };
    const auto culled = run("true");
    const auto all = run("false");
    ASSERT_EQ(culled.size(), 2u) << (culled.empty() ? "" : culled[0].at("error"));
    ASSERT_EQ(all.size(), 2u) << (all.empty() ? "" : all[0].at("error"));
    EXPECT_NE(culled[1].at("passes").find("gbuffer:skipped"), std::string::npos)
        << culled[1].at("passes");
    EXPECT_NE(culled[1].at("passes").find("metric.ssim:skipped(no consumer"), std::string::npos);
    EXPECT_EQ(all[1].at("passes").find("no consumer"), std::string::npos) << all[1].at("passes");
    EXPECT_EQ(all[1].at("passes").find("gbuffer:skipped"), std::string::npos)
        << all[1].at("passes");
    EXPECT_EQ(all[1].at("frame.culling"), "false");
    for (int i = 0; i < 2; ++i)
        for (const char* image : {"image.technique", "image.reference"}) {
            EXPECT_EQ(experiment::readExrScalar(culled[std::size_t(i)].at(image)).pixels,
                      experiment::readExrScalar(all[std::size_t(i)].at(image)).pixels)
                << image << " of frame " << i;
        }
}

TEST(OcclusionDriver, ComposesTheLitFrameAndMeasuresItAgainstTheFullRadiance)
{
    // The Cornell box with a point light, two still frames, frame: {lighting: true}, and the
    // bent-cone technique whose 16 cone visibilities attenuate the sky.
    const auto& registry = plugin::builtinRegistry();
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_lit";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "lamp.yaml")
        << "scene: lamp\nbase: cornell_box\nframes: 2\n"
           "point_lights:\n  - {position: [0.28, 0.45, 0.2], intensity: [0.05, 0.05, 0.04]}\n";
    const auto e = experiment::parseExperiment(R"(base:
  scene: lamp.yaml
  resolution: [32, 24]
  frames: 2
  metrics: [error]
  frame: {lighting: true, tonemapper: reinhard, shadow_map_size: 64}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.05, target_rel_stderr: 0.1, max_samples: 32}
  techniques: {occlusion: {technique: bentcone_ssdo}}
)",
                                               (dir / "lit.yaml").string(), registry);
    const auto rows = runAndLoad(e, registry, (dir / "out").string());
    ASSERT_EQ(rows.size(), 2u) << (rows.empty() ? "" : rows[0].at("error"));
    for (const auto& row : rows) {
        ASSERT_EQ(row.at("status"), "ok") << row.at("error");
        EXPECT_EQ(row.at("frame.visibility"), "cones")
            << "bentcone_ssdo gives the 16 cone visibilities";
        EXPECT_NE(row.at("frame.indirect").find("none"), std::string::npos)
            << "no voxel_gi technique: recorded";
        for (const char* column : {"frame.rmse", "frame.rel_mse", "frame.flip", "direct.rmse"}) {
            const double v = experiment::getNumber(row, column);
            EXPECT_TRUE(std::isfinite(v) && v >= 0.0) << column << " = " << v;
        }
        // The frame has no indirect light and no light from the emissive ceiling onto other
        // surfaces: it is darker than the full radiance on average.
        EXPECT_LT(experiment::getNumber(row, "frame.mean_signed_error"), 0.0);
        EXPECT_TRUE(std::filesystem::exists(row.at("image.lit")));
        EXPECT_TRUE(std::filesystem::exists(row.at("image.truth")));
        EXPECT_TRUE(row.count("lighting.cpu_ms")) << "the graph times the compose passes";
        // The frame's time sums the passes that make it, not the ground truths and metrics.
        const double frameMs = experiment::getNumber(row, "frame.cpu_ms");
        double sum = 0.0;
        std::stringstream framePasses(row.at("frame_passes"));
        for (std::string pass; std::getline(framePasses, pass, ';');)
            if (row.count(pass + ".cpu_ms"))
                sum += experiment::getNumber(row, pass + ".cpu_ms");
        EXPECT_GT(frameMs, 0.0);
        EXPECT_NEAR(frameMs, sum, 1e-6 * sum) << "frame.cpu_ms is the sum over frame_passes";
        EXPECT_NE(row.at("frame_passes").find("lighting"), std::string::npos);
        EXPECT_EQ(row.at("frame_passes").find("reference"), std::string::npos)
            << row.at("frame_passes");
    }
    EXPECT_EQ(rows[0].at("frame.shadow_maps_rendered"), "1");
    // The graph's GPU resources: the G-buffer's render target and the shadow atlas (made in
    // frame 0, kept across frames) and seven images (view depth and normals, the world position
    // + depth and normal copies, HDR, direct, tonemapped): five of them made in frame 0 (the
    // world copies, which no pass of this run reads, go back to the pool once view_inputs_gpu
    // has written them, and the HDR and direct images take two RGBA32F images from it), all
    // seven reused in frame 1.
    EXPECT_EQ(rows[0].at("frame.gpu_images_created"), "7");
    EXPECT_EQ(rows[0].at("frame.gpu_images_reused"), "2");
    EXPECT_EQ(rows[1].at("frame.gpu_images_created"), "0");
    EXPECT_EQ(rows[1].at("frame.gpu_images_reused"), "7");
    EXPECT_NE(rows[1].at("passes").find(
                  "shadow_maps:skipped(no light and no shadow caster moved since frame 0)"),
              std::string::npos)
        << rows[1].at("passes");
}

TEST(OcclusionDriver, TheLitFrameBindsTheTechniquesImagesWithoutARoundTripThroughTheCpu)
{
    // bentcone_ssdo leaves its 16 cone visibilities on the GPU and the lighting pass binds them;
    // the read-back to the CPU runs for the metrics and images only, so it counts as a
    // measurement. The same technique sent through the CPU and uploaded again gives the same
    // lit frame, bitwise.
    auto registry = test::makeTestRegistry();
    plugin::registerTechnique<BentConeThroughTheCpu>(registry, "occlusion", "bentcone_via_cpu");
    registry.addTechnique(BentConeThroughTheCpu::inner());
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_slots";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "lamp.yaml")
        << "scene: lamp\nbase: cornell_box\nframes: 1\n"
           "point_lights:\n  - {position: [0.28, 0.45, 0.2], intensity: [0.05, 0.05, 0.04]}\n";
    auto run = [&](const std::string& technique) {
        const auto e = experiment::parseExperiment(R"(base:
  scene: lamp.yaml
  resolution: [32, 24]
  metrics: [error]
  frame: {lighting: true, shadow_map_size: 32}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.05, target_rel_stderr: 0.1, max_samples: 32}
  techniques: {occlusion: {technique: )" + technique + R"(}}
)",
                                                   (dir / (technique + ".yaml")).string(),
                                                   registry);
        return runAndLoad(e, registry, (dir / technique).string());
    };
    const auto onGpu = run("bentcone_ssdo");
    const auto viaCpu = run("bentcone_via_cpu");
    ASSERT_EQ(onGpu.size(), 1u);
    ASSERT_EQ(viaCpu.size(), 1u);
    ASSERT_EQ(onGpu[0].at("status"), "ok") << onGpu[0].at("error");
    ASSERT_EQ(viaCpu[0].at("status"), "ok") << viaCpu[0].at("error");
    const std::string& gpuPasses = onGpu[0].at("passes");
    EXPECT_NE(gpuPasses.find("occlusion_gpu_slots:run"), std::string::npos) << gpuPasses;
    EXPECT_NE(gpuPasses.find("occlusion_readback:run"), std::string::npos) << gpuPasses;
    EXPECT_EQ(gpuPasses.find("occlusion_upload"), std::string::npos) << gpuPasses;
    EXPECT_NE(gpuPasses.find("occlusion_slots:skipped(no consumer"), std::string::npos)
        << "nothing reads the CPU slots: " << gpuPasses;
    const std::string& gpuFrame = onGpu[0].at("frame_passes");
    EXPECT_EQ(gpuFrame.find("occlusion_readback"), std::string::npos)
        << "only measurements read it: " << gpuFrame;
    EXPECT_EQ(gpuFrame.find("gbuffer_readback"), std::string::npos) << gpuFrame;
    EXPECT_NE(gpuFrame.find("occlusion;"), std::string::npos) << gpuFrame;
    EXPECT_NE(viaCpu[0].at("passes").find("occlusion_upload:run"), std::string::npos)
        << viaCpu[0].at("passes");
    EXPECT_NE(viaCpu[0].at("frame_passes").find("occlusion_upload"), std::string::npos);
    EXPECT_EQ(onGpu[0].at("frame.visibility"), "cones");
    EXPECT_EQ(viaCpu[0].at("frame.visibility"), "cones");
    const Image<glm::vec3> a = experiment::readExrRgb(onGpu[0].at("image.lit_hdr"));
    const Image<glm::vec3> b = experiment::readExrRgb(viaCpu[0].at("image.lit_hdr"));
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    ASSERT_GT(a.pixels.size(), 0u);
    EXPECT_EQ(0, std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(glm::vec3)));
}

// The three frames of the scene `sceneYaml` (two point lights in the Cornell box and something
// that changes) lit with shadow maps, with culling on and off; every frame must be ok, the
// unculled run redraws all 12 faces every frame, and the lit HDR frames must not differ by a bit.
std::pair<std::vector<experiment::Row>, std::vector<experiment::Row>>
runShadowFramesCulledAndNot(const std::string& name, const std::string& sceneYaml)
{
    const auto& registry = plugin::builtinRegistry();
    const auto dir = std::filesystem::temp_directory_path() / ("rtlab_occlusion_driver_" + name);
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    std::ofstream(dir / (name + ".yaml")) << sceneYaml;
    auto run = [&](const std::string& culling) {
        const auto e = experiment::parseExperiment(R"(base:
  scene: )" + name + R"(.yaml
  resolution: [32, 24]
  frames: 3
  camera_path: static
  metrics: [error]
  frame: {lighting: true, shadow_map_size: 32, culling: )" + culling + R"(}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.2, target_rel_stderr: 0.5, max_samples: 4}
  techniques: {occlusion: {technique: gtao}}
)",
                                                   (dir / (name + "_" + culling + ".yaml")).string(), registry);
        return runAndLoad(e, registry, (dir / ("out_" + culling)).string());
    };
    auto culled = run("true");
    auto all = run("false");
    EXPECT_EQ(culled.size(), 3u) << (culled.empty() ? "" : culled[0].at("error"));
    EXPECT_EQ(all.size(), 3u) << (all.empty() ? "" : all[0].at("error"));
    for (std::size_t i = 0; i < std::min(culled.size(), all.size()); ++i) {
        EXPECT_EQ(culled[i].at("status"), "ok") << culled[i].at("error");
        EXPECT_EQ(all[i].at("status"), "ok") << all[i].at("error");
        EXPECT_EQ(all[i].at("frame.shadow_faces_rendered"), "12") << "frame " << i;
        EXPECT_EQ(all[i].at("frame.shadow_skips"), "") << "frame " << i;
        if (culled[i].at("status") != "ok" || all[i].at("status") != "ok")
            continue;
        const Image<glm::vec3> a = experiment::readExrRgb(culled[i].at("image.lit_hdr"));
        const Image<glm::vec3> b = experiment::readExrRgb(all[i].at("image.lit_hdr"));
        EXPECT_EQ(a.pixels.size(), b.pixels.size());
        if (a.pixels.size() == b.pixels.size())
            EXPECT_EQ(std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(glm::vec3)), 0)
                << "lit frame " << i;
    }
    return {std::move(culled), std::move(all)};
}

constexpr const char* kTwoLights =
    "point_lights:\n  - {position: [0.28, 0.45, 0.2], intensity: [0.05, 0.05, 0.04]}\n"
    "  - {position: [0.1, 0.3, 0.45], intensity: [0.02, 0.03, 0.04]}\n";

TEST(OcclusionDriver, ShadowMapsRedrawOnlyTheFacesAWalkerChangesAndTheFrameMatchesTheUnculledOne)
{
    // A small walking character. With culling the shadow pass redraws, after frame 0, only the
    // cube faces that see the walker's old or new capsule and records the kept ones.
    const auto [culled, all] = runShadowFramesCulledAndNot(
        "walker", std::string("scene: walker\nbase: cornell_box\nframes: 3\n") + kTwoLights +
                      "characters:\n  - name: walker\n"
                      "    capsules: [{a: [0, 0.03, 0], b: [0, 0.1, 0], radius: 0.03}]\n"
                      "    path: [{time: 0, position: [0.4, 0, 0.1]}, {time: 0.2, position: [0.45, 0, "
                      "0.2]}]\n");
    ASSERT_EQ(culled.size(), 3u);
    EXPECT_EQ(culled[0].at("frame.shadow_faces_rendered"), "12");
    for (std::size_t i = 1; i < 3; ++i) {
        EXPECT_NE(culled[i].at("passes").find("shadow_maps:run"), std::string::npos) << culled[i].at("passes");
        const double faces = experiment::getNumber(culled[i], "frame.shadow_faces_rendered");
        EXPECT_GT(faces, 0.0) << "frame " << i;
        EXPECT_LT(faces, 12.0) << "frame " << i;
        EXPECT_NE(culled[i].at("frame.shadow_skips").find("in their view"), std::string::npos)
            << culled[i].at("frame.shadow_skips");
    }
}

TEST(OcclusionDriver, ShadowMapsRedrawOnlyTheFacesADigChangesAndTheFrameMatchesTheUnculledOne)
{
    // A rock dug at frame 1. With culling the shadow pass bounds what changed by the dig's
    // primitive (grown by its blend and the mesher's reach), not by comparing triangles, and
    // redraws only the cube faces that see that box; at frame 2 nothing moved and it is skipped.
    const auto [culled, all] = runShadowFramesCulledAndNot(
        "dig", std::string("scene: dig\nbase: cornell_box\nframes: 3\n") + kTwoLights +
                   "sdf_models:\n  - name: rock\n    bounds: [[0.32, 0.0, 0.05], [0.52, 0.2, 0.25]]\n"
                   "    resolution: 48\n    edits:\n"
                   "      - {shape: rounded_box, op: add, center: [0.42, 0.08, 0.15], size: [0.08, 0.08, 0.08], "
                   "rounding: 0.02, material: white}\n"
                   "      - {shape: sphere, op: subtract, center: [0.47, 0.15, 0.10], size: 0.05, blend: 0.01, "
                   "frame: 1}\n");
    ASSERT_EQ(culled.size(), 3u);
    const double faces = experiment::getNumber(culled[1], "frame.shadow_faces_rendered");
    EXPECT_GT(faces, 0.0);
    EXPECT_LT(faces, 12.0);
    EXPECT_NE(culled[1].at("frame.shadow_skips").find("no caster moved in their view"), std::string::npos)
        << culled[1].at("frame.shadow_skips");
    EXPECT_NE(culled[2].at("passes").find("shadow_maps:skipped"), std::string::npos) << culled[2].at("passes");
}

TEST(OcclusionDriver, ADigOutsideTheModelOrOfNoSizeIsRecordedAndChangesNothing)
{
    // A dig far outside the rock's box at frame 1 and a dig of radius 0 in the air at frame 2:
    // the re-mesh runs, records that the mesh did not change, and nothing downstream redraws;
    // the frames equal the unculled ones bit for bit (the helper checks).
    const auto [culled, all] = runShadowFramesCulledAndNot(
        "dig_nothing", std::string("scene: dig_nothing\nbase: cornell_box\nframes: 3\n") + kTwoLights +
                           "sdf_models:\n  - name: rock\n    bounds: [[0.32, 0.0, 0.05], [0.52, 0.2, 0.25]]\n"
                           "    resolution: 32\n    edits:\n"
                           "      - {shape: sphere, op: add, center: [0.42, 0.08, 0.15], size: 0.07, material: white}\n"
                           "      - {shape: sphere, op: subtract, center: [5.0, 5.0, 5.0], size: 0.05, frame: 1}\n"
                           "      - {shape: sphere, op: subtract, center: [0.45, 0.19, 0.2], size: 0.0, frame: 2}\n");
    ASSERT_EQ(culled.size(), 3u);
    for (std::size_t i = 1; i < 3; ++i) {
        EXPECT_NE(culled[i].at("frame.sdf_remesh").find("the mesh did not change"), std::string::npos)
            << "frame " << i << ": " << culled[i].at("frame.sdf_remesh");
        EXPECT_NE(culled[i].at("passes").find("scene_upload:skipped"), std::string::npos)
            << culled[i].at("passes");
        EXPECT_NE(culled[i].at("passes").find("shadow_maps:skipped"), std::string::npos)
            << culled[i].at("passes");
        EXPECT_NE(all[i].at("frame.sdf_remesh").find("meshed in full"), std::string::npos)
            << all[i].at("frame.sdf_remesh");
    }
}

TEST(OcclusionDriver, VulkanTechniquesReadTheGBufferOnTheGpuWithTheSameResult)
{
    // gtao binds the view inputs made on the GPU (no upload of a CPU copy); the ablation
    // frame: {gbuffer_on_gpu: false} reads the CPU copy and uploads it. Same occlusion up to the
    // float rounding of the two normal transforms (1e-4 of the AO range).
    const auto& registry = plugin::builtinRegistry();
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_gpu_inputs";
    std::filesystem::remove_all(dir);
    auto run = [&](const std::string& onGpu) {
        const auto e =
            experiment::parseExperiment(R"(base:
  scene: ao_testbed
  resolution: [32, 24]
  metrics: [error]
  frame: {gbuffer_on_gpu: )" + onGpu + R"(}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.05, max_samples: 16}
  techniques: {occlusion: {technique: gtao}}
)",
                                        (dir / ("gpu_" + onGpu + ".yaml")).string(), registry);
        const auto out = dir / ("out_" + onGpu);
        return runAndLoad(e, registry, out.string());
    };
    const auto gpu = run("true");
    const auto cpu = run("false");
    ASSERT_EQ(gpu.size(), 1u);
    ASSERT_EQ(cpu.size(), 1u);
    ASSERT_EQ(gpu[0].at("status"), "ok") << gpu[0].at("error");
    EXPECT_NE(gpu[0].at("passes").find("view_inputs_gpu:run"), std::string::npos)
        << gpu[0].at("passes");
    EXPECT_NE(cpu[0].at("passes").find("view_inputs_gpu:skipped(no consumer"), std::string::npos)
        << cpu[0].at("passes");
    const auto a = experiment::readExrScalar(gpu[0].at("image.technique"));
    const auto b = experiment::readExrScalar(cpu[0].at("image.technique"));
    ASSERT_EQ(a.pixels.size(), b.pixels.size());
    for (std::size_t i = 0; i < a.pixels.size(); ++i)
        ASSERT_NEAR(a.pixels[i], b.pixels[i], 1e-4f) << "pixel " << i;
}

TEST(OcclusionDriver, ComputesOnlyTheMetricsTheRunAsksForAndTheGroundTruthTheyRead)
{
    auto registry = test::makeTestRegistry();
    plugin::registerTechnique<Unoccluded>(registry, "occlusion", "unoccluded");
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_metrics";
    std::filesystem::remove_all(dir);
    const auto e = experiment::parseExperiment(R"(base:
  scene: ao_testbed
  resolution: [24, 16]
  metrics: [error]
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.05, max_samples: 16}
  techniques: {occlusion: {technique: unoccluded}}
)",
                                               (dir / "metrics.yaml").string(), registry);
    const auto rows = runAndLoad(e, registry, dir.string());
    ASSERT_EQ(rows.size(), 1u);
    ASSERT_EQ(rows[0].at("status"), "ok") << rows[0].at("error");
    const std::string& passes = rows[0].at("passes");
    EXPECT_NE(passes.find("reference_bent:skipped(no consumer"), std::string::npos) << passes;
    EXPECT_NE(passes.find("metric.ssim:skipped(no consumer"), std::string::npos) << passes;
    EXPECT_NE(passes.find("metric.error:run"), std::string::npos) << passes;
    EXPECT_TRUE(std::isfinite(experiment::getNumber(rows[0], "ao.rmse")));
    EXPECT_EQ(rows[0].count("ao.ssim"), 0u) << "a metric the run did not ask for has no column";
    EXPECT_EQ(rows[0].count("bent.angle_error_deg"), 0u);
}

TEST(OcclusionDriver, MeasuresAgainstTheOverriddenQuantityAndSaysSo)
{
    auto registry = test::makeTestRegistry();
    plugin::registerTechnique<Unoccluded>(registry, "occlusion", "unoccluded");
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_occlusion_driver_override";
    std::filesystem::remove_all(dir);
    // A fresh reference cache, so that "computed, not read from the cache" is what this run did.
    const char* previousCache = std::getenv("RTLAB_CACHE_DIR");
    const std::string savedCache = previousCache ? previousCache : "";
    setenv("RTLAB_CACHE_DIR", (dir / "cache").c_str(), 1);
    const auto e = experiment::parseExperiment(R"(base:
  scene: ao_testbed
  resolution: [24, 16]
  frames: 2
  camera_path: orbit
  metrics: [error, flicker, screen_space_split]
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.05, max_samples: 16, quantity: ao_uniform, radius: 0.25}
  techniques: {occlusion: {technique: unoccluded}}
)",
                                               (dir / "override.yaml").string(), registry);
    const auto rows = runAndLoad(e, registry, dir.string());
    ASSERT_EQ(rows.size(), 2u) << (rows.empty() ? "" : rows[0].at("error"));
    EXPECT_EQ(rows[0].at("reference.quantity"), "ao_uniform");
    EXPECT_DOUBLE_EQ(experiment::getNumber(rows[0], "reference.radius"), 0.25);
    EXPECT_EQ(rows[0].at("reference.matches_technique"), "false");
    EXPECT_EQ(rows[0].at("camera_path"), "orbit");
    // The orbit moves the camera, not the geometry: frame 1 reuses the upload but draws anew,
    // and its ground truth is not a cache hit (the G-buffer changed).
    EXPECT_NE(rows[1].at("passes").find("scene_upload:skipped"), std::string::npos)
        << rows[1].at("passes");
    EXPECT_NE(rows[1].at("passes").find("gbuffer:run"), std::string::npos) << rows[1].at("passes");
    EXPECT_NE(rows[1].at("passes").find("reference:run"), std::string::npos)
        << rows[1].at("passes");
    // Flicker needs a previous frame; the screen-space split runs on every frame.
    EXPECT_NE(rows[0].at("passes").find("metric.flicker:skipped(input 'previous_frame' is not "
                                        "available: first frame of the run)"),
              std::string::npos)
        << rows[0].at("passes");
    EXPECT_TRUE(std::isfinite(experiment::getNumber(rows[1], "flicker.rms")));
    EXPECT_GT(experiment::getNumber(rows[1], "flicker.used_share"), 0.5)
        << "a 45-degree orbit about the target keeps most pixels in view";
    for (const auto& row : rows) {
        EXPECT_TRUE(std::isfinite(experiment::getNumber(row, "screen_truth.rmse")));
        EXPECT_TRUE(std::isfinite(experiment::getNumber(row, "ao_vs_screen_truth.rmse")));
    }
    if (previousCache)
        setenv("RTLAB_CACHE_DIR", savedCache.c_str(), 1);
    else
        unsetenv("RTLAB_CACHE_DIR");
}
