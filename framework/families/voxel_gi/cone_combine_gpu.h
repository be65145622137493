#pragma once
// The final combine of a cone-traced gather on Vulkan (shaders/cone_combine.comp): combineCones
// (upsample.h) per full-resolution pixel, reading the cone radiances where the pixel cone
// dispatch left them on the device, so that only the full-resolution irradiance comes back.
// Shared by the structures gathered on Vulkan (cascades, svo, adaptive_voxel_tree_cones).

#include "families/voxel_gi/cone_gather_gpu.h"
#include "families/voxel_gi/upsample.h"
#include "gpu/context.h"

#include <array>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rtlab::voxelgi {

//! The inputs of the resident combine (ConeCombineGpu::combineResident): everything where the
//! frame keeps it on the GPU but the capsules (a few vec4 per character).
struct ResidentCombineInputs {
    const plugin::VoxelGiGpuGBuffer* gbuffer = nullptr;
    //! Cone k's visibility in channel k % 4 of RGBA32Float image k / 4; all null: none.
    std::array<const gpu::Image*, 4> visibility{};
    const std::vector<scene::PosedCapsule>* capsules = nullptr; //!< or null
    double coneHalfAngle = 0.5;                                 //!< radians
    CapsuleResolution capsuleResolution = CapsuleResolution::Full;
};

//! The combine shader's push constants (cone_combine_gpu.cpp).
struct CombineConstants;

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
    //! The combine of cones traced from pixels that `dispatch` reduced on the device
    //! (PixelConeDispatch::preparePixels with the G-buffer's GPU images; its output and
    //! representatives are read where they are), the G-buffer and the visibilities read from
    //! their images, the irradiance written to an RGBA32Float image of the G-buffer's size that
    //! this object owns (valid until the next call). Only the capsules go up. `cones`, when
    //! given, is read instead of the dispatch's output (its cones' sky, laid out the same way).
    const gpu::Image& combineResident(gpu::Context& context, const PixelConeDispatch& dispatch,
                                      int factor, const ResidentCombineInputs& in,
                                      const gpu::Buffer* cones = nullptr);
    //! Records a resident combine: combineResident without its submission. The checks, the
    //! output image and the capsules' upload happen here; the returned recorder adds the
    //! dispatches to a command list (gatherConesResident records the light's and the sky's in
    //! one submission), valid while this object and the bound resources are.
    using Recorder = std::function<void(gpu::CommandList&)>;
    Recorder prepareResident(gpu::Context& context, const PixelConeDispatch& dispatch, int factor,
                             const ResidentCombineInputs& in, const gpu::Buffer* cones = nullptr);
    //! Sets getLastGpuMs() for dispatches recorded with prepareResident.
    void setLastGpuMs(std::optional<double> ms) { mLastGpuMs = ms; }
    //! The image of the last combineResident on the CPU. Throws rtlab::Error before one.
    Image<glm::vec3> readBackResident() const;
    //! The image of the last combineResident, or null.
    const gpu::Image* getResidentOutput() const
    {
        return mOutputImage.isValid() ? &mOutputImage : nullptr;
    }
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
    // context); `resident` also the variant that reads and writes images.
    void prepare(gpu::Context& context, bool resident = false);
    // The capsules relative to `anchor` as the shader reads them, uploaded; returns their count.
    int uploadCapsules(const std::vector<scene::PosedCapsule>* capsules, const glm::dvec3& anchor);
    // The combine's dispatches with `pipeline` (either variant): with the capsules at the traced
    // pixels a first one over the reduced pixels, then the full-resolution one; recorded
    // (makeRecorder) or run in their own submission (runCombine).
    static Recorder makeRecorder(const gpu::ComputePipeline& pipeline, const std::vector<gpu::Binding>& bindings,
                                 const CombineConstants& constants, CapsuleResolution capsuleResolution);
    void runCombine(gpu::Context& context, const gpu::ComputePipeline& pipeline,
                    const std::vector<gpu::Binding>& bindings, const CombineConstants& constants,
                    CapsuleResolution capsuleResolution);
    // A buffer of at least `bytes`; every one here is written or read once per frame, so all are
    // gpu::BufferDesc::hostVisible.
    gpu::Buffer& reserve(gpu::Buffer& buffer, std::size_t bytes, const char* name);

    gpu::Context* mContext = nullptr;
    gpu::ComputePipeline mPipeline, mResidentPipeline;
    gpu::Image mOutputImage, mNoVisibility;
    gpu::Buffer mRepresentative, mPositions, mNormals, mDepths, mMaterials, mVisibility, mCapsules,
        mOutput, mUploadedCones;
    std::optional<double> mLastGpuMs;
    std::size_t mLastUploadBytes = 0;
};

//! A cone-traced gather resident on the device: `traceCones(source)` prepares the pixels of
//! `source` (the G-buffer's GPU images, reduced by `traceStep` on the device) in its
//! PixelConeDispatch, runs its cones without reading back and returns the dispatch; the combine
//! then reads them there and writes the irradiance into `combiner`'s image, which is returned.
//! The technique's dispatches are recorded (PixelSource::deferSubmission) and submitted with the
//! combine: the whole gather is one submission. `combineMs`, when given, receives its wall time
//! from the cones' recording on. With `skyCombiner` the dispatch's cones' sky
//! (PixelConeDispatch::getSkyOutput) is combined the same way into its image, in the same
//! submission (`combiner`'s getLastGpuMs then counts both).
const gpu::Image& gatherConesResident(
    gpu::Context& context, ConeCombineGpu& combiner, const plugin::VoxelGiGpuGBuffer& gbuffer,
    int traceStep, double coneHalfAngle, const std::array<const gpu::Image*, 4>& visibility,
    const std::vector<scene::PosedCapsule>* capsules,
    const std::function<const PixelConeDispatch&(const PixelSource&)>& traceCones,
    double* combineMs = nullptr, CapsuleResolution capsuleResolution = CapsuleResolution::Full,
    ConeCombineGpu* skyCombiner = nullptr);

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
