#include "svo_gather_gpu.h"

#include "gpu/shader_compiler.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace rtlab::voxelgi {

namespace {

struct GatherConstants {
    glm::ivec4 size{0}; // width, height, depth, max steps
    glm::vec4 march{0}; // leaf size, tan(half-angle), start offset, step scale
    glm::vec4 cube{0};  // min corner relative to the centre, side
};
static_assert(sizeof(GatherConstants) == 48, "must match svo_gather.comp");

gpu::Buffer makeBuffer(gpu::Context& context, std::size_t bytes, const char* name)
{
    return context.createBuffer({std::max<std::size_t>(bytes, 16), name});
}

} // namespace

std::filesystem::path OctreeGatherGpu::getShaderDir()
{
    if (const char* root = std::getenv("RTLAB_SOURCE_DIR"); root != nullptr && *root != '\0')
        return std::filesystem::path(root) / "techniques" / "voxel_gi" / "svo" / "shaders";
    return std::filesystem::path(RTLAB_TECHNIQUE_DIR) / "shaders";
}

void OctreeGatherGpu::gatherCones(gpu::Context& context, const SparseVoxelOctree& tree,
                                  const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out)
{
    if (mContext != &context) {
        *this = OctreeGatherGpu();
        mContext = &context;
    }
    if (!mPipeline.isValid()) {
        const gpu::ShaderCompiler compiler;
        gpu::ComputePipelineDesc desc;
        desc.name = kDispatchLabel;
        desc.spirv = compiler.compileFile(getShaderDir() / "svo_gather.comp").spirv;
        for (std::uint32_t b = 0; b < 6; ++b)
            desc.bindings.push_back({b, gpu::BindingType::StorageBuffer});
        desc.pushConstantSize = sizeof(GatherConstants);
        mPipeline = context.createPipeline(desc);
        std::vector<glm::vec4> cones(kConeCount);
        for (int k = 0; k < kConeCount; ++k)
            cones[std::size_t(k)] = glm::vec4(glm::vec3(tree.getCones().directions[std::size_t(k)]), 0.0f);
        mCones = makeBuffer(context, cones.size() * sizeof(glm::vec4), "svo.cones");
        mCones.uploadSpan<glm::vec4>(cones);
    }
    mLastUploadBytes = 0;
    if (mUploadedStamp != tree.getStamp()) {
        const auto& children = tree.getChildPointers();
        const auto& gathered = tree.getGathered();
        if (!mChildren.isValid() || mChildren.getSize() < children.size() * sizeof(std::uint32_t))
            mChildren = makeBuffer(context, children.size() * sizeof(std::uint32_t), "svo.children");
        if (!mGathered.isValid() || mGathered.getSize() < gathered.size() * sizeof(glm::vec4))
            mGathered = makeBuffer(context, gathered.size() * sizeof(glm::vec4), "svo.gathered");
        mChildren.uploadSpan<std::uint32_t>(children);
        mGathered.uploadSpan<glm::vec4>(gathered);
        mLastUploadBytes += children.size() * sizeof(std::uint32_t) + gathered.size() * sizeof(glm::vec4);
        mUploadedStamp = tree.getStamp();
    }
    const glm::dvec3 anchor = tree.getOrigin() + glm::dvec3(0.5 * tree.getSide());
    const int w = gbuffer.width, h = gbuffer.height;
    const std::size_t pixels = std::size_t(w) * std::size_t(h);
    if (mPixels != pixels) {
        mPositions = makeBuffer(context, pixels * sizeof(glm::vec4), "svo.positions");
        mNormals = makeBuffer(context, pixels * sizeof(glm::vec4), "svo.normals");
        mOutput = makeBuffer(context, pixels * kConeCount * sizeof(glm::vec4), "svo.cone_radiance");
        mPixels = pixels;
    }
    std::vector<glm::vec4> positions(pixels), normals(pixels);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const glm::dvec3 p(gbuffer.position.at(x, y));
            const bool surface = gbuffer.hasSurface(x, y) && std::isfinite(p.x + p.y + p.z);
            positions[i] = glm::vec4(glm::vec3(surface ? p - anchor : glm::dvec3(0.0)), surface ? 1.0f : 0.0f);
            normals[i] = glm::vec4(gbuffer.normal.at(x, y), 0.0f);
        }
    mPositions.uploadSpan<glm::vec4>(positions);
    mNormals.uploadSpan<glm::vec4>(normals);
    mLastUploadBytes += 2 * pixels * sizeof(glm::vec4);

    const OctreeSettings& s = tree.getSettings();
    GatherConstants constants;
    constants.size = {w, h, tree.getDepth(), 1024};
    constants.march = {float(tree.getLeafSize()), float(tree.getCones().tanHalfAngle),
                       float(s.startOffset), float(s.stepScale)};
    constants.cube = glm::vec4(glm::vec3(tree.getOrigin() - anchor), float(tree.getSide()));
    const gpu::RunResult result = context.run([&](gpu::CommandList& cmd) {
        cmd.dispatch(mPipeline,
                     {gpu::Binding::storageBuffer(0, mChildren), gpu::Binding::storageBuffer(1, mGathered),
                      gpu::Binding::storageBuffer(2, mPositions), gpu::Binding::storageBuffer(3, mNormals),
                      gpu::Binding::storageBuffer(4, mOutput), gpu::Binding::storageBuffer(5, mCones)},
                     gpu::PushConstants(constants),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(w), 8),
                                     gpu::computeGroupCount(std::uint64_t(h), 8), 1},
                     kDispatchLabel);
    });
    mLastGpuMs = result.sumGpuMs(kDispatchLabel);
    const std::vector<glm::vec4> e = mOutput.downloadVector<glm::vec4>(pixels * kConeCount);
    out.resize(pixels * kConeCount);
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = glm::vec3(e[i]);
}

} // namespace rtlab::voxelgi
