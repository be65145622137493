#pragma once
// The pixel gather of the sparse voxel octree on Vulkan (shaders/svo_gather.comp): the child
// pointers and the gathered light of every node in two storage buffers, uploaded again only when
// the tree or its light changed; positions go up relative to the cube's centre. Asked for the
// cones' sky, the same dispatch also writes the sky and emitters each cone sees past the voxels.

#include "sparse_voxel_octree.h"

#include "families/voxel_gi/cone_gather_gpu.h"
#include "gpu/context.h"

#include <filesystem>
#include <optional>
#include <vector>

namespace rtlab::voxelgi {

class OctreeGatherGpu {
public:
    static constexpr const char* kDispatchLabel = "svo.gather";

    //! SparseVoxelOctree::gatherCones on the GPU, [pixel * 16 + cone].
    void gatherCones(gpu::Context& context, const SparseVoxelOctree& tree,
                     const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out);
    //! The same without the read-back: the radiances stay on the device, in the returned buffer
    //! (for cone_combine_gpu.h), valid until the next call.
    const gpu::Buffer& gatherConesOnDevice(gpu::Context& context, const SparseVoxelOctree& tree,
                                           const scene::GBuffer& gbuffer);
    //! The same from pixels reduced on the device (the resident gather, cone_combine_gpu.h
    //! gatherConesResident): the dispatch holds the radiances and the representatives.
    const PixelConeDispatch& gatherConesResident(gpu::Context& context, const SparseVoxelOctree& tree,
                                                 const PixelSource& pixels);
    //! Whether the following gathers also trace the sky and emitters each cone sees past the
    //! voxels (the sky per cone, computeSkyPerCone), or not (nullopt).
    void setConeSky(const std::optional<std::array<glm::vec3, kConeCount>>& skyPerCone) { mSkyPerCone = skyPerCone; }
    //! The cones' sky of the last gather, which traced it, [pixel * 16 + cone].
    void readBackSky(std::vector<glm::vec3>& out) const { mDispatch.readBackSky(out); }
    std::optional<double> getLastGpuMs() const { return mLastGpuMs ? mLastGpuMs : mDispatch.getDeferredGpuMs(); }
    std::size_t getLastUploadBytes() const { return mLastUploadBytes; }
    //! $RTLAB_SOURCE_DIR/techniques/voxel_gi/svo/shaders when set, else the source folder.
    static std::filesystem::path getShaderDir();

private:
    void trace(gpu::Context& context, const SparseVoxelOctree& tree, const PixelSource& pixels,
               std::vector<glm::vec3>* out);

    PixelConeDispatch mDispatch;
    gpu::Buffer mChildren, mGathered, mEmission;
    bool mEmits = false;
    std::optional<std::array<glm::vec3, kConeCount>> mSkyPerCone;
    std::uint64_t mUploadedStamp = 0;
    std::optional<double> mLastGpuMs;
    std::size_t mLastUploadBytes = 0;
};

} // namespace rtlab::voxelgi
