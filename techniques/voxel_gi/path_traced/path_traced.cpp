// path_traced: Embree path tracing of the indirect irradiance at a fixed number of paths per
// pixel, the equal-time baseline of the voxel GI studies: how good is brute force for the time a
// voxel structure takes?
//
// Registry key: voxel_gi/path_traced
//
// What it computes: exactly the ground truth's quantity (reference/reference.h "indirect": the
// irradiance of light reflected 1..bounces times, same lights, next-event estimation and MIS) by
// the ground truth's estimator, stopped after samples_per_pixel paths: no stopping rule, no cache,
// its own seed (a new one each frame), so its error is its noise and not correlated with the
// ground truth's. Rays go against the frame's full triangle scene (characters included) with
// Embree on the CPU, all threads; its time is CPU time (technique_time_source = cpu), like the
// CPU path of the voxel techniques, so at equal time the two had the same processor.
// It keeps no voxels: voxelize and injectLight are skipped with that reason.
//
// Parameters
// | name              | type | default | range      | unit  |
// |-------------------|------|---------|------------|-------|
// | samples_per_pixel | int  | 4       | [1, 65536] | paths |
// | bounces           | int  | 2       | [1, 8]     |       |
//
// Config example (the equal-time sweep of experiments/voxel_gi.yaml):
//   techniques: {voxel_gi: {technique: path_traced, params: {samples_per_pixel: 16}}}
//   sweep: {voxel_gi.samples_per_pixel: [1, 4, 16, 64]}

#include "core/error.h"
#include "families/voxel_gi/voxel_gi.h"
#include "reference/reference.h"

namespace {

using namespace rtlab;

class PathTraced final : public plugin::VoxelGiTechnique {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "Embree path tracing at N paths per pixel (equal-time baseline)",
                .reference = "the ground truth's estimator, stopped at a fixed sample count",
                .seed = ""};
    }

    static config::ParamSchema declareParams()
    {
        config::ParamSchema schema;
        schema.addInt("samples_per_pixel", 4, 1, 65536, "paths", "paths per pixel");
        schema.addInt("bounces", 2, 1, 8, "", "reflections before the light reaches the pixel");
        return schema;
    }

    explicit PathTraced(const config::ParamSet& p)
        : mSamples(int(p.getInt("samples_per_pixel"))), mBounces(int(p.getInt("bounces")))
    {
    }

    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p;
        p.set("samples_per_pixel", std::int64_t(mSamples));
        p.set("bounces", std::int64_t(mBounces));
        return p;
    }

    plugin::VoxelGiDefinition definition() const override { return {.bounces = mBounces}; }

    plugin::VoxelGiStep voxelize(const plugin::VoxelGiFrame&) override
    {
        return plugin::VoxelGiStep::skipped("path tracing keeps no voxels");
    }

    plugin::VoxelGiStep injectLight(const plugin::VoxelGiFrame&) override
    {
        return plugin::VoxelGiStep::skipped("path tracing keeps no voxels");
    }

    void gather(const plugin::VoxelGiInput& input, Image<glm::vec3>& irradiance) override
    {
        if (input.scene == nullptr)
            throw Error("path_traced needs the frame's triangle scene (VoxelGiInput::scene)");
        if (input.scene->indices.empty()) {
            // Nothing to reflect light: no indirect light anywhere.
            irradiance = Image<glm::vec3>(input.gbuffer->width, input.gbuffer->height,
                                          glm::vec3(0.0f));
            return;
        }
        // Not the ground truth's seed (0), and a new one every frame.
        const reference::ReferenceSettings s = reference::makeFixedSampleSettings(
            reference::Quantity::Indirect, mBounces, mSamples,
            0x5eed0000ull + std::uint64_t(input.frameIndex));
        irradiance = reference::computeReference(*input.scene, *input.gbuffer, s).irradiance;
    }

    plugin::VoxelGiMemory memory() const override { return {}; }

private:
    int mSamples;
    int mBounces;
};

} // namespace

RTLAB_REGISTER_TECHNIQUE(voxel_gi, path_traced, PathTraced)
