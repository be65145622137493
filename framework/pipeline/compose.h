#pragma once
// The compose passes of the lit frame, on the GPU, after the families' passes:
//
//   shadow_maps     cube shadow maps of the point lights (needs point_lights), re-rendered per
//                   light and cube face: every face of a light that moved, and of every light on
//                   the first frame, when the number of lights or the scene's bounds (they set the
//                   maps' planes) changed, or without culling; otherwise only the faces that see
//                   a triangle that appeared or disappeared since the last frame (walking
//                   characters, remeshed digs: the symmetric difference of the frames' triangle
//                   sets, grouped into boxes). The other faces and lights keep their maps, each
//                   skip recorded with its reason (ComposeStats::shadowSkips); a kept face holds
//                   what re-rendering it would give, so the frame is bitwise that of a run
//                   without culling. Skipped when neither geometry nor lights changed.
//   lighting        point lights with filtered shadows, the sky, emission, and the indirect slot
//                   (render/lighting_pass.h). The sky is `cone_sky` when a voxel GI technique
//                   fills it (the sky and the emitters through its cones, each cone already
//                   times the occlusion family's visibility of its direction; ComposeStats::sky
//                   "cones"), else the 16-lobe SRBF sky attenuated by the frame's directional
//                   occlusion ("lobes"). The occlusion family fills `occlusion.ambient`
//                   and, when its technique gives them, the 16 per-direction cone visibilities
//                   `occlusion.cone_visibility` (used instead, as the Tomorrow Children did:
//                   shared/seeds/000_3da000e866ebc485.txt); `indirect_irradiance` is the voxel GI
//                   family's slot. A slot no family fills is recorded as such.
//   tonemap         exposure and the tonemapper (ACES fit or Reinhard), sRGB
//   frame_readback  HDR, direct and tonemapped frames to the CPU (metrics and files)
//
// Resources a family writes for the frame use the slot names below with these types; a slot
// nobody writes is an unavailable external, so the lighting pass reads it optionally. Each slot
// has a CPU form (for CPU readers: voxel GI's gather reads the cone visibilities) and a GPU form
// (what the lighting pass binds). A family whose technique keeps its result on the GPU writes
// the GPU slot itself (the occlusion family binds the technique's own images: no round trip
// through the CPU); for a slot a family fills on the CPU only, the compose passes add an upload
// pass (`occlusion_upload`, `indirect_upload`) into images the graph keeps across frames, timed
// and culled like any other pass.

#include "core/image.h"
#include "pipeline/frame_graph.h"
#include "pipeline/frame_start.h"

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace rtlab::render {
class LightingPass;
class ShadowPass;
} // namespace rtlab::render
namespace rtlab::gpu {
class Image;
}

namespace rtlab::pipeline {

//! The lit frame on the CPU.
struct LitFrame {
    Image<glm::vec3> hdr;    //!< linear radiance: emission + direct + indirect
    Image<glm::vec3> direct; //!< albedo/pi * (point lights + sky), no emission, no indirect
    Image<glm::vec3> ldr;    //!< tonemapped, sRGB-encoded, [0, 1]
    //! Luminance (Rec. 709) of the sky's part of `direct` (the cones' sky and emitters, or the
    //! lobes'); the rest of `direct` is the point lights'.
    Image<float> directSky;
};

struct ComposeOptions {
    std::string tonemapper = "aces"; //!< "aces" or "reinhard" (render/lighting_pass.h)
    double exposureEv = 0.0;
    int shadowMapSize = 256; //!< texels per cube face
    //! Light the sky (and the emitters) through a voxel GI technique's cones when it gives them
    //! (`cone_sky`); false: always the lobes times the occlusion family's visibility.
    bool coneSky = true;
};

//! What the compose passes did in the last frame (columns of the row).
struct ComposeStats {
    int lights = 0;
    int lightsRendered = 0;      //!< lights with at least one shadow-map face drawn this frame
    int shadowFacesRendered = 0; //!< shadow-map cube faces drawn this frame, 0..6 * lights
    std::string shadowSkips;     //!< the lights and faces whose maps were kept, and why
    std::string visibility;      //!< "none", "ambient_occlusion", "cones"
    std::string indirect;        //!< "none (...)" or the producer's slot
    //! Where the lit frame's sky came from: "cones" (the voxel GI technique's cone sky: the sky
    //! and the emitters through its voxels) or "lobes" (the 16 SRBF lobes times the occlusion
    //! family's visibility, `visibility`).
    std::string sky = "lobes";
};

class Compose {
public:
    static constexpr const char* kAmbientOcclusion = "occlusion.ambient";
    static constexpr const char* kConeVisibility = "occlusion.cone_visibility";
    static constexpr const char* kIndirectIrradiance = "indirect_irradiance";
    static constexpr const char* kLitFrame = "lit_frame";
    static constexpr const char* kAmbientOcclusionGpu = "occlusion.ambient_gpu";
    static constexpr const char* kConeVisibilityGpu = "occlusion.cone_visibility_gpu";
    static constexpr const char* kIndirectIrradianceGpu = "indirect_irradiance_gpu";
    //! The sky and the emitters' light that a voxel GI technique's cones see past its voxels
    //! (render/lighting_pass.h LightingInputs::coneSkyIrradiance); an empty image when the
    //! technique gives none this frame.
    static constexpr const char* kConeSky = "cone_sky";
    static constexpr const char* kConeSkyGpu = "cone_sky_gpu";

    Compose(FrameStart& start, ComposeOptions options);
    ~Compose();

    //! Adds the passes; call after every family has added its own (they fill the slots).
    void addPasses(FrameGraph& graph);
    const ComposeStats& getStats() const { return mStats; }
    const ComposeOptions& getOptions() const { return mOptions; }

    // The slots (typed as the families that fill them must write them) and the CPU frame.
    static Resource<Image<float>> ambientOcclusionSlot(int width, int height)
    {
        return {kAmbientOcclusion, ResourceType::cpuImage("float", width, height)};
    }
    static Resource<std::vector<Image<float>>> coneVisibilitySlot(int width, int height)
    {
        return {kConeVisibility, ResourceType::cpuImage("16 x float", width, height)};
    }
    static Resource<Image<glm::vec3>> indirectIrradianceSlot(int width, int height)
    {
        return {kIndirectIrradiance, ResourceType::cpuImage("vec3", width, height)};
    }
    static Resource<Image<glm::vec3>> coneSkySlot(int width, int height)
    {
        return {kConeSky, ResourceType::cpuImage("vec3", width, height)};
    }
    //! The GPU forms: the image (R32Float) holding the AO, null when the producer gives none.
    static Resource<const gpu::Image*> ambientOcclusionGpuSlot(int width, int height)
    {
        return {kAmbientOcclusionGpu, ResourceType::gpuImage("r32f", width, height)};
    }
    //! Four RGBA32Float images, cone k in channel k % 4 of image k / 4 (render/lighting_pass.h);
    //! all null when the producer gives no cone visibilities.
    static Resource<std::array<const gpu::Image*, 4>> coneVisibilityGpuSlot(int width, int height)
    {
        return {kConeVisibilityGpu,
                ResourceType::gpuImage("4 x rgba32f (cone k: channel k % 4 of image k / 4)", width,
                                       height)};
    }
    //! RGBA32Float, irradiance in rgb.
    static Resource<const gpu::Image*> indirectIrradianceGpuSlot(int width, int height)
    {
        return {kIndirectIrradianceGpu, ResourceType::gpuImage("rgba32f", width, height)};
    }
    //! RGBA32Float, irradiance in rgb; null when the producer gave none this frame.
    static Resource<const gpu::Image*> coneSkyGpuSlot(int width, int height)
    {
        return {kConeSkyGpu, ResourceType::gpuImage("rgba32f", width, height)};
    }
    Resource<LitFrame> litFrame() const
    {
        return {kLitFrame, ResourceType::cpuImage("lit frame: hdr, direct, ldr", mWidth, mHeight)};
    }

private:
    //! The upload passes for slots filled on the CPU only, and unavailable externals for slots
    //! nobody fills.
    void addSlotUploads(FrameGraph& graph);

    FrameStart& mStart;
    ComposeOptions mOptions;
    int mWidth = 0;
    int mHeight = 0;
    std::unique_ptr<render::ShadowPass> mShadows;
    std::unique_ptr<render::LightingPass> mLighting;
    ComposeStats mStats;
    // What the shadow maps were rendered for.
    std::string mShadowGeometryHash;
    std::vector<glm::vec3> mShadowLightPositions;
    std::vector<scene::Capsule> mShadowCapsules; //!< the characters' capsules, posed
    glm::vec3 mShadowBoundsMin{0.0f};
    glm::vec3 mShadowBoundsMax{0.0f};
    int mShadowFrame = -1;
};

} // namespace rtlab::pipeline
