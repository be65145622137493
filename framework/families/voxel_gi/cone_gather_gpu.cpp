#include "families/voxel_gi/cone_gather_gpu.h"

#include "gpu/shader_compiler.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::voxelgi {

void PixelConeDispatch::create(gpu::Context& context, const std::filesystem::path& shader,
                               const std::string& label, std::size_t pushConstantSize, const ConeSet& cones,
                               std::uint32_t extraBuffers)
{
    *this = PixelConeDispatch();
    mContext = &context;
    mLabel = label;
    const gpu::ShaderCompiler compiler;
    gpu::ComputePipelineDesc desc;
    desc.name = label;
    desc.spirv = compiler.compileFile(shader).spirv;
    for (std::uint32_t b = 0; b < 6 + extraBuffers; ++b)
        desc.bindings.push_back({b, gpu::BindingType::StorageBuffer});
    desc.pushConstantSize = std::uint32_t(pushConstantSize);
    mPipeline = context.createPipeline(desc);
    std::vector<glm::vec4> directions(kConeCount);
    for (int k = 0; k < kConeCount; ++k)
        directions[std::size_t(k)] = glm::vec4(glm::vec3(cones.directions[std::size_t(k)]), 0.0f);
    mCones = makeBuffer(directions.size() * sizeof(glm::vec4), "cone_gather.cones");
    mCones.uploadSpan<glm::vec4>(directions);
}

gpu::Buffer PixelConeDispatch::makeBuffer(std::size_t bytes, const char* name, bool hostVisible)
{
    return mContext->createBuffer(
        {.size = std::max<std::size_t>(bytes, 16), .name = name, .hostVisible = hostVisible});
}

void PixelConeDispatch::reserve(Starts& starts, std::size_t entries, const char* what)
{
    if (starts.capacity != entries) {
        const std::string name = std::string("cone_gather.") + what;
        // Uploaded for every dispatch: read by the shader where the host wrote them.
        starts.positions =
            makeBuffer(entries * sizeof(glm::vec4), (name + ".positions").c_str(), true);
        starts.normals = makeBuffer(entries * sizeof(glm::vec4), (name + ".normals").c_str(), true);
        starts.output = makeBuffer(entries * kConeCount * sizeof(glm::vec4), (name + ".cone_radiance").c_str());
        starts.capacity = entries;
    }
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

std::optional<double> PixelConeDispatch::run(gpu::Buffer& first, gpu::Buffer& second,
                                             const gpu::PushConstants& constants,
                                             std::vector<glm::vec3>* out,
                                             const std::vector<gpu::Buffer*>& extra, bool points)
{
    Starts& starts = points ? mPoints : mPixels;
    std::vector<gpu::Binding> bindings = {
        gpu::Binding::storageBuffer(0, first),            gpu::Binding::storageBuffer(1, second),
        gpu::Binding::storageBuffer(2, starts.positions), gpu::Binding::storageBuffer(3, starts.normals),
        gpu::Binding::storageBuffer(4, starts.output),    gpu::Binding::storageBuffer(5, mCones)};
    for (std::size_t i = 0; i < extra.size(); ++i)
        bindings.push_back(gpu::Binding::storageBuffer(std::uint32_t(6 + i), *extra[i]));
    const gpu::RunResult result = mContext->run([&](gpu::CommandList& cmd) {
        cmd.dispatch(mPipeline, bindings, constants,
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(starts.width), 8),
                                     gpu::computeGroupCount(std::uint64_t(starts.height), 8),
                                     std::uint32_t(kConeCount)},
                     mLabel.c_str());
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

} // namespace rtlab::voxelgi
