#pragma once
// Voxelization of triangles into the volumetric G-buffer every voxel_gi technique builds on
// (the Tomorrow Children, shared/seeds/000_3da000e866ebc485.txt, "Volumetric G-Buffer" and
// "Object Voxelization"):
//
//  * Anisotropic voxels: per voxel and per axis face (+x, -x, +y, -y, +z, -z) the albedo and
//    occupancy seen from that side, the emission, and the voxel's mean surface normal.
//  * Coverage from supersampling: the region is rasterised along each axis with `supersampling`
//    x `supersampling` rays per voxel column (the talk renders at 16x the resolution per axis).
//    A face's occupancy is the share of its axis' rays that meet a surface inside the voxel, and
//    its albedo and emission are those of the front-most surface each ray meets in the voxel
//    (entering from that face's side), averaged over the rays. An object that moves by less
//    than a voxel therefore changes occupancy smoothly instead of jumping.
//  * Solid voxelization ("Post Processing: ensure a solid voxelization"): along every axis a
//    column's rays count entries (front faces) and exits (back faces); a voxel whose centre lies
//    inside a closed span on at least two of the three axes is solid (occupancy 1 on every
//    face; the majority keeps one-sided open geometry such as a floor plane from filling the
//    space behind it). The surface attributes are propagated one layer inward: a solid voxel's
//    face takes the albedo of the surface voxel beside it on that side.
//  * The list of surface voxels (the voxels light is traced from).
//
// This is the CPU path (deterministic for any thread count: every ray's fragments are sorted by
// depth and triangle). Triangles are two-sided, as in the ground truth.

#include "scene/render_scene.h"

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rtlab::voxelgi {

inline constexpr int kFaceCount = 6;
//! Face f of a voxel is the side whose outward normal is getFaceNormal(f):
//! 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z.
glm::vec3 getFaceNormal(int face);

//! An axis-aligned cube of resolution^3 voxels.
struct VoxelRegion {
    glm::dvec3 origin{0.0}; //!< world position of the min corner
    double voxelSize = 1.0; //!< world units
    int resolution = 0;

    glm::dvec3 getMaxCorner() const { return origin + glm::dvec3(voxelSize * resolution); }
    std::size_t getVoxelCount() const
    {
        return std::size_t(resolution) * std::size_t(resolution) * std::size_t(resolution);
    }
    std::size_t index(int x, int y, int z) const
    {
        return std::size_t(x) +
               std::size_t(resolution) * (std::size_t(y) + std::size_t(resolution) * std::size_t(z));
    }
    glm::dvec3 getVoxelCentre(int x, int y, int z) const
    {
        return origin + (glm::dvec3(x, y, z) + 0.5) * voxelSize;
    }
    bool operator==(const VoxelRegion&) const = default;
};

enum VoxelFlags : std::uint8_t {
    kVoxelSurface = 1u << 0, //!< some surface passes through it
    kVoxelSolid = 1u << 1,   //!< inside a closed object (no surface)
};

//! The volumetric G-buffer of one region (dense).
struct VoxelGrid {
    VoxelRegion region;
    std::vector<glm::vec4> faces;     //!< [voxel * 6 + face]: rgb albedo, a occupancy in [0, 1]
    std::vector<glm::vec3> emission;  //!< [voxel * 6 + face]: emitted radiance seen from that side
    std::vector<glm::vec3> normal;    //!< [voxel]: mean surface normal (unit) or 0
    std::vector<std::uint8_t> flags;  //!< [voxel]: VoxelFlags
    std::vector<std::uint32_t> surfaceVoxels; //!< indices of the surface voxels, ascending

    const glm::vec4& face(std::size_t voxel, int f) const { return faces[voxel * kFaceCount + f]; }
};

struct VoxelizeOptions {
    int supersampling = 4; //!< rays per voxel column and axis, per side (1..16)
    bool solid = true;     //!< fill closed spans and propagate attributes inward
    //! Only the voxels in [boxBegin, boxEnd) (voxel indices; boxEnd -1 = the resolution) are
    //! voxelized, the others stay empty: a scrolled slab or a dug region. A voxel's values depend
    //! only on the rays through its column, so they equal those of a whole-region voxelization.
    glm::ivec3 boxBegin{0};
    glm::ivec3 boxEnd{-1};
};

struct VoxelizeStats {
    std::size_t trianglesConsidered = 0; //!< triangles whose bounds meet the region's columns
    std::size_t fragments = 0;           //!< ray-triangle hits, all axes
    std::size_t surfaceVoxels = 0;
    std::size_t solidVoxels = 0;
};

//! Throws rtlab::Error for a region with a resolution outside [1, maxResolution], a non-positive
//! or non-finite voxel size or a non-finite origin, or supersampling outside [1, 16].
void checkVoxelizeArguments(const VoxelRegion& region, const VoxelizeOptions& options,
                            int maxResolution = 1024);
//! The voxel box [begin, end) that options.boxBegin/boxEnd select in `region`.
void getVoxelizeBox(const VoxelRegion& region, const VoxelizeOptions& options, glm::ivec3& begin,
                    glm::ivec3& end);

//! Voxelizes every triangle of `scene` that meets `region` (its box). Throws rtlab::Error for a
//! region with resolution < 1 or a non-positive or non-finite voxel size, or a bad option.
VoxelGrid voxelizeTriangles(const scene::RenderScene& scene, const VoxelRegion& region,
                            const VoxelizeOptions& options, VoxelizeStats* stats = nullptr);

//! The steps that look across voxels, after the grid's voxels were set (voxelizeTriangles does
//! this; call it again after pasting parts of grids together): solid voxels' faces opaque with
//! the neighbouring surface's albedo (one layer inward), and the list of surface voxels.
//! Returns the number of solid voxels.
std::size_t finalizeVoxelGrid(VoxelGrid& grid);

//! The voxels of `old` that lie in `region` (the same lattice, `shift` voxels further: region's
//! voxel v is old's voxel v + shift), the rest empty; call finalizeVoxelGrid after filling it.
VoxelGrid shiftVoxelGrid(const VoxelGrid& old, const VoxelRegion& region, const glm::ivec3& shift);
//! Copies the voxels of `part` in [begin, end) (end -1 = the resolution) into `grid` (same region).
void pasteVoxelBox(const VoxelGrid& part, const glm::ivec3& begin, const glm::ivec3& end,
                   VoxelGrid& grid);

//! The cells of a lattice (min corner `origin`, cube cells of `cellSize`, `cells` per axis) that
//! a triangle of `scene` meets, for sparse structures that are built from the voxels geometry
//! passes through (the "voxel fragments" of Crassin et al. 2011; the solid children of Quantum
//! Break's tree). Closed cells: a triangle touching a cell's face meets it. Exact separating-axis
//! test per cell (Akenine-Moeller 2001, "Fast 3D Triangle-Box Overlap Testing"), visiting only
//! the cells around the triangle's plane. Sorted by (z, y, x), unique; degenerate and non-finite
//! triangles meet nothing. Throws rtlab::Error for a non-positive cell size or cell count.
std::vector<glm::ivec3> listCellsMeetingTriangles(const scene::RenderScene& scene,
                                                  const glm::dvec3& origin, double cellSize,
                                                  const glm::ivec3& cells);

} // namespace rtlab::voxelgi
