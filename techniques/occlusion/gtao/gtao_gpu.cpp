// The Vulkan path of GTAO (see gtao.cpp for the algorithm, shaders/gtao.comp for the kernel).

#include "gtao_gpu.h"

#include "gpu/shader_compiler.h"
#include "render/gbuffer_pass.h"

#include <string>

namespace rtlab::occlusion {

std::filesystem::path GtaoGpu::getShaderDir()
{
    return gpu::findShaderDir("techniques/occlusion/gtao/shaders",
                              std::filesystem::path(RTLAB_TECHNIQUE_DIR) / "shaders");
}

void GtaoGpu::prepare(gpu::Context& context, int width, int height)
{
    if (mContext != &context) {
        // A different device: nothing made on the old one can be used.
        *this = GtaoGpu();
        mContext = &context;
    }
    if (!mPipeline.isValid()) {
        gpu::ShaderCompilerOptions options;
        options.includeDirs.push_back(render::getRenderShaderDir()); // screen_space.glsl
        const gpu::ShaderCompiler compiler(options);
        gpu::ComputePipelineDesc desc;
        desc.name = kDispatchLabel;
        desc.spirv = compiler.compileFile(getShaderDir() / "gtao.comp").spirv;
        desc.bindings = {{0, gpu::BindingType::StorageImage},
                         {1, gpu::BindingType::StorageImage},
                         {2, gpu::BindingType::StorageImage},
                         {3, gpu::BindingType::StorageImage},
                         {4, gpu::BindingType::StorageImage}};
        desc.pushConstantSize = sizeof(GtaoFrameConstants);
        mPipeline = context.createPipeline(desc);
    }
    if (width != mWidth || height != mHeight || !mDepth.isValid()) {
        const auto makeImage = [&](gpu::Format format, const char* name) {
            return context.createImage({gpu::ImageDimension::Image2D, format, std::uint32_t(width),
                                        std::uint32_t(height), 1, gpu::ImageUsage::Storage, name});
        };
        mDepth = makeImage(gpu::Format::R32Float, "gtao.depth");
        mNormal = makeImage(gpu::Format::RGBA32Float, "gtao.normal");
        mAmbient = makeImage(gpu::Format::R32Float, "gtao.ambient");
        mBentNormal = makeImage(gpu::Format::RGBA32Float, "gtao.bent_normal");
        mAperture = makeImage(gpu::Format::R32Float, "gtao.aperture");
        mWidth = width;
        mHeight = height;
    }
}

void GtaoGpu::compute(gpu::Context& context, const GtaoFrameConstants& constants,
                      const Image<float>& depth, const Image<glm::vec3>& normal,
                      plugin::OcclusionOutput& out)
{
    const int width = depth.width;
    const int height = depth.height;
    prepare(context, width, height);
    const std::size_t count = std::size_t(width) * std::size_t(height);

    mDepth.upload(depth.pixels.data(), count * sizeof(float));
    mStaging.resize(count * 4);
    for (std::size_t i = 0; i < count; ++i) {
        mStaging[4 * i + 0] = normal.pixels[i].x;
        mStaging[4 * i + 1] = normal.pixels[i].y;
        mStaging[4 * i + 2] = normal.pixels[i].z;
        mStaging[4 * i + 3] = 0.0f;
    }
    mNormal.upload(mStaging.data(), count * 4 * sizeof(float));
    dispatch(context, constants, mDepth, mNormal, width, height, out);
}

void GtaoGpu::compute(gpu::Context& context, const GtaoFrameConstants& constants,
                      const gpu::Image& depth, const gpu::Image& normal,
                      plugin::OcclusionOutput& out)
{
    const int width = int(depth.getDesc().width);
    const int height = int(depth.getDesc().height);
    prepare(context, width, height);
    dispatch(context, constants, depth, normal, width, height, out);
}

void GtaoGpu::dispatch(gpu::Context& context, const GtaoFrameConstants& constants,
                       const gpu::Image& depth, const gpu::Image& normal, int width, int height,
                       plugin::OcclusionOutput& out)
{
    context.run([&](gpu::CommandList& cmd) {
        cmd.dispatch(mPipeline,
                     {gpu::Binding::storageImage(0, depth), gpu::Binding::storageImage(1, normal),
                      gpu::Binding::storageImage(2, mAmbient),
                      gpu::Binding::storageImage(3, mBentNormal),
                      gpu::Binding::storageImage(4, mAperture)},
                     gpu::PushConstants(constants),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(width), 8),
                                     gpu::computeGroupCount(std::uint64_t(height), 8), 1},
                     kDispatchLabel);
    });

    out = plugin::OcclusionOutput();
    out.gpu.ambient = &mAmbient;
    mComputed = true;
}

void GtaoGpu::readBack(plugin::OcclusionOutput& out)
{
    if (!mComputed)
        throw Error("gtao: nothing computed on the GPU to read back");
    const int width = mWidth, height = mHeight;
    const std::size_t count = std::size_t(width) * std::size_t(height);
    mStaging.resize(count * 4);
    out.ambient = Image<float>(width, height);
    mAmbient.download(out.ambient.pixels.data(), count * sizeof(float));
    out.coneAperture = Image<float>(width, height);
    mAperture.download(out.coneAperture.pixels.data(), count * sizeof(float));
    mBentNormal.download(mStaging.data(), count * 4 * sizeof(float));
    out.bentNormal = Image<glm::vec3>(width, height);
    for (std::size_t i = 0; i < count; ++i)
        out.bentNormal.pixels[i] = {mStaging[4 * i + 0], mStaging[4 * i + 1], mStaging[4 * i + 2]};
    out.coneVisibility.clear();
    out.gpu.ambient = &mAmbient;
}

} // namespace rtlab::occlusion
