#pragma once
// The pixel half of a Vulkan cone gather, shared by the structures that are cone traced from the
// G-buffer (cascades, svo): a compute pipeline whose bindings are 0 and 1 the structure's two
// buffers, 2 the pixels' positions (relative to an anchor, w = 1 for a surface), 3 their normals,
// 4 the output [pixel * 16 + cone], 5 the 16 cone directions, and from 6 on the structure's extra
// buffers, if any; the per-pixel buffers, the dispatch over 8 x 8 groups, and the read-back of the
// cone radiances.

#include "families/voxel_gi/cone_tracing.h"
#include "gpu/context.h"
#include "scene/gbuffer.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace rtlab::voxelgi {

class PixelConeDispatch {
public:
    //! True when the pipeline exists for `context` (else call create first).
    bool isReadyFor(const gpu::Context& context) const { return mContext == &context && mPipeline.isValid(); }
    //! Compiles `shader` into the pipeline `label` (with `extraBuffers` storage buffers at
    //! bindings 6, 7, ...) and uploads the cone directions.
    void create(gpu::Context& context, const std::filesystem::path& shader, const std::string& label,
                std::size_t pushConstantSize, const ConeSet& cones, std::uint32_t extraBuffers = 0);
    //! Uploads the pixels' positions relative to `anchor` and their normals; returns the bytes.
    std::size_t uploadPixels(const scene::GBuffer& gbuffer, const glm::dvec3& anchor);
    //! Runs the pipeline over the uploaded pixels with the structure's two buffers and reads the
    //! cone radiances back into `out`; returns the dispatch's GPU time when the device has one.
    std::optional<double> run(gpu::Buffer& first, gpu::Buffer& second, const gpu::PushConstants& constants,
                              std::vector<glm::vec3>& out, const std::vector<gpu::Buffer*>& extra = {});
    //! A storage buffer of at least `bytes` (16 at least) named `name`.
    gpu::Buffer makeBuffer(std::size_t bytes, const char* name);

private:
    gpu::Context* mContext = nullptr;
    gpu::ComputePipeline mPipeline;
    std::string mLabel;
    gpu::Buffer mPositions, mNormals, mOutput, mCones;
    int mWidth = 0, mHeight = 0;
    std::size_t mPixels = 0;
};

} // namespace rtlab::voxelgi
