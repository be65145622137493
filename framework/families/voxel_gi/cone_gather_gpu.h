#pragma once
// The pixel half of a Vulkan cone gather, shared by the structures that are cone traced from the
// G-buffer (cascades, svo): a compute pipeline whose bindings are 0 and 1 the structure's two
// buffers, 2 the pixels' positions (relative to an anchor, w = 1 for a surface), 3 their normals,
// 4 the output [pixel * 16 + cone], 5 the 16 cone directions, and from 6 on the structure's extra
// buffers, if any, then (for a gather that traces the cones' sky) the sky output; the per-pixel
// buffers, the dispatch, and the read-back of the cone radiances.
// The pixels come from the CPU G-buffer (uploaded), or from the G-buffer's GPU images reduced on
// the device in the same submission as the cones (shaders/gbuffer_reduce.comp): nothing crosses
// the bus then.
// The dispatch is 8 x 8 groups of pixels times 16 in z: one invocation per pixel and cone
// (gl_GlobalInvocationID.z the cone), so that a GPU has 16 times the invocations of a pixel per
// invocation to hide its memory latency with, and a warp marches one direction.

#include "families/voxel_gi/cone_tracing.h"
#include "gpu/context.h"
#include "scene/gbuffer.h"

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace rtlab::plugin {
struct VoxelGiGpuGBuffer;
}

namespace rtlab::voxelgi {

//! Where the pixels of a gather come from: a CPU G-buffer (as given: the caller reduced it), or
//! the G-buffer's GPU images, reduced on the device to one pixel per `factor` x `factor` block
//! (voxelgi::reduceGBuffer's choice).
struct PixelSource {
    const scene::GBuffer* gbuffer = nullptr;
    const plugin::VoxelGiGpuGBuffer* gpu = nullptr;
    int factor = 1;
    //! With `gpu`: the dispatch records the reduction and the cones (getRecorded) instead of
    //! submitting them, for a caller that submits them with what reads them (the resident
    //! gather's combine: one submission for the whole gather).
    bool deferSubmission = false;
    //! The traced pixels' grid: the G-buffer's size, or the reduced size for `gpu`.
    glm::ivec2 getSize() const;
};

class PixelConeDispatch {
public:
    //! True when the pipeline exists for `context` (else call create first).
    bool isReadyFor(const gpu::Context& context) const { return mContext == &context && mPipeline.isValid(); }
    //! Compiles `shader` into the pipeline `label` (with `extraBuffers` storage buffers at
    //! bindings 6, 7, ...) and uploads the cone directions. With `coneSky` the shader also writes
    //! the sky and emitters each cone sees past the voxels (cone_tracing.h
    //! computeConeSkyRadiance) at binding 6 + extraBuffers, [pixel * 16 + cone] (getSkyOutput),
    //! and reads the sky radiance of cone k at entry 16 + k of the cone buffer (setSkyPerCone).
    //! Shaders may #include <cone_march.glsl> (families/voxel_gi/shaders).
    void create(gpu::Context& context, const std::filesystem::path& shader, const std::string& label,
                std::size_t pushConstantSize, const ConeSet& cones, std::uint32_t extraBuffers = 0,
                bool coneSky = false);
    //! The mean sky radiance of each cone (computeSkyPerCone) where a `coneSky` shader reads it,
    //! uploaded when it changed; returns the bytes uploaded.
    std::size_t setSkyPerCone(const std::array<glm::vec3, kConeCount>& sky);
    //! The cones' sky of the last run over pixels of a `coneSky` pipeline whose shader traced it,
    //! [pixel * 16 + cone] as vec4.
    const gpu::Buffer& getSkyOutput() const { return (mOnDevice ? mDevicePixels : mPixels).skyOutput; }
    //! That buffer on the CPU (one row of 16 per pixel), or with `points` the sky of the last
    //! run over the uploaded points.
    void readBackSky(std::vector<glm::vec3>& out, bool points = false) const;
    //! Uploads the pixels' positions relative to `anchor` and their normals; returns the bytes.
    std::size_t uploadPixels(const scene::GBuffer& gbuffer, const glm::dvec3& anchor);
    //! uploadPixels for a CPU source; for a GPU one, the reduction is recorded before the next
    //! run()'s cones (device-local buffers, nothing uploaded) and getRepresentative() holds the
    //! reduced pixels' full-resolution indices after it. Returns the bytes uploaded.
    std::size_t preparePixels(const PixelSource& source, const glm::dvec3& anchor);
    //! After a run() over pixels reduced on the device: [reduced pixel] -> full pixel, -1 none.
    const gpu::Buffer& getRepresentative() const { return mDevicePixels.representative; }
    //! The grid of the pixels of the last uploadPixels or preparePixels.
    glm::ivec2 getPixelsSize() const
    {
        const Starts& s = mOnDevice ? mDevicePixels : mPixels;
        return {s.width, s.height};
    }
    //! Uploads points to trace cones from instead of pixels (a structure's own points, such as
    //! voxel centres; their own buffers, laid out as rows of 256 "pixels", w = 0 past the last):
    //! positions (w = 1) and a second vec4 per point whose meaning is the shader's; returns the
    //! bytes.
    std::size_t uploadPoints(const std::vector<glm::vec4>& positions, const std::vector<glm::vec4>& second);
    //! The layout of the uploaded points: "pixels" per row, rows.
    glm::ivec2 getPointsSize() const { return {mPoints.width, mPoints.height}; }
    //! Runs the pipeline over the uploaded pixels (or, with `points`, the uploaded points) with
    //! the structure's two buffers and reads the cone radiances back into `out` (one row of 16
    //! per pixel or point); returns the dispatch's GPU time when the device has one. With `out`
    //! null nothing is read back: the radiances stay in getOutput() (for cone_combine_gpu.h).
    std::optional<double> run(gpu::Buffer& first, gpu::Buffer& second,
                              const gpu::PushConstants& constants, std::vector<glm::vec3>* out,
                              const std::vector<gpu::Buffer*>& extra = {}, bool points = false);
    //! A dispatch of the pipeline before the pixels' cones (run with `before`): its push
    //! constants and group count (z included), or the group count the device wrote into
    //! `indirect` at `indirectOffset` (gpu::CommandList::dispatchIndirect).
    struct Step {
        std::vector<std::byte> constants;
        gpu::GroupCount groups;
        const gpu::Buffer* indirect = nullptr;
        std::size_t indirectOffset = 0;
    };
    //! Bytes [offset, offset + size) of extra buffer `extra`, to be zeroed.
    struct Clear {
        std::size_t extra = 0;
        std::size_t offset = 0;
        std::size_t size = 0;
    };
    //! run() over the prepared pixels with, in the same submission after the reduction, the
    //! ranges `clear` zeroed and the `before` dispatches of the same pipeline and bindings (a
    //! structure's work that depends on the pixels, such as marking and tracing what their cones
    //! will read), then the cones. Nothing is read back.
    std::optional<double> runWithSteps(gpu::Buffer& first, gpu::Buffer& second, const gpu::PushConstants& constants,
                                       const std::vector<gpu::Buffer*>& extra, const std::vector<Clear>& clear,
                                       const std::vector<Step>& before);
    //! For a structure with nothing to trace: the prepared pixels' reduction (if on the device)
    //! and zero radiances in getOutput().
    void runWithoutCones();
    //! What the last run recorded instead of submitting (PixelSource::deferSubmission), to be
    //! recorded into the caller's command list; empty when it submitted. Valid while the bound
    //! buffers are, until the next preparePixels.
    const std::function<void(gpu::CommandList&)>& getRecorded() const { return mRecorded; }
    //! The GPU time of the deferred dispatches, as the caller's submission measured it
    //! (setDeferredGpuMs); nullopt otherwise.
    std::optional<double> getDeferredGpuMs() const { return mDeferredGpuMs; }
    void setDeferredGpuMs(std::optional<double> ms) const { mDeferredGpuMs = ms; }
    const std::string& getLabel() const { return mLabel; }
    //! The cone radiances of the last run over pixels, [pixel * 16 + cone] as vec4.
    const gpu::Buffer& getOutput() const { return mOnDevice ? mDevicePixels.output : mPixels.output; }
    //! A storage buffer of at least `bytes` (16 at least) named `name`; `hostVisible` for data
    //! uploaded anew for each dispatch (gpu::BufferDesc::hostVisible).
    gpu::Buffer makeBuffer(std::size_t bytes, const char* name, bool hostVisible = false);

private:
    gpu::Context* mContext = nullptr;
    gpu::ComputePipeline mPipeline;
    std::string mLabel;
    gpu::Buffer mCones; //!< [k] directions, [16 + k] the sky per cone (coneSky)
    std::array<glm::vec3, kConeCount> mSkyPerCone{};
    std::uint32_t mSkyBinding = 0; //!< 0: the pipeline writes no cones' sky
    // What the cones start from: the pixels, or points.
    struct Starts {
        gpu::Buffer positions, normals, output;
        gpu::Buffer skyOutput; //!< with mSkyBinding
        gpu::Buffer representative; //!< mDevicePixels only
        int width = 0, height = 0;
        std::size_t count = 0;    //!< entries read back
        std::size_t capacity = 0; //!< entries the buffers hold
    };
    // Uploaded pixels, uploaded points, pixels reduced on the device (device-local buffers).
    Starts mPixels, mPoints, mDevicePixels;
    bool mOnDevice = false; //!< the last pixels prepared were reduced on the device
    bool mDefer = false;    //!< the next run records into mRecorded (PixelSource::deferSubmission)
    std::function<void(gpu::CommandList&)> mRecorded;
    mutable std::optional<double> mDeferredGpuMs;
    // The reduction recorded before the next run() (mOnDevice).
    gpu::ComputePipeline mReduce;
    std::vector<std::byte> mReduceConstants;
    const gpu::Image* mReducePositions = nullptr;
    const gpu::Image* mReduceNormals = nullptr;
    void reserve(Starts& starts, std::size_t entries, const char* what, bool hostVisible = true);
    void recordReduce(gpu::CommandList& cmd);
    // The pipeline's bindings over `starts`, and the cones' dispatch over them.
    std::vector<gpu::Binding> bindStarts(const Starts& starts, gpu::Buffer& first, gpu::Buffer& second,
                                         const std::vector<gpu::Buffer*>& extra) const;
    void recordCones(gpu::CommandList& cmd, const std::vector<gpu::Binding>& bindings,
                     const gpu::PushConstants& constants, const Starts& starts) const;
};

//! The push constant of a gather that traces the cones' sky (cone_march.glsl, the shader's `sky`):
//! x 1 when traced, y the distance from which the voxels hide the sky (world units), z 1 for the
//! sky's transmittance in optical depth, w 1 when an emission buffer is bound.
glm::vec4 makeConeSkyConstants(bool traced, double skyStartDistance, bool opticalDepth, bool emission);

//! Uploads a sparse structure's emission ([element * 6 + face], premultiplied; empty when nothing
//! emits) into `buffer` as vec4 (grown as needed; 16 bytes when empty), for a gather that
//! traces the cones' sky; returns the bytes uploaded.
std::size_t uploadFaceEmission(PixelConeDispatch& dispatch, gpu::Buffer& buffer,
                               const std::vector<glm::vec3>& emission, const char* name);

} // namespace rtlab::voxelgi
