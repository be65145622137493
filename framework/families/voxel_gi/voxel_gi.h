#pragma once
// Family `voxel_gi`: a voxel scene structure (cascades, sparse octree, 64-ary adaptive tree) built
// from the voxelized scene, then cone traced to give indirect diffuse irradiance at G-buffer pixels.
// Ground truth: the path tracer's indirect-only irradiance with the same lights.

#include "core/image.h"
#include "plugin/technique.h"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace rtlab::plugin {

//! One voxel of the anisotropic scene voxelization: per axis-aligned face direction (+x,-x,+y,
//! -y,+z,-z) the albedo and occupancy seen from that side, plus emission and normal.
struct VoxelSample {
    glm::ivec3 coord{0};                //!< integer voxel coordinate at the finest level
    std::array<glm::vec4, 6> faces{};   //!< rgb albedo, a = occupancy in [0, 1]
    glm::vec3 emission{0.0f};           //!< radiance units
    glm::vec3 normal{0.0f};             //!< average surface normal, may be zero
};

//! The voxelized scene shared by all voxel_gi techniques.
struct VoxelScene {
    glm::dvec3 origin{0.0};     //!< world position of voxel (0, 0, 0)'s corner
    double voxelSize = 1.0;     //!< finest voxel edge, world units
    int resolution = 0;         //!< finest grid is resolution^3
    std::vector<VoxelSample> voxels;  //!< occupied voxels only
};

struct VoxelGiInput {
    const VoxelScene* scene = nullptr;
    const Image<glm::vec3>* worldPosition = nullptr;  //!< G-buffer, world units
    const Image<glm::vec3>* worldNormal = nullptr;    //!< G-buffer, unit length
};

//! Sizes the family reports for the data-structure metrics.
struct VoxelGiMemory {
    std::size_t topologyBytes = 0;  //!< tree nodes, masks, pointers
    std::size_t payloadBytes = 0;   //!< colours, occupancy, light
};

class VoxelGiTechnique : public Technique {
public:
    static constexpr const char* kFamily = "voxel_gi";
    //! Builds (or updates) the structure from the voxelized scene.
    virtual void build(const VoxelScene& scene) = 0;
    //! Indirect diffuse irradiance at every G-buffer pixel.
    virtual void gather(const VoxelGiInput& input, Image<glm::vec3>& irradiance) = 0;
    virtual VoxelGiMemory memory() const = 0;
};

} // namespace rtlab::plugin
