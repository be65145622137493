#pragma once
// Light injection of the cascades on Vulkan (shaders/cascade_inject.comp): the 16 cones and the
// point lights' shadow cones of every surface voxel of a level, the part of an update that costs
// (CascadeVolume::IrradianceGather). The light buffers stay CascadeVolume's: a level's buffers go
// up when they changed since they were last uploaded (Level::lightRevision), and the irradiance
// per face comes back for the C++ side to reflect, propagate inward and pre-combine.

#include "cascade_volume.h"

#include "gpu/context.h"

#include <filesystem>
#include <optional>
#include <vector>

namespace rtlab::voxelgi {

class CascadeInjectGpu {
public:
    static constexpr const char* kDispatchLabel = "cascades.inject";

    //! The irradiance per face of the surface voxels of level `level`, as gatherVoxelIrradiance
    //! over volume.sampleFields gives it (in float, positions relative to the coarsest level's
    //! centre).
    void gatherIrradiance(gpu::Context& context, const CascadeVolume& volume, int level,
                          const InjectionLights& lights, std::vector<FaceIrradiance>& out);
    //! Sums over the calls since resetCounters: GPU time (when the device has timestamps), wall
    //! time from submit to completion, wall time of the whole call (packing, uploads, read-back),
    //! bytes uploaded, dispatches.
    struct Counters {
        double gpuMs = 0.0;
        bool timed = true;
        double submitMs = 0.0;
        double callMs = 0.0;
        std::size_t uploadBytes = 0;
        int dispatches = 0;
    };
    const Counters& getCounters() const { return mCounters; }
    void resetCounters() { mCounters = {}; }

private:
    gpu::Context* mContext = nullptr;
    gpu::ComputePipeline mPipeline;
    gpu::Buffer mLevels, mFields, mVoxels, mOutput, mCones, mSky, mLights;
    std::size_t mFieldLevelFaces = 0;
    std::vector<std::uint64_t> mUploadedRevision; //!< per level: Level::lightRevision uploaded
    Counters mCounters;

    // A buffer of at least `bytes`; `hostVisible` for data that crosses the bus once per call
    // (gpu::BufferDesc::hostVisible).
    gpu::Buffer& reserve(gpu::Buffer& buffer, std::size_t bytes, const char* name,
                         bool hostVisible = false);
};

} // namespace rtlab::voxelgi
