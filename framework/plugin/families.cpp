#include "plugin/technique.h"

namespace rtlab::plugin {

void registerBuiltinFamilies(Registry& registry)
{
    registry.addFamily({
        .name = "occlusion",
        .summary = "screen-space ambient occlusion / obscurance with bent normals and cones",
        .input = "G-buffer (linear depth, view-space normals) and camera",
        .output = "AO or obscurance in [0,1], bent normal, cone aperture",
        .groundTruth = "Embree rays from the same G-buffer points, same quantity and radius",
    });
    registry.addFamily({
        .name = "isosurface",
        .summary = "triangle meshes from sampled signed distance fields",
        .input = "SDF samples on a regular grid (+ exact field for Hermite data)",
        .output = "indexed triangle mesh",
        .groundTruth = "the analytic SDF of the model",
    });
    registry.addFamily({
        .name = "voxel_gi",
        .summary = "voxel scene structures cone traced for indirect diffuse light",
        .input = "anisotropic voxelization of the scene, G-buffer",
        .output = "indirect irradiance at G-buffer pixels",
        .groundTruth = "Embree path tracer, indirect only, same lights",
    });
}

} // namespace rtlab::plugin
