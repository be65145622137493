#pragma once
// The pixel gather of the cascades on Vulkan (shaders/cascade_gather.comp): the levels'
// pre-combined direction buffers live in one storage buffer, re-uploaded per level only when the
// level was re-voxelized or re-lit; positions go up relative to the coarsest level's centre.
// Asked for the cones' sky, the same dispatches also trace the sky and emitters each cone sees
// past the voxels (the far cones' too), from the levels' faces (occupancy and emission, uploaded
// the same way, only while the sky is traced).

#include "cascade_volume.h"

#include "families/voxel_gi/cone_gather_gpu.h"
#include "gpu/context.h"

#include <filesystem>
#include <optional>
#include <vector>

namespace rtlab::voxelgi {

//! A level as the Vulkan passes see it (shaders/cascade_common.glsl `Level`).
struct GpuCascadeLevel {
    glm::vec4 origin{0.0f};                     //!< min corner relative to the anchor, voxel size
    glm::vec4 centre{0.0f, 0.0f, 0.0f, -1.0f}; //!< centre, radius of its selection sphere (< 0: empty)
};
//! What positions on the GPU are relative to: the coarsest voxelized level's centre (float
//! precision far from the origin).
glm::dvec3 getGpuAnchor(const CascadeVolume& volume);
//! The levels relative to `anchor`; those not voxelized, and with `needCombined` those without
//! pre-combined buffers, are empty.
std::vector<GpuCascadeLevel> describeGpuLevels(const CascadeVolume& volume, const glm::dvec3& anchor,
                                               bool needCombined);

class CascadeGatherGpu {
public:
    static constexpr const char* kDispatchLabel = "cascades.gather";

    //! CascadeVolume::gatherCones on the GPU: the radiance of each of the 16 cones at every
    //! pixel, [pixel * 16 + cone]. Needs pre-combined buffers (CascadeSettings::precombine); with
    //! split cones (farStart > 0), volume.prepareFarCones(gbuffer) called first.
    void gatherCones(gpu::Context& context, const CascadeVolume& volume,
                     const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out);
    //! The same without the read-back: the radiances stay on the device, in the returned buffer
    //! (for cone_combine_gpu.h), valid until the next call.
    const gpu::Buffer& gatherConesOnDevice(gpu::Context& context, const CascadeVolume& volume,
                                           const scene::GBuffer& gbuffer);
    //! The same from pixels reduced on the device (the resident gather, cone_combine_gpu.h
    //! gatherConesResident): the dispatch holds the radiances and the representatives. With
    //! split cones the far cones stay on the device too: per level voxel a state and 16
    //! radiances; in one submission the pixels mark the voxels they will read, the marked ones
    //! not yet traced are traced and committed, then the pixels' cones run (what
    //! CascadeVolume::prepareFarCones does on the CPU for the other paths). A level's far cones
    //! are dropped when a level they sample changed (CascadeVolume::invalidateFarCones' rule).
    const PixelConeDispatch& gatherConesResident(gpu::Context& context, const CascadeVolume& volume,
                                                 const PixelSource& pixels);
    //! CascadeVolume::FarConeTracer on Vulkan: the 16 far cones of each voxel centre, through
    //! the same pre-combined buffers (uploaded when they changed), [centre * 16 + cone]; with
    //! `sky` (and setConeSky) their sky and emitters too.
    void traceFarCones(gpu::Context& context, const CascadeVolume& volume,
                       const std::vector<std::pair<int, std::uint32_t>>& centres, std::vector<glm::vec3>& out,
                       std::vector<glm::vec3>* sky = nullptr);
    //! Whether the following gathers also trace the sky and emitters each cone sees past the
    //! voxels (the sky per cone, computeSkyPerCone), or not (nullopt).
    void setConeSky(const std::optional<std::array<glm::vec3, kConeCount>>& skyPerCone) { mSkyPerCone = skyPerCone; }
    //! Whether the last gather over pixels traced the cones' sky (asked for it, and with split
    //! cones every far cone traced with it).
    bool tracedSky() const { return mLastTracedSky; }
    //! The cones' sky of the last gather over pixels, which traced it, [pixel * 16 + cone].
    void readBackSky(std::vector<glm::vec3>& out) const { mDispatch.readBackSky(out); }
    //! GPU time of the last dispatch, when the device has timestamps.
    std::optional<double> getLastGpuMs() const { return mLastGpuMs ? mLastGpuMs : mDispatch.getDeferredGpuMs(); }
    //! Bytes uploaded by the last call (levels that changed, pixels).
    std::size_t getLastUploadBytes() const { return mLastUploadBytes; }
    //! Levels whose resident far cones the last resident gather dropped (their inputs changed).
    std::size_t getLastFarLevelsDropped() const { return mLastFarLevelsDropped; }
    //! $RTLAB_SOURCE_DIR/techniques/voxel_gi/cascades/shaders when set, else the source folder.
    static std::filesystem::path getShaderDir();

private:
    void trace(gpu::Context& context, const CascadeVolume& volume, const PixelSource& pixels,
               std::vector<glm::vec3>* out);
    // The pipeline for `context`, the levels' descriptors and the pre-combined buffers of the
    // levels that changed; returns the anchor positions are relative to.
    glm::dvec3 prepare(gpu::Context& context, const CascadeVolume& volume);
    // The far cones of split cone tracing (or placeholders when off), when they changed.
    void uploadFarCones(const CascadeVolume& volume);

    PixelConeDispatch mDispatch;
    gpu::Buffer mLevels, mCombined;
    // The cones' sky: the levels' faces (emission, occupancy) and what was uploaded of them; the
    // far cones' sky (uploaded far cones, resident ones) and the sky the resident ones hold.
    std::optional<std::array<glm::vec3, kConeCount>> mSkyPerCone;
    gpu::Buffer mFaces, mFarSky, mResidentFarSky;
    std::vector<std::uint64_t> mUploadedFaceStamps;
    std::optional<std::array<glm::vec3, kConeCount>> mResidentFarSkyOf;
    std::uint32_t mEmittingLevels = 0; //!< bit i: level i emits (its faces are bound)
    bool mFarSkyUploaded = false; //!< the uploaded far cones carry their sky
    bool mLastTracedSky = false;
    gpu::Buffer mFarSlots, mFarCones; //!< split cones: slot per level voxel, radiance per slot
    std::vector<std::pair<std::uint64_t, std::size_t>> mUploadedFar; //!< per level: stamp, slots
    // The resident far cones: per level voxel a state (0 none, 1 wanted, 2 traced) and 16
    // radiances; per level the stamps of the levels its far cones sampled when last dropped.
    gpu::Buffer mResidentFarState, mResidentFarCones;
    // The voxels listed for tracing: a 32-byte header (count, two dispatchIndirect argument
    // triples) and one uint per voxel (shaders/cascade_gather.comp FarListBuffer); a 64-byte
    // placeholder where the far cones are not resident.
    gpu::Buffer mResidentFarList, mFarListPlaceholder;
    std::size_t mResidentFarVoxels = 0;
    std::vector<std::vector<std::uint64_t>> mResidentFarInputs;
    std::size_t mLastFarLevelsDropped = 0;
    std::size_t mCombinedLevelVoxels = 0;
    int mCombinedLevelCount = 0;
    std::vector<std::uint64_t> mUploadedStamps;
    std::optional<double> mLastGpuMs;
    std::size_t mLastUploadBytes = 0;
};

} // namespace rtlab::voxelgi
