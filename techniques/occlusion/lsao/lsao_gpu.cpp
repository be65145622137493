#include "lsao_gpu.h"

#include "gpu/shader_compiler.h"

#include <stdexcept>
#include <string>
#include "render/gbuffer_pass.h"

#include <string>

namespace rtlab::occlusion::lsao {

std::filesystem::path getShaderDir()
{
    return gpu::findShaderDir("techniques/occlusion/lsao/shaders",
                              std::filesystem::path(RTLAB_TECHNIQUE_DIR) / "shaders");
}

namespace {

constexpr std::uint32_t kSweepGroupSize = 64;
constexpr std::uint32_t kGatherGroupSize = 8;

gpu::ComputePipeline createPipeline(gpu::Context& context, const gpu::ShaderCompiler& compiler,
                                    const char* file, const char* name,
                                    std::vector<gpu::BindingSlot> bindings, const Params& params)
{
    const std::vector<gpu::ShaderDefine> defines = {
        {"LSAO_HULL_CAPACITY", std::to_string(kHullCapacity)},
        {"LSAO_WALLS", params.walls ? "1" : "0"},
        {"LSAO_SMOOTHSTEP", params.falloff == Falloff::Smoothstep ? "1" : "0"},
        {"LSAO_GATHER_NEAREST", params.gather == Gather::Nearest ? "1" : "0"},
        {"LSAO_INTERLEAVE",
         std::to_string(computeEffectiveInterleave(params.interleave, params.directions))}};
    gpu::ComputePipelineDesc desc;
    desc.name = name;
    desc.spirv = compiler.compileFile(getShaderDir() / file, defines).spirv;
    desc.bindings = std::move(bindings);
    desc.pushConstantSize = sizeof(Constants);
    return context.createPipeline(desc);
}

} // namespace

GpuRunner::GpuRunner(gpu::Context& context, const Params& params)
    : mContext(&context), mWalls(params.walls), mFalloff(params.falloff),
      mGatherMode(params.gather),
      mInterleave(computeEffectiveInterleave(params.interleave, params.directions))
{
    gpu::ShaderCompilerOptions options;
    options.includeDirs = {getShaderDir(), render::getRenderShaderDir()};
    const gpu::ShaderCompiler compiler(options);
    using gpu::BindingType;
    mSweep = createPipeline(context, compiler, "lsao_sweep.comp", "lsao.sweep",
                            {{0, BindingType::StorageImage},
                             {1, BindingType::StorageBuffer},
                             {2, BindingType::StorageBuffer},
                             {3, BindingType::StorageImage}},
                            params);
    mGather = createPipeline(context, compiler, "lsao_gather.comp", "lsao.gather",
                             {{0, BindingType::StorageImage},
                              {1, BindingType::StorageBuffer},
                              {2, BindingType::StorageBuffer},
                              {3, BindingType::StorageImage},
                              {4, BindingType::StorageImage},
                              {5, BindingType::StorageImage}},
                             params);
    mResolve = createPipeline(context, compiler, "lsao_resolve.comp", "lsao.resolve",
                              {{0, BindingType::StorageImage},
                               {3, BindingType::StorageImage},
                               {4, BindingType::StorageImage},
                               {5, BindingType::StorageImage},
                               {6, BindingType::StorageImage},
                               {7, BindingType::StorageImage}},
                              params);
}

void GpuRunner::checkCompiledFor(const Params& params, const Layout& layout) const
{
    if (params.walls != mWalls || params.falloff != mFalloff || params.gather != mGatherMode ||
        layout.interleave != mInterleave)
        throw std::invalid_argument(
            "lsao: the shaders were compiled for other walls, falloff, gather or interleave");
}

void GpuRunner::prepare(const Layout& layout)
{
    if (layout.width != mWidth || layout.height != mHeight) {
        const auto w = std::uint32_t(layout.width), h = std::uint32_t(layout.height);
        using gpu::Format;
        using gpu::ImageDimension;
        using gpu::ImageUsage;
        mDepth = mContext->createImage({ImageDimension::Image2D, Format::R32Float, w, h, 1,
                                        ImageUsage::Storage, "lsao.depth"});
        mNormal = mContext->createImage({ImageDimension::Image2D, Format::RGBA32Float, w, h, 1,
                                         ImageUsage::Storage, "lsao.normal"});
        mAccumA = mContext->createImage({ImageDimension::Image2D, Format::RGBA32Float, w, h, 1,
                                         ImageUsage::Storage, "lsao.accum_a"});
        mAccumB = mContext->createImage({ImageDimension::Image2D, Format::R32Float, w, h, 1,
                                         ImageUsage::Storage, "lsao.accum_b"});
        mOutA = mContext->createImage({ImageDimension::Image2D, Format::RGBA32Float, w, h, 1,
                                       ImageUsage::Storage, "lsao.bent_aperture"});
        mOutB = mContext->createImage({ImageDimension::Image2D, Format::R32Float, w, h, 1,
                                       ImageUsage::Storage, "lsao.ambient"});
        mWidth = layout.width;
        mHeight = layout.height;
    }
    if (layout.directions.size() > mDirectionCapacity) {
        mDirectionCapacity = layout.directions.size();
        mDirections =
            mContext->createBuffer({mDirectionCapacity * sizeof(Direction), "lsao.directions"});
    }
    const std::size_t sweepEntries = std::max<std::size_t>(layout.maxBatchEntries, 1);
    if (sweepEntries > mSweepCapacity) {
        mSweepCapacity = sweepEntries;
        mSweepBuffer =
            mContext->createBuffer({mSweepCapacity * sizeof(std::uint32_t), "lsao.sweep"});
    }
}

void GpuRunner::run(const Layout& layout, const plugin::ScreenProjection& projection,
                    const Params& params, const Image<float>& depth, const Image<glm::vec3>& normal,
                    plugin::OcclusionOutput& out, bool readBack)
{
    checkCompiledFor(params, layout);
    prepare(layout);
    const int w = layout.width, h = layout.height;
    const std::size_t count = std::size_t(w) * std::size_t(h);
    mDepth.upload(depth.pixels.data(), count * sizeof(float));
    mStaging.resize(count * 4);
    for (std::size_t i = 0; i < count; ++i) {
        mStaging[4 * i + 0] = normal.pixels[i].x;
        mStaging[4 * i + 1] = normal.pixels[i].y;
        mStaging[4 * i + 2] = normal.pixels[i].z;
        mStaging[4 * i + 3] = 0.0f;
    }
    mNormal.upload(mStaging.data(), count * 4 * sizeof(float));
    run(layout, projection, params, mDepth, mNormal, out, readBack);
}

void GpuRunner::run(const Layout& layout, const plugin::ScreenProjection& projection,
                    const Params& params, const gpu::Image& depth, const gpu::Image& normal,
                    plugin::OcclusionOutput& out, bool readBack)
{
    checkCompiledFor(params, layout);
    prepare(layout);
    const int w = layout.width, h = layout.height;
    mDirections.upload(layout.directions.data(), layout.directions.size() * sizeof(Direction));

    std::vector<Constants> constants;
    for (std::size_t b = 0; b < layout.batches.size(); ++b)
        constants.push_back(makeConstants(layout, projection, params, b));
    mContext->run([&](gpu::CommandList& cmd) {
        for (std::size_t b = 0; b < layout.batches.size(); ++b) {
            const Batch& batch = layout.batches[b];
            cmd.dispatch(
                mSweep,
                {gpu::Binding::storageImage(0, depth), gpu::Binding::storageBuffer(1, mDirections),
                 gpu::Binding::storageBuffer(2, mSweepBuffer),
                 gpu::Binding::storageImage(3, normal)},
                gpu::PushConstants(constants[b]),
                gpu::GroupCount{gpu::computeGroupCount(layout.maxLineCount, kSweepGroupSize),
                                batch.end - batch.begin, 1},
                "lsao.sweep");
            cmd.dispatch(
                mGather,
                {gpu::Binding::storageImage(0, depth), gpu::Binding::storageBuffer(1, mDirections),
                 gpu::Binding::storageBuffer(2, mSweepBuffer),
                 gpu::Binding::storageImage(3, normal), gpu::Binding::storageImage(4, mAccumA),
                 gpu::Binding::storageImage(5, mAccumB)},
                gpu::PushConstants(constants[b]),
                gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(w), kGatherGroupSize),
                                gpu::computeGroupCount(std::uint64_t(h), kGatherGroupSize), 1},
                "lsao.gather");
        }
        cmd.dispatch(mResolve,
                     {gpu::Binding::storageImage(0, depth), gpu::Binding::storageImage(3, normal),
                      gpu::Binding::storageImage(4, mAccumA),
                      gpu::Binding::storageImage(5, mAccumB), gpu::Binding::storageImage(6, mOutA),
                      gpu::Binding::storageImage(7, mOutB)},
                     gpu::PushConstants(constants.back()),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(w), kGatherGroupSize),
                                     gpu::computeGroupCount(std::uint64_t(h), kGatherGroupSize), 1},
                     "lsao.resolve");
    });

    out = plugin::OcclusionOutput();
    out.gpu.ambient = &mOutB;
    mRunWidth = w;
    mRunHeight = h;
    if (readBack)
        this->readBack(out);
}

void GpuRunner::readBack(plugin::OcclusionOutput& out)
{
    if (mRunWidth == 0)
        throw Error("lsao: nothing computed on the GPU to read back");
    const int w = mRunWidth, h = mRunHeight;
    const std::size_t count = std::size_t(w) * std::size_t(h);
    const std::vector<float> a = mOutA.downloadVector<float>();
    const std::vector<float> b = mOutB.downloadVector<float>();
    out.ambient = Image<float>(w, h, 1.0f);
    out.bentNormal = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    out.coneAperture = Image<float>(w, h, 0.0f);
    out.coneVisibility.clear();
    for (std::size_t i = 0; i < count; ++i) {
        out.ambient.pixels[i] = b[i];
        out.bentNormal.pixels[i] = glm::vec3(a[4 * i + 0], a[4 * i + 1], a[4 * i + 2]);
        out.coneAperture.pixels[i] = a[4 * i + 3];
    }
    out.gpu.ambient = &mOutB;
}

std::vector<std::uint32_t> GpuRunner::downloadSweep(std::size_t entryCount) const
{
    return mSweepBuffer.downloadVector<std::uint32_t>(entryCount);
}

} // namespace rtlab::occlusion::lsao
