#pragma once
// The voxel_gi family's error split for the sky through the cones (metric split, in a lit frame
// whose sky comes through the technique's cones): the technique's voxels along rays, each seeing
// the sky in its own direction (VoxelGiTechnique::traceVoxelSkyRays), against the truth's direct
// irradiance without the point lights (split.sky_voxel_*: the voxel representation), and the
// cones' sky as the frame takes it, visibilities and capsules included, against those rays
// (split.sky_cone_*: the cones and their composition) and against the truth (sky.*).
//
//   reference_cone_sky   Embree "direct" irradiance of the scene without its point lights
//   voxel_sky_rays       traceVoxelSkyRays (skipped with its reason when the technique has none)
//   metric.sky_split     the three errors over the surface pixels

#include "core/image.h"
#include "experiment/results.h"
#include "families/voxel_gi/voxel_gi.h"
#include "pipeline/frame_graph.h"
#include "pipeline/frame_start.h"
#include "reference/reference.h"

#include <glm/vec3.hpp>

#include <string>

namespace rtlab::voxelgi {

struct ConeSkySplitResources {
    pipeline::Resource<scene::RenderScene> geometry;
    pipeline::Resource<scene::GBuffer> gbuffer;
    pipeline::Resource<pipeline::ViewInputs> view;
    pipeline::Resource<int> voxelLight; //!< the technique's light buffers are up to date
    pipeline::Resource<Image<glm::vec3>> coneSky; //!< the frame's cone-sky slot
};

struct ConeSkySplitSettings {
    int width = 0;
    int height = 0;
    plugin::VoxelGiTechnique* technique = nullptr;
    std::string techniqueName;
    reference::ReferenceSettings reference; //!< sampling of the family's truth (quantity replaced)
    int raysPerPixel = 256;
    //! Where the current frame's row is (the family's pointer, set every frame).
    experiment::ResultRow* const* row = nullptr;
};

//! Adds the three passes above to `graph`; their output is "metric.sky_split".
void addConeSkySplit(pipeline::FrameGraph& graph, const ConeSkySplitResources& resources,
                     const ConeSkySplitSettings& settings);

} // namespace rtlab::voxelgi
