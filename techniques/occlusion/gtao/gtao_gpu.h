#pragma once
// The Vulkan path of GTAO: one compute dispatch "gtao.main" (shaders/gtao.comp, 8x8 groups).

#include "gtao_kernel.h"

#include "gpu/context.h"

#include <filesystem>
#include <vector>

namespace rtlab::occlusion {

//! Pipeline and images of the GPU path. The pipeline is compiled on the first frame and kept;
//! the images are kept across frames and recreated when the size or the Context changes. A
//! Context is recognised by its address: a new Context created where a destroyed one lived is
//! taken for the old one, so a technique instance should not outlive the Context it ran on.
class GtaoGpu {
public:
    //! Uploads depth and normals and dispatches "gtao.main"; the results stay on the GPU
    //! (out.gpu.ambient; out's CPU images are cleared) until readBack().
    void compute(gpu::Context& context, const GtaoFrameConstants& constants,
                 const Image<float>& depth, const Image<glm::vec3>& normal,
                 plugin::OcclusionOutput& out);

    //! The same from depth and normals already on the GPU (R32Float and RGBA32Float storage
    //! images of one size): nothing is uploaded.
    void compute(gpu::Context& context, const GtaoFrameConstants& constants,
                 const gpu::Image& depth, const gpu::Image& normal, plugin::OcclusionOutput& out);

    //! The three outputs of the last compute() to the CPU (out.gpu kept). Throws rtlab::Error
    //! before the first compute().
    void readBack(plugin::OcclusionOutput& out);

    //! Label of the dispatch in the Context's run log.
    static constexpr const char* kDispatchLabel = "gtao.main";

    //! $RTLAB_SOURCE_DIR/techniques/occlusion/gtao/shaders when set, else the source folder.
    static std::filesystem::path getShaderDir();

private:
    void prepare(gpu::Context& context, int width, int height);
    void dispatch(gpu::Context& context, const GtaoFrameConstants& constants,
                  const gpu::Image& depth, const gpu::Image& normal, int width, int height,
                  plugin::OcclusionOutput& out);

    gpu::Context* mContext = nullptr;
    gpu::ComputePipeline mPipeline;
    int mWidth = 0;
    int mHeight = 0;
    gpu::Image mDepth;
    gpu::Image mNormal;
    gpu::Image mAmbient;
    gpu::Image mBentNormal;
    gpu::Image mAperture;
    bool mComputed = false;
    std::vector<float> mStaging; //!< RGBA texels for normal upload and bent normal download
};

} // namespace rtlab::occlusion
