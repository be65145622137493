// The voxel_gi family: voxel scene structures (cascades, sparse octree, 64-ary adaptive tree)
// cone traced for indirect diffuse light. The technique interface is families/voxel_gi/voxel_gi.h; the family
// has no passes yet (no technique is registered), so its runs are refused with that reason.

#include "experiment/family.h"
#include "families/voxel_gi/voxel_gi.h"

namespace rtlab::families {
namespace {

plugin::FamilyInfo describeVoxelGiFamily()
{
    plugin::FamilyInfo info{
        .name = "voxel_gi",
        .summary = "voxel scene structures cone traced for indirect diffuse light",
        .input = "anisotropic voxelization of the scene, G-buffer",
        .output = "indirect irradiance at G-buffer pixels",
        .groundTruth = "Embree path tracer, indirect only, same lights",
        .metrics = {{"error",
                     "RMSE, relative MSE, PSNR of indirect irradiance over surface pixels"}},
    };
    info.domain = plugin::FamilyDomain::Screen;
    info.report = {.cost = "technique_ms",
                   .costLabel = "time of the technique (ms, median, GPU)",
                   .error = "indirect.rmse",
                   .errorLabel = "RMSE of indirect irradiance against ground truth",
                   .passes = {"gbuffer.gpu_ms", "technique_ms"},
                   .passTimeLabel = "time (ms, median, GPU)"};
    return info; // no runtime: the runner refuses its runs by name
}

} // namespace
} // namespace rtlab::families

RTLAB_REGISTER_FAMILY(voxel_gi, rtlab::families::describeVoxelGiFamily)
