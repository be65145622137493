#pragma once
// The pixel gather of the adaptive voxel tree on Vulkan (shaders/tree_cone_gather.comp): the
// tree's topology (its rank words, then its node records: mask low, mask high, offset; 3 uints
// each) and the gathered light of every element in two storage buffers, uploaded again only when
// the tree or its light changed; positions go up relative to the lattice's centre. Asked for the
// cones' sky, the same dispatch also writes the sky and emitters each cone sees past the voxels.

#include "voxel_tree_cones.h"

#include "families/voxel_gi/cone_gather_gpu.h"
#include "gpu/context.h"

#include <glm/vec4.hpp>

#include <filesystem>
#include <optional>
#include <vector>

namespace rtlab::voxelgi {

class TreeConeGatherGpu {
public:
    static constexpr const char* kDispatchLabel = "adaptive_voxel_tree_cones.gather";

    //! VoxelTreeCones::gatherCones on the GPU, [pixel * 16 + cone].
    void gatherCones(gpu::Context& context, const VoxelTreeCones& tree, const scene::GBuffer& gbuffer,
                     std::vector<glm::vec3>& out);
    //! The same without the read-back: the radiances stay on the device, in the returned buffer
    //! (for cone_combine_gpu.h), valid until the next call.
    const gpu::Buffer& gatherConesOnDevice(gpu::Context& context, const VoxelTreeCones& tree,
                                           const scene::GBuffer& gbuffer);
    //! The same from pixels reduced on the device (the resident gather, cone_combine_gpu.h
    //! gatherConesResident): the dispatch holds the radiances (zero for an empty tree) and the
    //! representatives.
    const PixelConeDispatch& gatherConesResident(gpu::Context& context, const VoxelTreeCones& tree,
                                                 const PixelSource& pixels);
    //! Whether the following gathers also trace the sky and emitters each cone sees past the
    //! voxels (the sky per cone, computeSkyPerCone), or not (nullopt).
    void setConeSky(const std::optional<std::array<glm::vec3, kConeCount>>& skyPerCone) { mSkyPerCone = skyPerCone; }
    //! The cones' sky of the last gather, which traced it, [pixel * 16 + cone] (zero for an
    //! empty tree).
    void readBackSky(std::vector<glm::vec3>& out) const;
    std::optional<double> getLastGpuMs() const { return mLastGpuMs ? mLastGpuMs : mDispatch.getDeferredGpuMs(); }
    std::size_t getLastUploadBytes() const { return mLastUploadBytes; }
    //! $RTLAB_SOURCE_DIR/techniques/voxel_gi/adaptive_voxel_tree_cones/shaders when set, else the
    //! source folder.
    static std::filesystem::path getShaderDir();

private:
    void trace(gpu::Context& context, const VoxelTreeCones& tree, const PixelSource& pixels,
               std::vector<glm::vec3>* out);

    PixelConeDispatch mDispatch;
    gpu::Buffer mNodes, mGathered, mEmission;
    bool mEmits = false;
    bool mEmptyTree = false; //!< the last gather had no tree: no cones traced
    std::size_t mLastPixels = 0;
    std::optional<std::array<glm::vec3, kConeCount>> mSkyPerCone;
    gpu::Buffer mZeros; //!< the radiances of an empty tree, when kept on the device
    std::uint32_t mRecordStart = 0; //!< uint index of the first node record in mNodes
    glm::ivec4 mMasks{0};           //!< the shader's masks constant (shared masks: where they lie)
    std::uint64_t mUploadedStamp = 0;
    std::optional<double> mLastGpuMs;
    std::size_t mLastUploadBytes = 0;
};

} // namespace rtlab::voxelgi
