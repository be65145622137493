#pragma once
// The voxel_gi technique around a sparse cone-traced structure (svo, adaptive_voxel_tree_cones):
// rebuilt only when the static geometry changes and re-lit only when it or the lights change
// (each skip recorded with its reason), the pixel gather on Vulkan or in C++ at one pixel per
// trace_step^2 block upsampled with the occlusion family's cone visibilities and the characters'
// capsules, the error split's rays, memory and counters. A technique gives its structure, its
// Vulkan gather and how the structure is built over a scene.
//
// Structure: injectLight(scene), getCones(), gatherCones(gbuffer, out), gatherRays(gbuffer, rays,
// out), getLeaves(), getLeafSize(), getMeanStepsPerCone(), getTopologyBytes(), getPayloadBytes().
// Gpu: gatherCones(context, structure, gbuffer, out), gatherConesOnDevice(context, structure,
// gbuffer), gatherConesResident(context, structure, pixels), setConeSky(skyPerCone),
// readBackSky(out), getLastGpuMs(), getLastUploadBytes(). On a GPU the cones stay on the device and the
// combine runs there too (cone_combine_gpu.h shouldCombineOnGpu). Asked for the cones' sky
// (VoxelGiInput::coneSky), every path traces it with the light: in C++, on Vulkan and read back
// for combineConeSky, or resident, combined on the device (getGpuConeSky).

#include "families/voxel_gi/cone_combine_gpu.h"
#include "families/voxel_gi/sparse_cone_params.h"
#include "families/voxel_gi/upsample.h"
#include "families/voxel_gi/voxel_gi.h"
#include "core/error.h"

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace rtlab::voxelgi {

template <class Structure, class Gpu>
class SparseConeTechnique : public plugin::VoxelGiTechnique {
public:
    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p;
        mParams.write(p);
        writeStructureParams(p);
        return p;
    }

    plugin::VoxelGiDefinition definition() const override
    {
        // The walls' interior beyond the inner layers is not stored (voxel_gi.h surfacesOnly).
        return {.bounces = mParams.bounces, .surfacesOnly = true};
    }

    plugin::VoxelGiStep voxelize(const plugin::VoxelGiFrame& frame) override
    {
        if (mBuilt && frame.geometryKey == mGeometryKey && !frame.force)
            return plugin::VoxelGiStep::skipped("the static geometry is unchanged since the build");
        const std::string why = !mBuilt                              ? "first build"
                                : frame.geometryKey != mGeometryKey ? "geometry changed"
                                                                    : "culling off";
        const std::string what = build(*frame.geometry);
        mBuilt = true;
        mGeometryKey = frame.geometryKey;
        mLightsKey.clear();
        return plugin::VoxelGiStep::done(why + ": " + what);
    }

    plugin::VoxelGiStep injectLight(const plugin::VoxelGiFrame& frame) override
    {
        const std::string lightsKey = computeLightsKey(*frame.geometry);
        if (lightsKey == mLightsKey && !frame.force)
            return plugin::VoxelGiStep::skipped("the structure and the lights are unchanged since it was lit");
        mStructure->injectLight(*frame.geometry);
        mLightsKey = lightsKey;
        return plugin::VoxelGiStep::done("lit " + std::to_string(mStructure->getLeaves().size()) + " leaves, " +
                                         std::to_string(mParams.bounces) + " passes");
    }

    std::string whyNotGatheredOnGpu(const gpu::Context& gpu) const override
    {
        if (!shouldGatherOnGpu(&gpu, mParams.device))
            return "the pixel cones run in C++ (device: " + mParams.device +
                   (mParams.device == "auto" ? " on a CPU device" : "") + ")";
        return {};
    }

    const gpu::Image* getGpuIrradiance() const override { return mCombineGpu.getResidentOutput(); }

    void readBackIrradiance(Image<glm::vec3>& irradiance) override
    {
        irradiance = mCombineGpu.readBackResident();
    }

    const gpu::Image* getGpuConeSky() const override
    {
        return mSkyOnGpu ? mSkyCombineGpu.getResidentOutput() : nullptr;
    }

    void readBackConeSky(Image<glm::vec3>& irradiance) override
    {
        if (!mSkyOnGpu)
            throw Error("the last gather traced no cone sky on the GPU");
        irradiance = mSkyCombineGpu.readBackResident();
    }

    void gather(const plugin::VoxelGiInput& input, Image<glm::vec3>& irradiance) override
    {
        mSky.cones.clear();
        mSkyOnGpu = false;
        // The cones' sky and emitters, traced with the light when the frame asks for them.
        std::optional<std::array<glm::vec3, kConeCount>> skyPerCone;
        if (input.coneSky && input.scene != nullptr)
            skyPerCone = computeSkyPerCone(input.scene->sky, mStructure->getCones());
        if (input.gpuGBuffer != nullptr) {
            // Resident: the pixels reduced on the device, their cones and the combine there.
            if (input.gpu == nullptr || !whyNotGatheredOnGpu(*input.gpu).empty())
                throw Error("the G-buffer was given on the GPU to a gather that does not run there");
            mGatheredOnGpu = mCombinedOnGpu = true;
            mGpu.setConeSky(skyPerCone);
            gatherConesResident(
                *input.gpu, mCombineGpu, *input.gpuGBuffer, mParams.traceStep,
                mStructure->getCones().halfAngle, input.gpuConeVisibility, input.capsules,
                [&](const PixelSource& pixels) -> const PixelConeDispatch& {
                    return mGpu.gatherConesResident(*input.gpu, *mStructure, pixels);
                },
                &mCombineMs, mParams.capsules, skyPerCone ? &mSkyCombineGpu : nullptr);
            mSkyOnGpu = skyPerCone.has_value();
            if (input.readBack)
                readBackIrradiance(irradiance);
            return;
        }
        mGatheredOnGpu = shouldGatherOnGpu(input.gpu, mParams.device);
        mCombinedOnGpu = shouldCombineOnGpu(input.gpu, mGatheredOnGpu);
        if (mGatheredOnGpu)
            mGpu.setConeSky(skyPerCone);
        if (mCombinedOnGpu) {
            irradiance = gatherConesReducedOnGpu(
                *input.gpu, mCombineGpu, *input.gbuffer, mParams.traceStep,
                mStructure->getCones().halfAngle, input.coneVisibility, input.capsules,
                [&](const scene::GBuffer& reduced) -> const gpu::Buffer& {
                    return mGpu.gatherConesOnDevice(*input.gpu, *mStructure, reduced);
                },
                &mCombineMs, mParams.capsules);
            if (skyPerCone) {
                // The cones' sky comes to the CPU for combineConeSky (this path's round trip).
                mGpu.readBackSky(mSky.cones);
                keepConeSky(mSky, *input.gbuffer, mParams.traceStep, mStructure->getCones().halfAngle,
                            input.capsules, mParams.capsules);
            }
            return;
        }
        ConeSkyOutput sky;
        if (skyPerCone)
            sky.skyPerCone = *skyPerCone;
        irradiance = gatherConesReduced(
            *input.gbuffer, mParams.traceStep, mStructure->getCones().halfAngle,
            input.coneVisibility, input.capsules,
            [&](const scene::GBuffer& reduced, std::vector<glm::vec3>& cones,
                std::vector<glm::vec3>* skyCones) {
                if (mGatheredOnGpu) {
                    mGpu.gatherCones(*input.gpu, *mStructure, reduced, cones);
                    if (skyPerCone && skyCones != nullptr)
                        mGpu.readBackSky(*skyCones);
                } else {
                    sky.out = skyCones;
                    mStructure->gatherCones(reduced, cones, skyPerCone ? &sky : nullptr);
                }
            },
            &mCombineMs, mParams.capsules, &mSky);
    }

    std::string combineConeSky(const plugin::VoxelGiInput& input, Image<glm::vec3>& irradiance) override
    {
        if (!mSky.isValid())
            return "the last gather traced no cone sky";
        irradiance = voxelgi::combineConeSky(mSky, *input.gbuffer, mStructure->getCones().halfAngle,
                                             input.coneVisibility, input.capsules);
        return {};
    }

    bool traceVoxelRays(const plugin::VoxelGiInput& input, int raysPerPixel, Image<glm::vec3>& irradiance) override
    {
        irradiance = traceRaysReduced(*input.gbuffer, mParams.traceStep,
                                      [&](const scene::GBuffer& reduced, Image<glm::vec3>& low) {
                                          mStructure->gatherRays(reduced, raysPerPixel, low);
                                      });
        return true;
    }

    bool traceVoxelSkyRays(const plugin::VoxelGiInput& input, int raysPerPixel, const scene::Sky& sky,
                           Image<glm::vec3>& irradiance) override
    {
        irradiance = traceRaysReduced(*input.gbuffer, mParams.traceStep,
                                      [&](const scene::GBuffer& reduced, Image<glm::vec3>& low) {
                                          mStructure->gatherRays(reduced, raysPerPixel, low, &sky);
                                      });
        return true;
    }

    plugin::VoxelGiMemory memory() const override
    {
        if (!mBuilt)
            return {};
        return {.topologyBytes = mStructure->getTopologyBytes(), .payloadBytes = mStructure->getPayloadBytes()};
    }

    std::vector<std::pair<std::string, double>> counters() const override
    {
        if (!mBuilt)
            return {};
        std::vector<std::pair<std::string, double>> c = {
            {"voxel_size", mStructure->getLeafSize()},
            {"leaves", double(mStructure->getLeaves().size())},
            {"steps_per_cone", mGatheredOnGpu ? std::nan("") : mStructure->getMeanStepsPerCone()}};
        appendGatherCounters(c, mGatheredOnGpu, mGpu.getLastGpuMs(), mGpu.getLastUploadBytes(),
                             mCombineMs, mCombinedOnGpu, mCombineGpu);
        for (auto& extra : structureCounters())
            c.push_back(std::move(extra));
        return c;
    }

protected:
    explicit SparseConeTechnique(const config::ParamSet& p) : mParams(SparseConeParams::read(p)) {}

    //! Builds mStructure over the scene's static geometry; returns what it built, for the row.
    virtual std::string build(const scene::RenderScene& geometry) = 0;
    //! The parameters of the structure beyond SparseConeParams.
    virtual void writeStructureParams(config::ParamSet&) const {}
    //! Counters of the structure beyond the shared ones (its node counts).
    virtual std::vector<std::pair<std::string, double>> structureCounters() const { return {}; }

    SparseConeParams mParams;
    std::optional<Structure> mStructure;

private:
    Gpu mGpu;
    ConeCombineGpu mCombineGpu;
    ConeCombineGpu mSkyCombineGpu; // the resident gather's cones' sky
    bool mSkyOnGpu = false;        // the last gather left its cones' sky in mSkyCombineGpu
    ConeSkyTrace mSky; // the last gather's cones' sky on the CPU, for combineConeSky
    std::string mGeometryKey, mLightsKey;
    bool mBuilt = false;
    bool mGatheredOnGpu = false;
    bool mCombinedOnGpu = false;
    double mCombineMs = std::nan(""); // the gather beyond its cones: reduction and combine
};

} // namespace rtlab::voxelgi
