#include "svo_gather_gpu.h"
#include "gpu/shader_compiler.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::voxelgi {

namespace {

struct GatherConstants {
    glm::ivec4 size{0}; // width, height, depth, max steps
    glm::vec4 march{0}; // leaf size, tan(half-angle), start offset, step scale
    glm::vec4 cube{0};  // min corner relative to the centre, side
    glm::ivec4 mode{0}; // x: 1 = corner bricks
    glm::vec4 sky{0};   // makeConeSkyConstants
};
static_assert(sizeof(GatherConstants) == 80, "must match svo_gather.comp");

} // namespace

std::filesystem::path OctreeGatherGpu::getShaderDir()
{
    return gpu::findShaderDir("techniques/voxel_gi/svo/shaders",
                              std::filesystem::path(RTLAB_TECHNIQUE_DIR) / "shaders");
}

void OctreeGatherGpu::gatherCones(gpu::Context& context, const SparseVoxelOctree& tree,
                                  const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out)
{
    trace(context, tree, PixelSource{.gbuffer = &gbuffer}, &out);
}

const gpu::Buffer& OctreeGatherGpu::gatherConesOnDevice(gpu::Context& context,
                                                        const SparseVoxelOctree& tree,
                                                        const scene::GBuffer& gbuffer)
{
    trace(context, tree, PixelSource{.gbuffer = &gbuffer}, nullptr);
    return mDispatch.getOutput();
}

const PixelConeDispatch& OctreeGatherGpu::gatherConesResident(gpu::Context& context, const SparseVoxelOctree& tree,
                                                             const PixelSource& pixels)
{
    trace(context, tree, pixels, nullptr);
    return mDispatch;
}

void OctreeGatherGpu::trace(gpu::Context& context, const SparseVoxelOctree& tree,
                            const PixelSource& pixels, std::vector<glm::vec3>* out)
{
    if (!mDispatch.isReadyFor(context)) {
        const auto sky = mSkyPerCone;
        *this = OctreeGatherGpu();
        mSkyPerCone = sky;
        mDispatch.create(context, getShaderDir() / "svo_gather.comp", kDispatchLabel, sizeof(GatherConstants),
                         tree.getCones(), 1, true);
    }
    mLastUploadBytes = 0;
    if (mUploadedStamp != tree.getStamp()) {
        const auto& children = tree.getChildPointers();
        // With corner bricks the shader reads the bricks instead of the per-node values.
        const auto& gathered =
            tree.getSettings().cornerBricks ? tree.getGatheredBricks() : tree.getGathered();
        if (!mChildren.isValid() || mChildren.getSize() < children.size() * sizeof(std::uint32_t))
            mChildren = mDispatch.makeBuffer(children.size() * sizeof(std::uint32_t), "svo.children");
        if (!mGathered.isValid() || mGathered.getSize() < gathered.size() * sizeof(glm::vec4))
            mGathered = mDispatch.makeBuffer(gathered.size() * sizeof(glm::vec4), "svo.gathered");
        mChildren.uploadSpan<std::uint32_t>(children);
        mGathered.uploadSpan<glm::vec4>(gathered);
        mLastUploadBytes += children.size() * sizeof(std::uint32_t) + gathered.size() * sizeof(glm::vec4);
        // The emitters the pixels' cones meet; the bricks hold none (sampleBrickLevel).
        static const std::vector<glm::vec3> kNone;
        const auto& emission = tree.getSettings().cornerBricks ? kNone : tree.getEmission();
        mEmits = !emission.empty();
        mLastUploadBytes += uploadFaceEmission(mDispatch, mEmission, emission, "svo.emission");
        mUploadedStamp = tree.getStamp();
    }
    const glm::dvec3 anchor = tree.getOrigin() + glm::dvec3(0.5 * tree.getSide());
    const glm::ivec2 size = pixels.getSize();
    const int w = size.x, h = size.y;
    mLastUploadBytes += mDispatch.preparePixels(pixels, anchor);
    if (mSkyPerCone)
        mLastUploadBytes += mDispatch.setSkyPerCone(*mSkyPerCone);

    const OctreeSettings& s = tree.getSettings();
    GatherConstants constants;
    constants.size = {w, h, tree.getDepth(), 1024};
    constants.march = {float(tree.getLeafSize()), float(tree.getCones().tanHalfAngle),
                       float(s.startOffset), float(s.stepScale)};
    constants.cube = glm::vec4(glm::vec3(tree.getOrigin() - anchor), float(tree.getSide()));
    constants.mode = glm::ivec4(s.cornerBricks ? 1 : 0, 0, 0, 0);
    constants.sky = makeConeSkyConstants(mSkyPerCone.has_value(), s.skyStart * tree.getLeafSize(), s.skyOpticalDepth,
                                         mEmits);
    mLastGpuMs = mDispatch.run(mChildren, mGathered, gpu::PushConstants(constants), out, {&mEmission});
}

} // namespace rtlab::voxelgi
