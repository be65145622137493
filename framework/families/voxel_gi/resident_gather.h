#pragma once
// The voxel_gi family's resident gather: the passes of a frame whose technique gathers on the GPU
// from start to end (VoxelGiTechnique::whyNotGatheredOnGpu is ""), so that the G-buffer, the
// occlusion family's visibilities and the irradiance never leave the device.
//
//   voxel_gather           the technique's gather on the G-buffer's GPU images
//                          (FrameStart::positionDepthGpu, worldNormalGpu) and the visibilities'
//                          GPU slot; its irradiance image checked (RGBA32Float, the G-buffer's size)
//   voxel_gather_readback  that image to the CPU, only for passes that read it there (metrics)
//   indirect_gpu_slot      the image in the lit frame's GPU slot (no upload)
//   voxel_cone_sky         the technique's cones' sky image (VoxelGiTechnique::getGpuConeSky) in
//                          the lit frame's GPU slot, or a null slot and the reason
//   voxel_cone_sky_readback  that image to the CPU, only for passes that read it there (the
//                          error split of the cones' sky)

#include "core/image.h"
#include "experiment/results.h"
#include "families/voxel_gi/voxel_gi.h"
#include "pipeline/frame_graph.h"
#include "pipeline/frame_start.h"

#include <glm/vec3.hpp>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace rtlab::voxelgi {

struct ResidentGatherResources {
    pipeline::Resource<int> voxelLight;               //!< the technique's light is up to date
    pipeline::Resource<Image<glm::vec3>> indirect;    //!< the CPU irradiance the read-back writes
    //! The frame's triangles, lights and sky (the sky of the cones' sky).
    pipeline::Resource<scene::RenderScene> geometry;
    pipeline::Resource<Image<glm::vec3>> coneSky; //!< the CPU cones' sky the read-back writes
    //! The occlusion family's GPU cone visibilities (pipeline/compose.h), when a family gives them.
    std::optional<pipeline::Resource<std::array<const gpu::Image*, 4>>> coneVisibility;
    std::optional<pipeline::Resource<std::vector<scene::PosedCapsule>>> capsules;
};

struct ResidentGatherSettings {
    int width = 0;
    int height = 0;
    plugin::VoxelGiTechnique* technique = nullptr;
    std::string techniqueName;
    gpu::Context* gpu = nullptr;
    bool coneSky = false; //!< the lit frame takes its sky through the cones
    //! The row's `voxel_gather.resident` ("yes"), kept by the family.
    const std::string* resident = nullptr;
    //! Where the current frame's row is (the family's pointer, set every frame).
    experiment::ResultRow* const* row = nullptr;
};

//! Adds the passes above to `graph`.
void addResidentGather(pipeline::FrameGraph& graph, pipeline::FrameStart& start,
                       const ResidentGatherResources& resources, const ResidentGatherSettings& settings);

} // namespace rtlab::voxelgi
