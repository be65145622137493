#include "tree_cone_gather_gpu.h"
#include "gpu/shader_compiler.h"

#include <glm/vec4.hpp>


namespace rtlab::voxelgi {

namespace {

struct GatherConstants {
    glm::ivec4 size{0};  // width, height, depth, max steps
    glm::vec4 march{0};  // leaf size, tan(half-angle), start offset, step scale
    glm::vec4 box{0};    // min corner relative to the centre
    glm::ivec4 roots{
        0}; // xyz: root cells per axis, w: the first node record's uint in the topology buffer
    glm::ivec4 masks{0}; // x: shared masks' record bits (0: inline), y: first base's uint, z: table's
    glm::vec4 sky{0};    // makeConeSkyConstants
};
static_assert(sizeof(GatherConstants) == 96, "must match tree_cone_gather.comp");
static_assert(sizeof(VoxelTreeNode) == 3 * sizeof(std::uint32_t), "the shader reads 3 uints per node");
static_assert(AdaptiveVoxelTree::kOffsetBits == 12, "the shader splits a record word at bit 12");
static_assert(sizeof(VoxelTreeRank) == 3 * sizeof(std::uint32_t),
              "the shader reads 3 uints per rank word");

} // namespace

std::filesystem::path TreeConeGatherGpu::getShaderDir()
{
    return gpu::findShaderDir("techniques/voxel_gi/adaptive_voxel_tree_cones/shaders",
                              std::filesystem::path(RTLAB_TECHNIQUE_DIR) / "shaders");
}

void TreeConeGatherGpu::gatherCones(gpu::Context& context, const VoxelTreeCones& tree, const scene::GBuffer& gbuffer,
                                    std::vector<glm::vec3>& out)
{
    trace(context, tree, PixelSource{.gbuffer = &gbuffer}, &out);
}

const gpu::Buffer& TreeConeGatherGpu::gatherConesOnDevice(gpu::Context& context,
                                                          const VoxelTreeCones& tree,
                                                          const scene::GBuffer& gbuffer)
{
    trace(context, tree, PixelSource{.gbuffer = &gbuffer}, nullptr);
    if (tree.getTree() != nullptr)
        return mDispatch.getOutput();
    const std::vector<glm::vec4> zeros(
        std::size_t(gbuffer.width) * std::size_t(gbuffer.height) * kConeCount, glm::vec4(0.0f));
    if (!mZeros.isValid() || mZeros.getSize() < zeros.size() * sizeof(glm::vec4))
        mZeros = mDispatch.makeBuffer(zeros.size() * sizeof(glm::vec4),
                                      "adaptive_voxel_tree_cones.no_tree");
    if (!zeros.empty())
        mZeros.uploadSpan<glm::vec4>(zeros);
    return mZeros;
}

const PixelConeDispatch& TreeConeGatherGpu::gatherConesResident(gpu::Context& context, const VoxelTreeCones& tree,
                                                               const PixelSource& pixels)
{
    trace(context, tree, pixels, nullptr);
    return mDispatch;
}

void TreeConeGatherGpu::trace(gpu::Context& context, const VoxelTreeCones& tree,
                              const PixelSource& pixels, std::vector<glm::vec3>* out)
{
    if (!mDispatch.isReadyFor(context)) {
        const auto sky = mSkyPerCone;
        *this = TreeConeGatherGpu();
        mSkyPerCone = sky;
        mDispatch.create(context, getShaderDir() / "tree_cone_gather.comp", kDispatchLabel, sizeof(GatherConstants),
                         tree.getCones(), 1, true);
    }
    const AdaptiveVoxelTree* t = tree.getTree();
    const glm::ivec2 size = pixels.getSize();
    mEmptyTree = t == nullptr;
    mLastPixels = std::size_t(size.x) * std::size_t(size.y);
    if (t == nullptr) {
        if (out != nullptr)
            out->assign(std::size_t(size.x) * std::size_t(size.y) * kConeCount, glm::vec3(0.0f));
        // Pixels reduced on the device: their representatives and no light.
        if (pixels.gpu != nullptr) {
            mDispatch.preparePixels(pixels, tree.getOrigin());
            mDispatch.runWithoutCones();
        }
        return;
    }
    mLastUploadBytes = 0;
    if (mUploadedStamp != tree.getStamp()) {
        // One topology buffer: the rank words, then the node records as the tree holds them.
        GpuTreeTopology packed = packTopologyForGpu(*t);
        const std::vector<std::uint32_t>& topology = packed.words;
        mRecordStart = packed.recordStart;
        mMasks = packed.masks;
        const std::size_t nodeBytes = topology.size() * sizeof(std::uint32_t);
        const auto& gathered = tree.getGathered();
        if (!mNodes.isValid() || mNodes.getSize() < nodeBytes)
            mNodes = mDispatch.makeBuffer(nodeBytes, "adaptive_voxel_tree_cones.topology");
        if (!mGathered.isValid() || mGathered.getSize() < gathered.size() * sizeof(glm::vec4))
            mGathered = mDispatch.makeBuffer(gathered.size() * sizeof(glm::vec4), "adaptive_voxel_tree_cones.gathered");
        mNodes.uploadSpan<std::uint32_t>(topology);
        mGathered.uploadSpan<glm::vec4>(gathered);
        mLastUploadBytes += nodeBytes + gathered.size() * sizeof(glm::vec4);
        mEmits = !tree.getEmission().empty();
        mLastUploadBytes +=
            uploadFaceEmission(mDispatch, mEmission, tree.getEmission(), "adaptive_voxel_tree_cones.emission");
        mUploadedStamp = tree.getStamp();
    }
    const glm::dvec3 anchor = tree.getOrigin() + 0.5 * tree.getBoxSize();
    mLastUploadBytes += mDispatch.preparePixels(pixels, anchor);
    if (mSkyPerCone)
        mLastUploadBytes += mDispatch.setSkyPerCone(*mSkyPerCone);
    const TreeConeSettings& s = tree.getSettings();
    GatherConstants constants;
    constants.size = {size.x, size.y, s.depth, 1024};
    constants.march = {float(tree.getLeafSize()), float(tree.getCones().tanHalfAngle), float(s.startOffset),
                       float(s.stepScale)};
    constants.box = glm::vec4(glm::vec3(tree.getOrigin() - anchor), 0.0f);
    constants.roots = glm::ivec4(t->getLayout().rootCells, int(mRecordStart));
    constants.masks = mMasks;
    constants.sky = makeConeSkyConstants(mSkyPerCone.has_value(), s.skyStart * tree.getLeafSize(), s.skyOpticalDepth,
                                         mEmits);
    mLastGpuMs = mDispatch.run(mNodes, mGathered, gpu::PushConstants(constants), out, {&mEmission});
}

void TreeConeGatherGpu::readBackSky(std::vector<glm::vec3>& out) const
{
    if (mEmptyTree)
        out.assign(mLastPixels * kConeCount, glm::vec3(0.0f));
    else
        mDispatch.readBackSky(out);
}

} // namespace rtlab::voxelgi
