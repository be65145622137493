#pragma once
// The Vulkan version: shaders/lsao_sweep.comp ("lsao.sweep") and shaders/lsao_gather.comp
// ("lsao.gather"), one pair of dispatches per batch of directions (one batch at the default
// settings), then shaders/lsao_resolve.comp ("lsao.resolve"). Pipelines are built on first use;
// images and buffers are kept across frames and rebuilt when the image size or the layout grows.

#include "lsao_core.h"

#include "core/image.h"
#include "gpu/context.h"
#include "families/occlusion/occlusion.h"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace rtlab::occlusion::lsao {

//! Where the shaders are: $RTLAB_SOURCE_DIR/techniques/occlusion/lsao/shaders when set, else the
//! source folder the technique was built from.
std::filesystem::path getShaderDir();

class GpuRunner {
public:
    //! Compiles the shaders and creates the pipelines on `context`, which must outlive this,
    //! for the walls, falloff, gather and interleave of `params` (every run must have the same: the
    //! shaders are compiled with or without their code).
    explicit GpuRunner(gpu::Context& context, const Params& params = Params{});

    gpu::Context& getContext() const { return *mContext; }

    //! Both passes of every batch of `layout` in one submission, then (with `readBack`) reads
    //! back the outputs. out.gpu.ambient is the ambient image on the GPU either way.
    void run(const Layout& layout, const plugin::ScreenProjection& projection, const Params& params,
             const Image<float>& depth, const Image<glm::vec3>& normal,
             plugin::OcclusionOutput& out, bool readBack = true);
    //! The same from depth (R32Float) and normals (RGBA32Float) already on the GPU: nothing is
    //! uploaded but the direction table.
    void run(const Layout& layout, const plugin::ScreenProjection& projection, const Params& params,
             const gpu::Image& depth, const gpu::Image& normal, plugin::OcclusionOutput& out,
             bool readBack = true);
    //! The outputs of the last run() to the CPU (out.gpu kept). Throws rtlab::Error before it.
    void readBack(plugin::OcclusionOutput& out);

    //! The sweep buffer of the last batch of the last run (for tests).
    std::vector<std::uint32_t> downloadSweep(std::size_t entryCount) const;

private:
    //! Throws std::invalid_argument unless the shaders were compiled for these options.
    void checkCompiledFor(const Params& params, const Layout& layout) const;
    void prepare(const Layout& layout);

    gpu::Context* mContext = nullptr;
    bool mWalls = true;
    Falloff mFalloff = Falloff::Linear;
    Gather mGatherMode = Gather::Nearest;
    int mInterleave = 1; //!< Layout::interleave the resolve was compiled for
    gpu::ComputePipeline mSweep;
    gpu::ComputePipeline mGather;
    gpu::ComputePipeline mResolve;
    gpu::Image mDepth;
    gpu::Image mNormal;
    gpu::Image mAccumA;
    gpu::Image mAccumB;
    gpu::Image mOutA; //!< bent normal, aperture
    gpu::Image mOutB; //!< ambient
    gpu::Buffer mDirections;
    gpu::Buffer mSweepBuffer;
    int mWidth = 0;
    int mHeight = 0;
    std::size_t mDirectionCapacity = 0;
    std::size_t mSweepCapacity = 0;
    int mRunWidth = 0; //!< size of the last run(), 0 before the first
    int mRunHeight = 0;
    std::vector<float> mStaging;
};

} // namespace rtlab::occlusion::lsao
