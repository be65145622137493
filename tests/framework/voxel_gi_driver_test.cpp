// The voxel_gi family in the game frame, end to end on lavapipe: bent-cone SSDO and cascades in
// one run; the cascades fill the lit frame's indirect slot and read SSDO's 16 visibilities; the
// indirect light is measured against the Embree `indirect` ground truth; the structure's steps
// are skipped with their reasons when nothing changed; culling off gives the same frame bits.

#include "experiment/analysis.h"
#include "experiment/image_files.h"
#include "experiment/runner.h"
#include "families/voxel_gi/voxel_gi.h"
#include "gpu/context.h"
#include "test_registry.h"
#include "plugin/technique.h"
#include "report/report.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

using namespace rtlab;

namespace {

// `params`: more of the cascades' parameters; `frame`: more frame options (", key: value").
std::vector<experiment::Row> runGameFrame(const std::string& culling,
                                          const std::filesystem::path& dir,
                                          const std::string& combine = "auto",
                                          const std::string& params = "",
                                          const std::string& frame = "")
{
    const auto& registry = plugin::builtinRegistry();
    const auto e = experiment::parseExperiment(
        R"(base:
  scene: cornell_box
  resolution: [40, 30]
  frames: 2
  camera_path: static
  metrics: [error, flicker]
  frame: {lighting: true, shadow_map_size: 16, culling: )" +
            culling + frame + R"(}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.2, target_rel_stderr: 0.5, max_samples: 8}
  techniques:
    occlusion: {technique: bentcone_ssdo}
    voxel_gi: {technique: cascades, params: {levels: 3, resolution: 16, supersampling: 2,
                                             combine_device: )" +
            combine + params + R"(}}
)",
        (dir / ("gi_" + culling + combine + ".yaml")).string(), registry);
    const std::string out =
        (dir / ("out_" + culling + "_" + combine + (frame.empty() ? "" : "_frame"))).string();
    experiment::runExperiment(
        e, registry, {.outputDirectory = out, .quiet = true, .queryVulkanForManifest = false});
    return experiment::loadResults(out);
}

TEST(VoxelGiDriver, CascadesFillTheIndirectSlotOfTheLitFrame)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_voxel_gi_driver";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto culled = runGameFrame("true", dir);
    const auto all = runGameFrame("false", dir);
    ASSERT_EQ(culled.size(), 2u) << (culled.empty() ? "" : culled[0].at("error"));
    ASSERT_EQ(all.size(), 2u) << (all.empty() ? "" : all[0].at("error"));
    for (std::size_t i = 0; i < 2; ++i) {
        ASSERT_EQ(culled[i].at("status"), "ok") << culled[i].at("error");
        ASSERT_EQ(all[i].at("status"), "ok") << all[i].at("error");
        const auto& row = culled[i];
        EXPECT_EQ(row.at("frame.indirect"), "indirect_irradiance");
        EXPECT_EQ(row.at("gather.cone_visibility"), "true");
        // The sky and the ceiling's light come through the cascades' cones.
        EXPECT_EQ(row.at("frame.sky"), "cones");
        // What the frame is made of: the Cornell box has no point lights, so their part is 0 in
        // the truth (the same reference twice) and in the lit frame (direct is all sky: float
        // rounding of one luminance against another); its ceiling is emissive and in view.
        EXPECT_EQ(experiment::getNumber(row, "truth.term.point_lights"), 0.0);
        EXPECT_NEAR(experiment::getNumber(row, "frame.term.point_lights"), 0.0, 1e-5);
        EXPECT_GT(experiment::getNumber(row, "frame.term.emission"), 0.0);
        EXPECT_EQ(experiment::getNumber(row, "frame.term.emission"),
                  experiment::getNumber(row, "truth.term.emission"));
        EXPECT_GT(experiment::getNumber(row, "frame.term.sky"), 0.0);
        EXPECT_GT(experiment::getNumber(row, "truth.term.sky"), 0.0);
        EXPECT_GE(experiment::getNumber(row, "frame.term.indirect"), -1e-5);
        EXPECT_TRUE(std::isfinite(experiment::getNumber(row, "frame.term_rmse.sky")));
        EXPECT_EQ(row.at("reference.bounces"), "2");
        const double rmse = experiment::getNumber(row, "indirect.rmse");
        EXPECT_TRUE(std::isfinite(rmse) && rmse >= 0.0) << rmse;
        EXPECT_GT(experiment::getNumber(row, "memory.payload_bytes"), 0.0);
        // metrics [error, flicker] do not ask for the split: its passes are culled.
        EXPECT_NE(row.at("passes").find("voxel_rays:skipped"), std::string::npos);
        const std::string& passes = row.at("passes");
        EXPECT_NE(passes.find("voxel_gather:run"), std::string::npos) << passes;
        EXPECT_NE(passes.find("indirect_slot:run"), std::string::npos) << passes;
        // Frame 1: a still camera and no edit, so the structure has nothing to update.
        if (i == 0) {
            EXPECT_NE(passes.find("voxelize:run"), std::string::npos) << passes;
            EXPECT_NE(row.at("voxelize.did").find("level 2: first voxelization"), std::string::npos)
                << row.at("voxelize.did");
            EXPECT_NE(passes.find("light_injection:run"), std::string::npos) << passes;
        } else {
            EXPECT_NE(passes.find("voxelize:skipped"), std::string::npos) << passes;
            EXPECT_NE(passes.find("light_injection:skipped"), std::string::npos) << passes;
            EXPECT_NE(all[i].at("passes").find("voxelize:run"), std::string::npos)
                << all[i].at("passes");
            // A still frame: the truth repeats exactly; the indirect light changes only through
            // SSDO's visibilities (its sample pattern turns every frame), which the flicker
            // metric reports.
            EXPECT_EQ(experiment::getNumber(row, "indirect_flicker.reference_change_rms"), 0.0);
            const double flicker = experiment::getNumber(row, "indirect_flicker.rms");
            EXPECT_TRUE(std::isfinite(flicker) && flicker >= 0.0) << flicker;
            EXPECT_GT(experiment::getNumber(row, "indirect_flicker.used_share"), 0.5);
        }
        const Image<glm::vec3> a = experiment::readExrRgb(culled[i].at("image.lit_hdr"));
        const Image<glm::vec3> b = experiment::readExrRgb(all[i].at("image.lit_hdr"));
        ASSERT_EQ(a.pixels.size(), b.pixels.size());
        EXPECT_EQ(
            std::memcmp(a.pixels.data(), b.pixels.data(), a.pixels.size() * sizeof(glm::vec3)), 0)
            << "lit frame " << i;
    }
}

// The study report of a game-frame run draws its filmstrip (the lit PNGs and the HDR error
// maps of every frame): the PNGs are read as PNGs, not through the EXR reader.
TEST(VoxelGiDriver, TheReportDrawsTheGameFramesFilmstrip)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_voxel_gi_driver_report";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto rows = runGameFrame("true", dir);
    ASSERT_EQ(rows.size(), 2u) << (rows.empty() ? "" : rows[0].at("error"));
    const report::ReportSummary summary =
        report::writeStudyReport((dir / "out_true_auto").string(), plugin::builtinRegistry());
    const bool filmstrip =
        std::any_of(summary.plots.begin(), summary.plots.end(), [](const std::string& p) {
            return std::filesystem::path(p).filename().string().rfind("filmstrip_", 0) == 0;
        });
    EXPECT_TRUE(filmstrip) << summary.plots.size() << " plots";
    EXPECT_TRUE(std::filesystem::exists(summary.html));
}

// The full-resolution combine (SSDO's 16 visibilities and the cones upsampled) on Vulkan, the
// gather's cones read where they were traced, gives the C++ combine's frame: the same RMSE to
// 1e-5 and the lit frame within 1e-4 per pixel (the float combine against the double one; the
// combine alone agrees to 5e-6, cone_combine_gpu_test.cpp).
TEST(VoxelGiDriver, TheVulkanCombineGivesTheCppCombinesFrame)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_voxel_gi_driver_combine";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto gpu = runGameFrame("true", dir, "vulkan");
    const auto cpu = runGameFrame("true", dir, "cpu");
    ASSERT_EQ(gpu.size(), 2u) << (gpu.empty() ? "" : gpu[0].at("error"));
    ASSERT_EQ(cpu.size(), 2u) << (cpu.empty() ? "" : cpu[0].at("error"));
    for (std::size_t i = 0; i < 2; ++i) {
        ASSERT_EQ(gpu[i].at("status"), "ok") << gpu[i].at("error");
        ASSERT_EQ(cpu[i].at("status"), "ok") << cpu[i].at("error");
        EXPECT_EQ(experiment::getNumber(gpu[i], "counter.combine_on_gpu"), 1.0);
        EXPECT_EQ(experiment::getNumber(cpu[i], "counter.combine_on_gpu"), 0.0);
        EXPECT_EQ(gpu[i].at("gather.cone_visibility"), "true");
        const double a = experiment::getNumber(gpu[i], "indirect.rmse");
        const double b = experiment::getNumber(cpu[i], "indirect.rmse");
        EXPECT_NEAR(a, b, 1e-5 * b) << "frame " << i;
        const Image<glm::vec3> x = experiment::readExrRgb(gpu[i].at("image.lit_hdr"));
        const Image<glm::vec3> y = experiment::readExrRgb(cpu[i].at("image.lit_hdr"));
        ASSERT_EQ(x.pixels.size(), y.pixels.size());
        std::size_t off = 0;
        for (std::size_t p = 0; p < x.pixels.size(); ++p)
            for (int c = 0; c < 3; ++c)
                off += std::abs(x.pixels[p][c] - y.pixels[p][c]) >
                               1e-4f * std::max(1e-2f, y.pixels[p][c])
                           ? 1
                           : 0;
        EXPECT_EQ(off, 0u) << "frame " << i;
    }
}

// The resident gather: the cascades' pixel cones (split near/far: the far cones marked,
// traced and kept on the device) and combine on Vulkan read the G-buffer and SSDO's visibilities
// where the frame keeps them and leave the irradiance in an image the lighting pass binds; nothing
// of the gather crosses the bus in the frame, and the irradiance comes to the CPU only for the
// measurements. The round trip (`frame: {gbuffer_on_gpu: false}`)
// gives the same frame: the same combine on the same cones but for the reduced positions, which
// the device rounds within a float ulp of the upload's (cone_combine_gpu_test.cpp): the lit
// frame within 1e-4 per pixel and the indirect RMSE within 1e-5.
TEST(VoxelGiDriver, TheResidentGatherKeepsTheFrameOnTheGpu)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_voxel_gi_driver_resident";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const std::string params = ", device: vulkan"; // split cones: the far cones resident too
    const auto resident = runGameFrame("true", dir, "vulkan", params);
    const auto roundTrip = runGameFrame("true", dir, "vulkan", params, ", gbuffer_on_gpu: false");
    ASSERT_EQ(resident.size(), 2u) << (resident.empty() ? "" : resident[0].at("error"));
    ASSERT_EQ(roundTrip.size(), 2u) << (roundTrip.empty() ? "" : roundTrip[0].at("error"));
    for (std::size_t i = 0; i < 2; ++i) {
        const auto& row = resident[i];
        ASSERT_EQ(row.at("status"), "ok") << row.at("error");
        ASSERT_EQ(roundTrip[i].at("status"), "ok") << roundTrip[i].at("error");
        EXPECT_EQ(row.at("voxel_gather.resident"), "yes");
        EXPECT_EQ(roundTrip[i].at("voxel_gather.resident").rfind("no: frame: {gbuffer_on_gpu: false}", 0), 0u)
            << roundTrip[i].at("voxel_gather.resident");
        EXPECT_EQ(row.at("gather.cone_visibility"), "true");
        // Frame 0 traces every level's far cones; frame 1 (a still camera, nothing changed)
        // keeps them all.
        EXPECT_EQ(experiment::getNumber(row, "counter.far_levels_dropped"), i == 0 ? 3.0 : 0.0);
        const std::string& passes = row.at("passes");
        EXPECT_NE(passes.find("indirect_gpu_slot:run"), std::string::npos) << passes;
        EXPECT_NE(passes.find("voxel_gather_readback:run"), std::string::npos) << passes;
        EXPECT_EQ(passes.find("indirect_upload"), std::string::npos) << passes;
        EXPECT_NE(roundTrip[i].at("passes").find("indirect_upload:run"), std::string::npos);
        // Read back for the measurements only: not frame time, not the frame's bytes.
        const std::string& framePasses = row.at("frame_passes");
        for (const char* measurementOnly : {"voxel_gather_readback", "gbuffer_readback", "occlusion_readback"})
            EXPECT_EQ(framePasses.find(measurementOnly), std::string::npos) << framePasses;
        EXPECT_EQ(experiment::getNumber(row, "voxel_gather.readback_bytes"), 0.0);
        EXPECT_EQ(experiment::getNumber(row, "frame.readback_bytes"), 0.0);
        EXPECT_GT(experiment::getNumber(roundTrip[i], "frame.readback_bytes"), 0.0);
        // The sky and the emitters through the cones on both paths: resident, combined on the
        // device; on the round trip, the same Vulkan cones' sky (the far cones' with it) read
        // back and combined in C++.
        EXPECT_EQ(row.at("frame.sky"), "cones");
        EXPECT_EQ(roundTrip[i].at("frame.sky"), "cones");
        EXPECT_EQ(row.count("voxel_cone_sky.none"), 0u);
        EXPECT_EQ(roundTrip[i].count("voxel_cone_sky.none"), 0u);
        const double a = experiment::getNumber(row, "indirect.rmse");
        const double b = experiment::getNumber(roundTrip[i], "indirect.rmse");
        EXPECT_NEAR(a, b, 1e-5 * b) << "frame " << i;
        const Image<glm::vec3> x = experiment::readExrRgb(row.at("image.lit_hdr"));
        const Image<glm::vec3> y = experiment::readExrRgb(roundTrip[i].at("image.lit_hdr"));
        ASSERT_EQ(x.pixels.size(), y.pixels.size());
        std::size_t off = 0;
        for (std::size_t p = 0; p < x.pixels.size(); ++p)
            for (int c = 0; c < 3; ++c)
                off += std::abs(x.pixels[p][c] - y.pixels[p][c]) > 1e-4f * std::max(1e-2f, y.pixels[p][c]) ? 1 : 0;
        EXPECT_EQ(off, 0u) << "frame " << i;
    }
}

// The sparse octree's resident gather traces the cones' sky and emitters with its light
// (cone_march.glsl) and combines them on the device into the image the lighting pass takes for
// its sky: the cornell box's ceiling light reaches the walls through the cones (`frame.sky` =
// cones) with nothing read back, and the round trip (the same Vulkan cones, their sky read back
// and combined in C++, then uploaded) gives the same lit frame within 1e-4 per pixel (the float
// combine against the double one, as above).
TEST(VoxelGiDriver, TheResidentSparseGatherLightsTheFrameWithItsConesSky)
{
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_voxel_gi_driver_resident_sky";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto run = [&](const std::string& frame) {
        const auto& registry = plugin::builtinRegistry();
        const auto e = experiment::parseExperiment(R"(base:
  scene: cornell_box
  resolution: [40, 30]
  frames: 1
  metrics: [error]
  frame: {lighting: true, shadow_map_size: 16)" + frame + R"(}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.2, target_rel_stderr: 0.5, max_samples: 8}
  techniques:
    occlusion: {technique: bentcone_ssdo}
    voxel_gi: {technique: svo, params: {resolution: 32, supersampling: 2, device: vulkan}}
)",
                                                   (dir / "svo.yaml").string(), registry);
        const std::string out = (dir / (frame.empty() ? "resident" : "round_trip")).string();
        experiment::runExperiment(e, registry, {.outputDirectory = out, .quiet = true, .queryVulkanForManifest = false});
        return experiment::loadResults(out);
    };
    const auto resident = run("");
    const auto roundTrip = run(", gbuffer_on_gpu: false");
    ASSERT_EQ(resident.size(), 1u);
    ASSERT_EQ(roundTrip.size(), 1u);
    const auto& row = resident[0];
    ASSERT_EQ(row.at("status"), "ok") << row.at("error");
    ASSERT_EQ(roundTrip[0].at("status"), "ok") << roundTrip[0].at("error");
    EXPECT_EQ(row.at("voxel_gather.resident"), "yes");
    EXPECT_EQ(row.at("frame.sky"), "cones");
    EXPECT_EQ(roundTrip[0].at("frame.sky"), "cones");
    EXPECT_EQ(row.count("voxel_cone_sky.none"), 0u) << row.at("voxel_cone_sky.none");
    const std::string& passes = row.at("passes");
    EXPECT_NE(passes.find("voxel_cone_sky:run"), std::string::npos) << passes;
    EXPECT_EQ(passes.find("cone_sky_upload"), std::string::npos) << passes;
    EXPECT_NE(roundTrip[0].at("passes").find("cone_sky_upload:run"), std::string::npos);
    EXPECT_EQ(experiment::getNumber(row, "frame.readback_bytes"), 0.0);
    const Image<glm::vec3> x = experiment::readExrRgb(row.at("image.lit_hdr"));
    const Image<glm::vec3> y = experiment::readExrRgb(roundTrip[0].at("image.lit_hdr"));
    ASSERT_EQ(x.pixels.size(), y.pixels.size());
    std::size_t off = 0;
    double lit = 0.0;
    for (std::size_t p = 0; p < x.pixels.size(); ++p)
        for (int c = 0; c < 3; ++c) {
            off += std::abs(x.pixels[p][c] - y.pixels[p][c]) > 1e-4f * std::max(1e-2f, y.pixels[p][c]) ? 1 : 0;
            lit += y.pixels[p][c];
        }
    EXPECT_EQ(off, 0u);
    EXPECT_GT(lit, 0.0);
}

// svo as a technique that claims a resident gather and then leaves no image on the GPU (`mode:
// none`) or one the lighting pass cannot bind (`mode: small`, a 1x1 R32Float image; `small_sky`,
// the right irradiance image and such a cone sky): the frame stops with an error that names the
// technique and what it left, never a stale image.
class ResidentButWrong final : public plugin::VoxelGiTechnique {
public:
    static plugin::TechniqueInfo describe() { return {.summary = "test double: a resident gather gone wrong"}; }
    static const plugin::TechniqueEntry& inner()
    {
        for (const auto* e : plugin::builtinRegistry().techniques("voxel_gi"))
            if (e->info.name == "svo")
                return *e;
        throw Error("svo is not registered");
    }
    static config::ParamSchema declareParams()
    {
        config::ParamSchema s = inner().schema;
        s.addEnum("mode", "none", {"none", "small", "small_sky"}, "what the resident gather leaves on the GPU");
        return s;
    }
    explicit ResidentButWrong(const config::ParamSet& p)
        : mMode(p.getString("mode")), mInner(inner().create(config::ParamSet::defaultsOf(inner().schema))),
          mTechnique(dynamic_cast<plugin::VoxelGiTechnique&>(*mInner))
    {
    }
    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p = mInner->effectiveParams();
        p.set("mode", mMode);
        return p;
    }
    plugin::VoxelGiDefinition definition() const override { return mTechnique.definition(); }
    plugin::VoxelGiStep voxelize(const plugin::VoxelGiFrame& f) override { return mTechnique.voxelize(f); }
    plugin::VoxelGiStep injectLight(const plugin::VoxelGiFrame& f) override { return mTechnique.injectLight(f); }
    plugin::VoxelGiMemory memory() const override { return mTechnique.memory(); }
    std::string whyNotGatheredOnGpu(const gpu::Context&) const override { return {}; }
    void gather(const plugin::VoxelGiInput& input, Image<glm::vec3>&) override
    {
        if (mMode == "small" && input.gpu != nullptr)
            mImage = input.gpu->createImage({gpu::ImageDimension::Image2D, gpu::Format::R32Float, 1, 1, 1,
                                             gpu::ImageUsage::StorageAndSampled, "test.small"});
        // A right irradiance image and a cone sky the lighting pass cannot bind.
        if (mMode == "small_sky" && input.gpu != nullptr && input.gpuGBuffer != nullptr) {
            mImage = input.gpu->createImage({gpu::ImageDimension::Image2D, gpu::Format::RGBA32Float,
                                             std::uint32_t(input.gpuGBuffer->width),
                                             std::uint32_t(input.gpuGBuffer->height), 1,
                                             gpu::ImageUsage::StorageAndSampled, "test.irradiance"});
            mSky = input.gpu->createImage({gpu::ImageDimension::Image2D, gpu::Format::R32Float, 1, 1, 1,
                                           gpu::ImageUsage::StorageAndSampled, "test.small_sky"});
        }
    }
    const gpu::Image* getGpuIrradiance() const override { return mImage.isValid() ? &mImage : nullptr; }
    const gpu::Image* getGpuConeSky() const override { return mSky.isValid() ? &mSky : nullptr; }
    void readBackIrradiance(Image<glm::vec3>& irradiance) override
    {
        irradiance = Image<glm::vec3>(int(mImage.getDesc().width), int(mImage.getDesc().height), glm::vec3(0.0f));
    }

private:
    std::string mMode;
    std::unique_ptr<plugin::Technique> mInner;
    plugin::VoxelGiTechnique& mTechnique;
    gpu::Image mImage, mSky;
};

TEST(VoxelGiDriver, AResidentGatherThatLeavesNoUsableImageStopsTheFrameWithAClearError)
{
    auto registry = test::makeTestRegistry();
    plugin::registerTechnique<ResidentButWrong>(registry, "voxel_gi", "resident_but_wrong");
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_voxel_gi_driver_wrong";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    for (const std::string mode : {"none", "small", "small_sky"}) {
        const auto e = experiment::parseExperiment(R"(base:
  scene: cornell_box
  resolution: [24, 16]
  frames: 1
  metrics: [error]
  frame: {lighting: true, shadow_map_size: 16}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.2, target_rel_stderr: 0.5, max_samples: 4}
  techniques:
    voxel_gi: {technique: resident_but_wrong, params: {resolution: 16, mode: )" + mode + R"(}}
)",
                                                   (dir / (mode + ".yaml")).string(), registry);
        const std::string out = (dir / mode).string();
        experiment::runExperiment(e, registry, {.outputDirectory = out, .quiet = true, .queryVulkanForManifest = false});
        const auto rows = experiment::loadResults(out);
        ASSERT_EQ(rows.size(), 1u);
        EXPECT_EQ(rows[0].at("status"), "failed");
        const std::string& error = rows[0].at("error");
        EXPECT_NE(error.find("technique 'resident_but_wrong'"), std::string::npos) << error;
        const char* expected = mode == "none"    ? "left no irradiance there"
                               : mode == "small" ? "left a 1x1 R32_SFLOAT irradiance image"
                                                 : "left a 1x1 R32_SFLOAT cone sky image";
        EXPECT_NE(error.find(expected), std::string::npos) << error;
    }
}

TEST(VoxelGiDriver, TheSplitCoversTheConesSky)
{
    // A lit frame whose sky comes through the cones, with the split: the sky's error against the
    // truth's direct irradiance without point lights (sky.*), split into the voxels' (rays
    // through them, split.sky_voxel_*) and the cones' (against those rays, split.sky_cone_*).
    // The three RMSEs are norms of differences over the same pixels, so the whole is at most the
    // sum of its halves (the triangle inequality); and the sky term's images are written.
    const auto dir = std::filesystem::temp_directory_path() / "rtlab_voxel_gi_sky_split";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto& registry = plugin::builtinRegistry();
    const auto e = experiment::parseExperiment(R"(base:
  scene: cornell_box
  resolution: [40, 30]
  frames: 1
  metrics: [error, split]
  frame: {lighting: true, shadow_map_size: 16}
  timing: {warmup: 0, repeats: 1}
  reference: {target_stderr: 0.2, target_rel_stderr: 0.5, max_samples: 8}
  techniques:
    occlusion: {technique: bentcone_ssdo}
    voxel_gi: {technique: svo, params: {resolution: 16, trace_step: 2}}
)",
                                               (dir / "split.yaml").string(), registry);
    const std::string out = (dir / "out").string();
    experiment::runExperiment(e, registry, {.outputDirectory = out, .quiet = true, .queryVulkanForManifest = false});
    const auto rows = experiment::loadResults(out);
    ASSERT_EQ(rows.size(), 1u);
    const auto& row = rows[0];
    ASSERT_EQ(row.at("status"), "ok") << row.at("error");
    EXPECT_EQ(row.at("frame.sky"), "cones");
    const std::string& passes = row.at("passes");
    EXPECT_NE(passes.find("voxel_sky_rays:run"), std::string::npos) << passes;
    EXPECT_NE(passes.find("metric.sky_split:run"), std::string::npos) << passes;
    const double whole = experiment::getNumber(row, "sky.rmse");
    const double cone = experiment::getNumber(row, "split.sky_cone_rmse");
    const double voxel = experiment::getNumber(row, "split.sky_voxel_rmse");
    ASSERT_TRUE(std::isfinite(whole) && std::isfinite(cone) && std::isfinite(voxel));
    EXPECT_GT(whole, 0.0);
    EXPECT_LE(whole, (cone + voxel) * (1.0 + 1e-6));
    EXPECT_TRUE(std::filesystem::exists(out + "/runs/" + row.at("run_id") + "/frame0/sky_term.exr"));
    EXPECT_TRUE(std::filesystem::exists(out + "/runs/" + row.at("run_id") + "/frame0/truth_sky_term.exr"));
}

} // namespace
