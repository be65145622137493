#pragma once
// Voxelization of triangles on Vulkan (shaders/voxelize_columns.comp, voxelize_resolve.comp): the
// algorithm of voxelize.h's voxelizeTriangles, one invocation per voxel column and axis casting
// the column's supersampled rays through the triangles binned to it (the binning in C++), then
// one per voxel turning the three axes' sums into the volumetric G-buffer. The solid fill's one
// layer inward and the list of surface voxels (finalizeVoxelGrid) run in C++ on the result.
// Float from positions relative to the region's min corner: a sample on a triangle's edge or a
// fragment on a voxel boundary may fall the other way than in the double C++ path (the tests
// bound how many voxels differ).

#include "families/voxel_gi/voxelize.h"
#include "gpu/context.h"

#include <filesystem>

namespace rtlab::voxelgi {

class VoxelizerGpu {
public:
    static constexpr const char* kColumnsLabel = "voxelize.columns";
    static constexpr const char* kResolveLabel = "voxelize.resolve";
    static constexpr int kMaxResolution = 128;
    static constexpr int kMaxFragmentsPerRay = 64; //!< must match voxelize_columns.comp
    //! Columns (of one axis) holding more triangles than this are voxelized by the C++ path: an
    //! invocation loops over its column's triangles, and lavapipe ends any invocation after
    //! 65,535 loop iterations in all.
    static constexpr std::uint32_t kMaxTrianglesPerColumn = 40000;

    //! voxelizeTriangles on Vulkan, for regions up to kMaxResolution voxels per axis (throws
    //! rtlab::Error beyond, and for the arguments voxelizeTriangles refuses). When some ray meets
    //! more than kMaxFragmentsPerRay surfaces, or a column holds more than
    //! kMaxTrianglesPerColumn triangles, the region is voxelized by the C++ path instead (counted
    //! in Counters::fallbacks).
    VoxelGrid voxelize(gpu::Context& context, const scene::RenderScene& scene, const VoxelRegion& region,
                       const VoxelizeOptions& options, VoxelizeStats* stats = nullptr);

    //! Sums over the calls since resetCounters.
    struct Counters {
        int calls = 0;
        int fallbacks = 0;
        double submitMs = 0.0; //!< wall time from submit to completion of the dispatches
        double callMs = 0.0;   //!< wall time of the calls (binning, uploads, read-back, finalize)
        std::size_t uploadBytes = 0;
    };
    const Counters& getCounters() const { return mCounters; }
    void resetCounters() { mCounters = {}; }

    //! $RTLAB_SOURCE_DIR/framework/families/voxel_gi/shaders when set, else the source folder.
    static std::filesystem::path getShaderDir();

private:
    gpu::Context* mContext = nullptr;
    gpu::ComputePipeline mColumns, mResolve;
    gpu::Buffer mTriangles, mMaterials, mBinStart, mBins, mCounts, mFaceSums, mNormalSums, mStats;
    gpu::Buffer mFaces, mEmission, mNormals;
    Counters mCounters;

    // A buffer of at least `bytes`; `hostVisible` for data that crosses the bus once per call
    // (gpu::BufferDesc::hostVisible).
    gpu::Buffer& reserve(gpu::Buffer& buffer, std::size_t bytes, const char* name,
                         bool hostVisible = false);
};

} // namespace rtlab::voxelgi
