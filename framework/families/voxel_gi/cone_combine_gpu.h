#pragma once
// The final combine of a cone-traced gather on Vulkan (shaders/cone_combine.comp): combineCones
// (upsample.h) per full-resolution pixel, reading the cone radiances where the pixel cone
// dispatch left them on the device, so that only the full-resolution irradiance comes back.
// Shared by the structures gathered on Vulkan (cascades, svo, adaptive_voxel_tree_cones).

#include "families/voxel_gi/upsample.h"
#include "gpu/context.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rtlab::voxelgi {

class ConeCombineGpu {
public:
    static constexpr const char* kDispatchLabel = "voxel_gi.combine";

    //! combineCones(in) on `context`, with the cone radiances [low-res pixel * 16 + cone] (vec4)
    //! in `coneRadiance` (in.coneRadiance is not read). With the capsules at the traced pixels
    //! (in.capsuleResolution) `coneRadiance` is multiplied by their visibility in place.
    Image<glm::vec3> combine(gpu::Context& context, const gpu::Buffer& coneRadiance,
                             const ConeCombineInputs& in);
    //! The same with in.coneRadiance uploaded first.
    Image<glm::vec3> combine(gpu::Context& context, const ConeCombineInputs& in);
    //! Uploads cone radiances traced elsewhere (the C++ gather) for combine(context, buffer, in);
    //! the buffer is valid until the next call.
    const gpu::Buffer& uploadCones(gpu::Context& context,
                                   const std::vector<glm::vec3>& coneRadiance);

    //! GPU time of the last dispatch, when the device has timestamps.
    std::optional<double> getLastGpuMs() const { return mLastGpuMs; }
    //! Bytes uploaded by the last call (G-buffer, visibilities, capsules).
    std::size_t getLastUploadBytes() const { return mLastUploadBytes; }
    //! $RTLAB_SOURCE_DIR/framework/families/voxel_gi/shaders when set, else the source folder.
    static std::filesystem::path getShaderDir();

private:
    // The pipeline on `context`, the cone directions compiled in (everything anew for another
    // context).
    void prepare(gpu::Context& context);
    // A buffer of at least `bytes`; every one here is written or read once per frame, so all are
    // gpu::BufferDesc::hostVisible.
    gpu::Buffer& reserve(gpu::Buffer& buffer, std::size_t bytes, const char* name);

    gpu::Context* mContext = nullptr;
    gpu::ComputePipeline mPipeline;
    gpu::Buffer mRepresentative, mPositions, mNormals, mDepths, mMaterials, mVisibility, mCapsules,
        mOutput, mUploadedCones;
    std::optional<double> mLastGpuMs;
    std::size_t mLastUploadBytes = 0;
};

//! Where a gather's combine runs for `setting` "vulkan", "cpu" or "auto" (without a device, in
//! C++). "auto": on Vulkan when the cones were traced there and the device is a GPU; in C++ when
//! they were traced in C++ or the device is a CPU implementation such as lavapipe, where the C++
//! combine is the faster (at 1280x720 on 2 cores: 62 against 232-240 ms, and 77 against 808 ms with
//! 10 capsules; cone_combine_gpu_test's DISABLED_Timing).
bool shouldCombineOnGpu(const gpu::Context* context, bool gatheredOnGpu,
                        std::string_view setting = "auto");

//! Whether the pixel gather runs on Vulkan for the `device` setting of a cone-traced technique:
//! "vulkan" wherever a Vulkan context is given, "cpu" never, "auto" on a GPU only (a context whose
//! device is not a CPU implementation such as lavapipe, where the C++ gather is the faster:
//! README, "Voxel GI").
bool shouldGatherOnGpu(const gpu::Context* context, std::string_view setting);

//! Appends the counters of a cone-traced gather's two steps, the same in every technique:
//! gather_on_gpu, gather_gpu_ms, gather_upload_bytes (the cones), combine_ms (the reduction and
//! the combine, wall time), combine_on_gpu, combine_gpu_ms, combine_upload_bytes.
void appendGatherCounters(std::vector<std::pair<std::string, double>>& counters, bool gatheredOnGpu,
                          std::optional<double> gatherGpuMs, std::size_t gatherUploadBytes,
                          double combineMs, bool combinedOnGpu, const ConeCombineGpu& combiner);

//! gatherConesReduced (upsample.h) with the cones kept on the device: `traceCones(reduced)` runs
//! a Vulkan pixel cone dispatch without reading back and returns its output buffer
//! ([low-res pixel * 16 + cone], vec4), and `combiner` brings it to full resolution on the same
//! device, the capsules tested where `capsuleResolution` says. `combineMs`, when given, receives
//! the wall time of the reduction and the combine.
Image<glm::vec3> gatherConesReducedOnGpu(
    gpu::Context& context, ConeCombineGpu& combiner, const scene::GBuffer& full, int traceStep,
    double coneHalfAngle, const std::vector<Image<float>>* visibility,
    const std::vector<scene::PosedCapsule>* capsules,
    const std::function<const gpu::Buffer&(const scene::GBuffer&)>& traceCones,
    double* combineMs = nullptr, CapsuleResolution capsuleResolution = CapsuleResolution::Full);

} // namespace rtlab::voxelgi
