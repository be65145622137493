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
        .metrics = {
            {"error", "RMSE, relative MSE, PSNR, mean signed error over surface pixels (ao.*)"},
            {"ssim", "structural similarity against the ground truth (ao.ssim)"},
            {"flip", "FLIP perceptual difference (ao.flip)"},
            {"masks", "errors inside the artifact masks: depth edges, thin occluders, screen border"},
            {"bent_cone", "bent-normal angle and cone-aperture errors against the ray-traced bent cone"},
            {"screen_space_split", "error against rays on the depth buffer (estimator error) and that "
                                   "ground truth's error against the full scene (what screen space cannot see)"},
            {"flicker", "frame-to-frame change along the camera path, beside the ground truth's"},
        },
    });
    registry.addFamily({
        .name = "isosurface",
        .summary = "triangle meshes from sampled signed distance fields",
        .input = "SDF samples on a regular grid (+ exact field for Hermite data)",
        .output = "indexed triangle mesh",
        .groundTruth = "the analytic SDF of the model",
        .metrics = {
            {"deviation", "distance of the mesh to the exact surface (max, mean, RMS) and volume error"},
            {"topology", "watertight, boundary / non-manifold / inconsistent edges, Euler characteristic"},
            {"chamfer", "two-sided Chamfer and Hausdorff distance to a dense sampling of the exact surface"},
            {"sharp_features", "edge-Chamfer and edge-F1 on the model's sharp features"},
            {"triangle_quality", "triangle-angle histogram and minimum angle"},
            {"self_intersections", "pairs of intersecting triangles (Embree collide)"},
        },
    });
    registry.addFamily({
        .name = "voxel_gi",
        .summary = "voxel scene structures cone traced for indirect diffuse light",
        .input = "anisotropic voxelization of the scene, G-buffer",
        .output = "indirect irradiance at G-buffer pixels",
        .groundTruth = "Embree path tracer, indirect only, same lights",
        .metrics = {{"error", "RMSE, relative MSE, PSNR of indirect irradiance over surface pixels"}},
    });
}

} // namespace rtlab::plugin
