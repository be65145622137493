#pragma once
// Family `voxel_gi`: a voxel scene structure (cascades, sparse octree, 64-ary adaptive tree)
// built from the voxelized scene, lit by cone tracing in 16 fixed directions, then cone traced
// from G-buffer pixels to give their indirect diffuse irradiance.
// Ground truth: the path tracer's indirect-only irradiance (reference.h "indirect") with the
// same lights and the bounce count the technique declares.
//
// A frame calls, each as a pass of the frame graph (families/voxel_gi/voxel_gi_family.cpp):
//   voxelize(frame)      re-voxelize what changed (nothing, a level, a dug region, a scrolled slab)
//   injectLight(frame)   update the voxel light buffers (direct, bounces) where they are stale
//   gather(input, out)   indirect irradiance at every G-buffer pixel
// Each step says whether it did anything and, when not, why (recorded as a skipped pass).
//
// The shared machinery lives beside this header: voxelize.h (triangles -> volumetric G-buffer)
// and cone_tracing.h (the 16 cones, the march, light injection).

#include "core/error.h"
#include "core/image.h"
#include "plugin/technique.h"
#include "scene/gbuffer.h"
#include "scene/render_scene.h"
#include "scene/scene.h"

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace rtlab::gpu {
class Context;
class Image;
} // namespace rtlab::gpu

namespace rtlab::plugin {

//! What a voxel_gi technique computes, so that the ground truth computes exactly that.
struct VoxelGiDefinition {
    int bounces = 2; //!< reflections before the light reaches the pixel (reference "indirect")
    //! The light step is a precompute (a bake, as Quantum Break's probes): its time is reported
    //! apart (column bake_ms) and left out of the frame's technique_ms.
    bool precomputedLight = false;
    //! The structure stores surfaces (with at most a thin layer inside), not the solid interior of
    //! closed objects: a cone sample coarser than a wall sees through its unstored inside, so a
    //! closed room loses light through thick walls. The family suite's furnace then bounds the
    //! loss instead of requiring the closed form.
    bool surfacesOnly = false;
};

//! The frame as the structure sees it: the static scene (no characters: the talk does not
//! voxelize them, their occlusion comes from capsules), the camera, the frame index.
struct VoxelGiFrame {
    const scene::RenderScene* geometry = nullptr; //!< triangles, lights, sky
    std::string geometryKey;                      //!< changes exactly when `geometry` changes
    //! When `changeKnown`: `geometry` differs from the geometry of key `changedFromKey` only by
    //! triangles inside [changedMin, changedMax] (lo > hi: by none), the region the digs
    //! re-meshed (pipeline::FrameStart::findSdfChangeSince). A technique that tracks what
    //! changed uses it instead of comparing the triangles.
    bool changeKnown = false;
    std::string changedFromKey;
    glm::dvec3 changedMin{1e300}, changedMax{-1e300};
    glm::dvec3 cameraPosition{0.0};
    int frameIndex = 0;
    bool force = false; //!< do the whole step even where nothing changed (culling off)
    gpu::Context* gpu = nullptr;
    //! The frame will ask for the cones' sky (VoxelGiInput::coneSky): a step that prepares it
    //! (a bake of the sky) does so only then.
    bool coneSky = false;
};

//! What a step did: ran (and what it did, for the row), or skipped with the reason.
struct VoxelGiStep {
    bool ran = true;
    std::string skipReason;
    std::string did; //!< e.g. "level 1: scrolled by (2, 0, 0) voxels, voxelized the new slabs"
    static VoxelGiStep skipped(std::string why) { return {false, std::move(why), {}}; }
    static VoxelGiStep done(std::string what) { return {true, {}, std::move(what)}; }
};

//! The G-buffer as the frame keeps it on the GPU (pipeline/frame_start.h positionDepthGpu,
//! worldNormalGpu): storage images of the G-buffer's size.
struct VoxelGiGpuGBuffer {
    //! RGBA32Float: world position in xyz, linear view depth in w (inf where no surface).
    const gpu::Image* positionDepth = nullptr;
    const gpu::Image* normal = nullptr; //!< RGBA32Float: world unit shading normal in xyz
    int width = 0;
    int height = 0;
    glm::dvec3 cameraPosition{0.0};
};

struct VoxelGiInput {
    //! World positions and normals of the pixels; null when the G-buffer is given on the GPU
    //! only (gpuGBuffer).
    const scene::GBuffer* gbuffer = nullptr;
    //! The frame's full triangle scene (characters included): ray-traced baselines only.
    const scene::RenderScene* scene = nullptr;
    glm::dvec3 cameraPosition{0.0};
    //! The occlusion family's 16 per-direction visibilities (bentcone_ssdo), or null.
    const std::vector<Image<float>>* coneVisibility = nullptr;
    //! The characters' capsules at this frame (not voxelized: they occlude the cones), or null.
    const std::vector<scene::PosedCapsule>* capsules = nullptr;
    int frameIndex = 0;
    gpu::Context* gpu = nullptr;
    //! The frame will ask for the cones' sky (combineConeSky): the gather traces it too. False
    //! when nothing reads it (no lit frame, or `frame: {sky: lobes}`).
    bool coneSky = false;

    // The resident gather (the frame stays on the GPU). Given to a technique whose
    // whyNotGatheredOnGpu() is "" when the frame keeps its G-buffer on the GPU; `gbuffer` and
    // `coneVisibility` are then null and the technique binds these instead.
    const VoxelGiGpuGBuffer* gpuGBuffer = nullptr;
    //! The occlusion family's 16 visibilities on the GPU (pipeline/compose.h
    //! coneVisibilityGpuSlot: cone k in channel k % 4 of RGBA32Float image k / 4); all null when
    //! the occlusion technique gives none or there is none.
    std::array<const gpu::Image*, 4> gpuConeVisibility{};
    //! With gpuGBuffer: false leaves the irradiance on the GPU only (getGpuIrradiance), and the
    //! image given to gather() untouched; readBackIrradiance() brings it to the CPU when a
    //! measurement reads it. True fills the image too.
    bool readBack = true;
};

//! Sizes the family reports for the data-structure metrics.
struct VoxelGiMemory {
    std::size_t topologyBytes = 0; //!< tree nodes, masks, pointers, level descriptors
    std::size_t payloadBytes = 0;  //!< volumetric G-buffer and light buffers
};

class VoxelGiTechnique : public Technique {
public:
    static constexpr const char* kFamily = "voxel_gi";
    virtual VoxelGiDefinition definition() const = 0;
    virtual VoxelGiStep voxelize(const VoxelGiFrame& frame) = 0;
    virtual VoxelGiStep injectLight(const VoxelGiFrame& frame) = 0;
    //! Indirect diffuse irradiance at every G-buffer pixel (0 where there is no surface).
    virtual void gather(const VoxelGiInput& input, Image<glm::vec3>& irradiance) = 0;
    virtual VoxelGiMemory memory() const = 0;
    //! Whether gather() on `gpu` runs on the device from start to end (the pixel cones and their
    //! combine), so that it can take the G-buffer and the cone visibilities as GPU images
    //! (VoxelGiInput::gpuGBuffer) and leave its irradiance there (getGpuIrradiance): no read-back
    //! and no upload per frame but the capsules. "" when it does, else why not (recorded in the
    //! row as `voxel_gather.resident`).
    virtual std::string whyNotGatheredOnGpu(const gpu::Context& gpu) const
    {
        return "the technique has no resident Vulkan gather";
    }
    //! The irradiance of the last gather() with VoxelGiInput::gpuGBuffer: RGBA32Float (rgb), the
    //! G-buffer's size, owned by the technique and valid until its next gather(); null before.
    virtual const gpu::Image* getGpuIrradiance() const { return nullptr; }
    //! That image on the CPU. Throws rtlab::Error when there is none.
    virtual void readBackIrradiance(Image<glm::vec3>& /*irradiance*/)
    {
        throw Error("this voxel_gi technique keeps no irradiance on the GPU to read back");
    }
    //! The irradiance from the sky and from emissive surfaces that the 16 cones of the last
    //! gather() saw past the technique's voxels (the sky where a cone leaves the structure, times
    //! what the voxels let through; the emitters the cones meet), at every pixel of that gather's
    //! G-buffer, with the same visibilities and capsules (`input`, as given to it). The lit frame
    //! lights the sky and the emitters with it (render/lighting_pass.h), as the Tomorrow Children
    //! did. Returns "" when written, else why there is none (the frame then lights the sky
    //! through the lobes times the occlusion family's visibility, and records that).
    virtual std::string combineConeSky(const VoxelGiInput& input, Image<glm::vec3>& irradiance)
    {
        return "the technique traces no cones toward the sky";
    }
    //! The cones' sky (as combineConeSky) of the last gather() with VoxelGiInput::gpuGBuffer and
    //! VoxelGiInput::coneSky: RGBA32Float (rgb), the G-buffer's size, owned by the technique and
    //! valid until its next gather(); null when that gather traced none.
    virtual const gpu::Image* getGpuConeSky() const { return nullptr; }
    //! That image on the CPU. Throws rtlab::Error when there is none.
    virtual void readBackConeSky(Image<glm::vec3>& /*irradiance*/)
    {
        throw Error("this voxel_gi technique keeps no cone sky on the GPU to read back");
    }
    //! For the split of the error: the technique's own voxels and light buffers gathered along
    //! `raysPerPixel` rays per pixel (zero aperture, no 16-direction quadrature, the finest voxels
    //! available) instead of its cones, at the same points. Technique vs this is the cone error;
    //! this vs the ground truth is the error of the voxel representation (geometry and light
    //! buffers). False when the technique has no such path.
    virtual bool traceVoxelRays(const VoxelGiInput& input, int raysPerPixel,
                                Image<glm::vec3>& irradiance)
    {
        return false;
    }
    //! The same split for the sky through the cones (combineConeSky): the irradiance from the sky
    //! and emitters that the technique's voxels let through along `raysPerPixel` rays per pixel,
    //! each seeing `sky` in its own direction, at the points of combineConeSky, without the
    //! occlusion family's visibilities. False when the technique has no such path.
    virtual bool traceVoxelSkyRays(const VoxelGiInput& input, int raysPerPixel, const scene::Sky& sky,
                                   Image<glm::vec3>& irradiance)
    {
        return false;
    }
    //! For the discontinuity metric: per pixel of input.gbuffer, the level of the structure its
    //! lookup starts at (cascades: the floor of the start level; a tree: the level of the
    //! interpolation), kNoLevel where there is none. Neighbouring pixels with different levels
    //! straddle a level transition. False when the technique has no such level.
    static constexpr std::uint8_t kNoLevel = 255;
    virtual bool computeLookupLevels(const VoxelGiInput& input, Image<std::uint8_t>& levels)
    {
        return false;
    }
};

} // namespace rtlab::plugin
