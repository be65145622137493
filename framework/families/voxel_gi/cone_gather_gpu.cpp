#include "families/voxel_gi/cone_gather_gpu.h"

#include "core/error.h"
#include "families/voxel_gi/cone_combine_gpu.h"
#include "families/voxel_gi/voxel_gi.h"
#include "gpu/format.h"
#include "gpu/shader_compiler.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <cstring>
#include <cmath>

namespace rtlab::voxelgi {

namespace {

struct ReduceConstants {
    glm::ivec4 size{0}; // full width, height; reduced width, height
    glm::ivec4 factor{0};
    glm::vec4 anchorHigh{0.0f};
    glm::vec4 anchorLow{0.0f};
};
static_assert(sizeof(ReduceConstants) == 64, "must match gbuffer_reduce.comp");

} // namespace

glm::ivec2 PixelSource::getSize() const
{
    if (gpu != nullptr)
        return {(gpu->width + factor - 1) / factor, (gpu->height + factor - 1) / factor};
    return gbuffer != nullptr ? glm::ivec2(gbuffer->width, gbuffer->height) : glm::ivec2(0);
}

void PixelConeDispatch::create(gpu::Context& context, const std::filesystem::path& shader,
                               const std::string& label, std::size_t pushConstantSize, const ConeSet& cones,
                               std::uint32_t extraBuffers, bool coneSky)
{
    *this = PixelConeDispatch();
    mContext = &context;
    mLabel = label;
    const gpu::ShaderCompiler compiler({.includeDirs = {ConeCombineGpu::getShaderDir()}});
    gpu::ComputePipelineDesc desc;
    desc.name = label;
    desc.spirv = compiler.compileFile(shader).spirv;
    mSkyBinding = coneSky ? 6 + extraBuffers : 0;
    for (std::uint32_t b = 0; b < 6 + extraBuffers + (coneSky ? 1 : 0); ++b)
        desc.bindings.push_back({b, gpu::BindingType::StorageBuffer});
    desc.pushConstantSize = std::uint32_t(pushConstantSize);
    mPipeline = context.createPipeline(desc);
    // The directions, then the sky per cone (none until setSkyPerCone).
    std::vector<glm::vec4> entries(2 * kConeCount, glm::vec4(0.0f));
    for (int k = 0; k < kConeCount; ++k)
        entries[std::size_t(k)] = glm::vec4(glm::vec3(cones.directions[std::size_t(k)]), 0.0f);
    mCones = makeBuffer(entries.size() * sizeof(glm::vec4), "cone_gather.cones");
    mCones.uploadSpan<glm::vec4>(entries);
}

std::size_t PixelConeDispatch::setSkyPerCone(const std::array<glm::vec3, kConeCount>& sky)
{
    if (mSkyBinding == 0)
        throw Error("cone gather: the pipeline '" + mLabel + "' traces no cones' sky");
    if (sky == mSkyPerCone)
        return 0;
    std::vector<glm::vec4> entries(kConeCount);
    for (int k = 0; k < kConeCount; ++k)
        entries[std::size_t(k)] = glm::vec4(sky[std::size_t(k)], 0.0f);
    mCones.uploadSpan<glm::vec4>(entries, kConeCount * sizeof(glm::vec4));
    mSkyPerCone = sky;
    return entries.size() * sizeof(glm::vec4);
}

void PixelConeDispatch::readBackSky(std::vector<glm::vec3>& out, bool points) const
{
    const Starts& starts = points ? mPoints : mOnDevice ? mDevicePixels : mPixels;
    if (mSkyBinding == 0 || !starts.skyOutput.isValid())
        throw Error("cone gather: the pipeline '" + mLabel + "' traced no cones' sky to read back");
    const std::vector<glm::vec4> e = starts.skyOutput.downloadVector<glm::vec4>(starts.count * kConeCount);
    out.resize(e.size());
    for (std::size_t i = 0; i < e.size(); ++i)
        out[i] = glm::vec3(e[i]);
}

gpu::Buffer PixelConeDispatch::makeBuffer(std::size_t bytes, const char* name, bool hostVisible)
{
    return mContext->createBuffer(
        {.size = std::max<std::size_t>(bytes, 16), .name = name, .hostVisible = hostVisible});
}

void PixelConeDispatch::reserve(Starts& starts, std::size_t entries, const char* what, bool hostVisible)
{
    if (starts.capacity != entries) {
        const std::string name = std::string("cone_gather.") + what;
        // Uploaded for every dispatch: read by the shader where the host wrote them (unless the
        // device writes them: hostVisible false).
        starts.positions =
            makeBuffer(entries * sizeof(glm::vec4), (name + ".positions").c_str(), hostVisible);
        starts.normals = makeBuffer(entries * sizeof(glm::vec4), (name + ".normals").c_str(), hostVisible);
        starts.output = makeBuffer(entries * kConeCount * sizeof(glm::vec4), (name + ".cone_radiance").c_str());
        if (mSkyBinding != 0)
            starts.skyOutput = makeBuffer(entries * kConeCount * sizeof(glm::vec4), (name + ".cone_sky").c_str());
        if (!hostVisible)
            starts.representative = makeBuffer(entries * sizeof(int), (name + ".representative").c_str());
        starts.capacity = entries;
    }
}

std::size_t PixelConeDispatch::preparePixels(const PixelSource& source, const glm::dvec3& anchor)
{
    mRecorded = {};
    mDeferredGpuMs.reset();
    mDefer = source.gpu != nullptr && source.deferSubmission;
    if (source.gpu == nullptr) {
        if (source.gbuffer == nullptr)
            throw Error("cone gather: no pixels given (neither a G-buffer nor its GPU images)");
        return uploadPixels(*source.gbuffer, anchor);
    }
    const plugin::VoxelGiGpuGBuffer& g = *source.gpu;
    if (g.positionDepth == nullptr || g.normal == nullptr)
        throw Error("cone gather: the G-buffer's GPU images are missing");
    for (const gpu::Image* image : {g.positionDepth, g.normal}) {
        const gpu::ImageDesc& d = image->getDesc();
        if (int(d.width) != g.width || int(d.height) != g.height || d.format != gpu::Format::RGBA32Float)
            throw Error("cone gather: the G-buffer image '" + d.name + "' is " + std::to_string(d.width) + "x" +
                        std::to_string(d.height) + " " + std::string(gpu::getFormatName(d.format)) +
                        ", expected RGBA32Float " + std::to_string(g.width) + "x" + std::to_string(g.height));
    }
    if (source.factor < 1 || source.factor > 16)
        throw Error("cone gather: the reduction factor must be in [1, 16], found " + std::to_string(source.factor));
    if (!mReduce.isValid()) {
        gpu::ComputePipelineDesc desc;
        desc.name = "voxel_gi.reduce";
        desc.spirv = gpu::ShaderCompiler().compileFile(ConeCombineGpu::getShaderDir() / "gbuffer_reduce.comp").spirv;
        desc.bindings = {{0, gpu::BindingType::StorageImage},
                         {1, gpu::BindingType::StorageImage},
                         {2, gpu::BindingType::StorageBuffer},
                         {3, gpu::BindingType::StorageBuffer},
                         {4, gpu::BindingType::StorageBuffer}};
        desc.pushConstantSize = sizeof(ReduceConstants);
        mReduce = mContext->createPipeline(desc);
    }
    const glm::ivec2 low = source.getSize();
    const std::size_t pixels = std::size_t(low.x) * std::size_t(low.y);
    reserve(mDevicePixels, pixels, "device_pixels", false);
    mDevicePixels.width = low.x;
    mDevicePixels.height = low.y;
    mDevicePixels.count = pixels;
    ReduceConstants c;
    c.size = {g.width, g.height, low.x, low.y};
    c.factor = {source.factor, 0, 0, 0};
    // The anchor as float plus what that left. Through volatile: GCC 12 at -O3 vectorizes
    // anchor - double(float(anchor)) for x and y into anchor - anchor (0), dropping the rounding.
    volatile float rounded[3] = {float(anchor.x), float(anchor.y), float(anchor.z)};
    const glm::vec3 high(rounded[0], rounded[1], rounded[2]);
    const glm::dvec3 rest = anchor - glm::dvec3(high);
    c.anchorHigh = glm::vec4(high, 0.0f);
    c.anchorLow = glm::vec4(glm::vec3(rest), 0.0f);
    mReduceConstants.resize(sizeof(c));
    std::memcpy(mReduceConstants.data(), &c, sizeof(c));
    mReducePositions = g.positionDepth;
    mReduceNormals = g.normal;
    mOnDevice = true;
    return 0;
}

std::size_t PixelConeDispatch::uploadPoints(const std::vector<glm::vec4>& positions,
                                            const std::vector<glm::vec4>& second)
{
    constexpr int kRow = 256;
    const std::size_t count = positions.size();
    mPoints.width = int(std::min<std::size_t>(std::max<std::size_t>(count, 1), kRow));
    mPoints.height = int((std::max<std::size_t>(count, 1) + kRow - 1) / kRow);
    const std::size_t entries = std::size_t(mPoints.width) * std::size_t(mPoints.height);
    // Grown in whole rows of 64 so that a few more points do not reallocate.
    reserve(mPoints, std::max(mPoints.capacity, (entries + 64 * kRow - 1) / (64 * kRow) * (64 * kRow)), "points");
    std::vector<glm::vec4> p(entries, glm::vec4(0.0f)), q(entries, glm::vec4(0.0f));
    std::copy(positions.begin(), positions.end(), p.begin());
    std::copy(second.begin(), second.begin() + std::ptrdiff_t(std::min(second.size(), count)), q.begin());
    mPoints.positions.uploadSpan<glm::vec4>(p);
    mPoints.normals.uploadSpan<glm::vec4>(q);
    mPoints.count = count;
    return 2 * entries * sizeof(glm::vec4);
}

std::size_t PixelConeDispatch::uploadPixels(const scene::GBuffer& gbuffer, const glm::dvec3& anchor)
{
    const int w = gbuffer.width, h = gbuffer.height;
    const std::size_t pixels = std::size_t(w) * std::size_t(h);
    mOnDevice = false;
    reserve(mPixels, pixels, "pixels");
    mPixels.width = w;
    mPixels.height = h;
    mPixels.count = pixels;
    std::vector<glm::vec4> positions(pixels), normals(pixels);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const glm::dvec3 p(gbuffer.position.at(x, y));
            const bool surface = gbuffer.hasSurface(x, y) && std::isfinite(p.x + p.y + p.z);
            positions[i] = glm::vec4(glm::vec3(surface ? p - anchor : glm::dvec3(0.0)), surface ? 1.0f : 0.0f);
            normals[i] = glm::vec4(gbuffer.normal.at(x, y), 0.0f);
        }
    mPixels.positions.uploadSpan<glm::vec4>(positions);
    mPixels.normals.uploadSpan<glm::vec4>(normals);
    return 2 * pixels * sizeof(glm::vec4);
}

std::vector<gpu::Binding> PixelConeDispatch::bindStarts(const Starts& starts, gpu::Buffer& first, gpu::Buffer& second,
                                                        const std::vector<gpu::Buffer*>& extra) const
{
    std::vector<gpu::Binding> bindings = {
        gpu::Binding::storageBuffer(0, first),            gpu::Binding::storageBuffer(1, second),
        gpu::Binding::storageBuffer(2, starts.positions), gpu::Binding::storageBuffer(3, starts.normals),
        gpu::Binding::storageBuffer(4, starts.output),    gpu::Binding::storageBuffer(5, mCones)};
    for (std::size_t i = 0; i < extra.size(); ++i)
        bindings.push_back(gpu::Binding::storageBuffer(std::uint32_t(6 + i), *extra[i]));
    if (mSkyBinding != 0) {
        if (extra.size() + 6 != mSkyBinding)
            throw Error("cone gather: the pipeline '" + mLabel + "' was created with " +
                        std::to_string(mSkyBinding - 6) + " extra buffers, given " + std::to_string(extra.size()));
        bindings.push_back(gpu::Binding::storageBuffer(mSkyBinding, starts.skyOutput));
    }
    return bindings;
}

void PixelConeDispatch::recordCones(gpu::CommandList& cmd, const std::vector<gpu::Binding>& bindings,
                                    const gpu::PushConstants& constants, const Starts& starts) const
{
    cmd.dispatch(mPipeline, bindings, constants,
                 gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(starts.width), 8),
                                 gpu::computeGroupCount(std::uint64_t(starts.height), 8),
                                 std::uint32_t(kConeCount)},
                 mLabel.c_str());
}

std::optional<double> PixelConeDispatch::runWithSteps(gpu::Buffer& first, gpu::Buffer& second,
                                                      const gpu::PushConstants& constants,
                                                      const std::vector<gpu::Buffer*>& extra,
                                                      const std::vector<Clear>& clear,
                                                      const std::vector<Step>& before)
{
    const Starts& starts = mOnDevice ? mDevicePixels : mPixels;
    // Everything the recording reads, held by value (it may run after this call returns).
    const std::vector<gpu::Binding> bindings = bindStarts(starts, first, second, extra);
    const std::vector<std::byte> bytes(constants.getData(), constants.getData() + constants.getSize());
    std::vector<std::pair<gpu::Buffer*, Clear>> clears;
    for (const Clear& c : clear)
        clears.emplace_back(extra.at(c.extra), c);
    const bool reduce = mOnDevice;
    const auto record = [this, &starts, bindings, bytes, clears, before, reduce](gpu::CommandList& cmd) {
        if (reduce)
            recordReduce(cmd);
        for (const auto& [buffer, c] : clears)
            cmd.fillBuffer(*buffer, 0u, c.offset, c.size);
        for (const Step& step : before) {
            const gpu::PushConstants stepConstants(step.constants.data(), step.constants.size());
            if (step.indirect != nullptr)
                cmd.dispatchIndirect(mPipeline, bindings, stepConstants, *step.indirect, step.indirectOffset,
                                     mLabel.c_str());
            else
                cmd.dispatch(mPipeline, bindings, stepConstants, step.groups, mLabel.c_str());
        }
        recordCones(cmd, bindings, gpu::PushConstants(bytes.data(), bytes.size()), starts);
    };
    if (mDefer) {
        mRecorded = record;
        return std::nullopt;
    }
    return mContext->run(record).sumGpuMs(mLabel);
}

void PixelConeDispatch::runWithoutCones()
{
    Starts& starts = mOnDevice ? mDevicePixels : mPixels;
    const bool reduce = mOnDevice;
    const auto record = [this, &starts, reduce](gpu::CommandList& cmd) {
        if (reduce)
            recordReduce(cmd);
        cmd.fillBuffer(starts.output, 0u);
        if (starts.skyOutput.isValid())
            cmd.fillBuffer(starts.skyOutput, 0u);
    };
    if (mDefer)
        mRecorded = record;
    else
        mContext->run(record);
}

void PixelConeDispatch::recordReduce(gpu::CommandList& cmd)
{
    cmd.dispatch(mReduce,
                 {gpu::Binding::storageImage(0, *mReducePositions),
                  gpu::Binding::storageImage(1, *mReduceNormals),
                  gpu::Binding::storageBuffer(2, mDevicePixels.positions),
                  gpu::Binding::storageBuffer(3, mDevicePixels.normals),
                  gpu::Binding::storageBuffer(4, mDevicePixels.representative)},
                 gpu::PushConstants(mReduceConstants.data(), mReduceConstants.size()),
                 gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(mDevicePixels.width), 8),
                                 gpu::computeGroupCount(std::uint64_t(mDevicePixels.height), 8), 1},
                 "voxel_gi.reduce");
}

std::optional<double> PixelConeDispatch::run(gpu::Buffer& first, gpu::Buffer& second,
                                             const gpu::PushConstants& constants,
                                             std::vector<glm::vec3>* out,
                                             const std::vector<gpu::Buffer*>& extra, bool points)
{
    Starts& starts = points ? mPoints : mOnDevice ? mDevicePixels : mPixels;
    const bool reduce = !points && mOnDevice;
    const std::vector<gpu::Binding> bindings = bindStarts(starts, first, second, extra);
    if (mDefer && !points && out == nullptr) {
        const std::vector<std::byte> bytes(constants.getData(), constants.getData() + constants.getSize());
        mRecorded = [this, &starts, bindings, bytes, reduce](gpu::CommandList& cmd) {
            if (reduce)
                recordReduce(cmd);
            recordCones(cmd, bindings, gpu::PushConstants(bytes.data(), bytes.size()), starts);
        };
        return std::nullopt;
    }
    const gpu::RunResult result = mContext->run([&](gpu::CommandList& cmd) {
        if (reduce)
            recordReduce(cmd);
        recordCones(cmd, bindings, constants, starts);
    });
    if (out != nullptr) {
        const std::vector<glm::vec4> e =
            starts.output.downloadVector<glm::vec4>(starts.count * kConeCount);
        out->resize(starts.count * kConeCount);
        for (std::size_t i = 0; i < out->size(); ++i)
            (*out)[i] = glm::vec3(e[i]);
    }
    return result.sumGpuMs(mLabel);
}

glm::vec4 makeConeSkyConstants(bool traced, double skyStartDistance, bool opticalDepth, bool emission)
{
    return {traced ? 1.0f : 0.0f, float(skyStartDistance), opticalDepth ? 1.0f : 0.0f,
            traced && emission ? 1.0f : 0.0f};
}

std::size_t uploadFaceEmission(PixelConeDispatch& dispatch, gpu::Buffer& buffer,
                               const std::vector<glm::vec3>& emission, const char* name)
{
    const std::size_t bytes = emission.size() * sizeof(glm::vec4);
    if (!buffer.isValid() || buffer.getSize() < bytes)
        buffer = dispatch.makeBuffer(bytes, name);
    if (emission.empty())
        return 0;
    std::vector<glm::vec4> packed(emission.size());
    for (std::size_t i = 0; i < emission.size(); ++i)
        packed[i] = glm::vec4(emission[i], 0.0f);
    buffer.uploadSpan<glm::vec4>(packed);
    return bytes;
}

} // namespace rtlab::voxelgi
