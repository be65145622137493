#pragma once
// The shared start of a screen-space frame, as reusable passes of the frame graph. Every screen
// family of a run (occlusion, voxel GI, ...) reads the resources these passes write, so a run
// with several families rasterises its G-buffer once:
//
//   sdf_remesh         the scene's SDF models as triangles (needs sdf_models; reused while no
//                      edit starts: the Dreams-style edit list,
//                      shared/seeds/001_5c6096db92814698.txt); a dig re-meshes only the cells
//                      it touched (scene::SdfMesher; in full with culling off, the ablation)
//   character_pose     the characters' capsules at this frame (needs characters)
//   assemble_geometry  the frame's triangles, lights and sky (scene::RenderScene)
//   scene_upload       to the GPU (reused while the geometry is unchanged)
//   gbuffer            rasterised on Vulkan into GPU attachments the graph creates and keeps
//                      (gbuffer_target; timed with the run's repeats; not redrawn while camera,
//                      geometry, size and jitter are unchanged)
//   gbuffer_readback   the attachments copied to the CPU, only when a pass that runs reads them
//   view_inputs        view-space normals and the surface mask (CPU), for CPU-side readers
//   view_inputs_gpu    linear depth and view-space normals on the GPU, for Vulkan techniques,
//                      and the world position + depth and normal attachments as storage images
//                      (the G-buffer stays on the GPU: no read-back unless a CPU reader runs)
//
// The passes are added once per run; FrameStart keeps what they reuse between frames.

#include "core/image.h"
#include "pipeline/frame_graph.h"
#include "scene/gbuffer.h"
#include "scene/render_scene.h"
#include "scene/scene.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace rtlab::gpu {
class Context;
class Image;
class RenderTarget;
} // namespace rtlab::gpu
namespace rtlab::render {
class GBufferPass;
class ViewInputsPass;
} // namespace rtlab::render

namespace rtlab::pipeline {

//! The G-buffer's GPU attachments of the current frame (render/gbuffer_pass.h: 0 world position
//! + linear depth, 1 normal, 2 albedo, 3 emission RGBA32F, 4 material id R32Uint, D32 depth).
struct GpuGBuffer {
    const gpu::RenderTarget* target = nullptr;
    int width = 0;
    int height = 0;
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
    scene::Camera camera;
};

//! View-space inputs that CPU readers need besides the G-buffer.
struct ViewInputs {
    Image<glm::vec3> normal;     //!< view-space unit normals, zero where no surface
    Image<std::uint8_t> surface; //!< 1 where a surface was rasterised
};

//! The matrices of the view inputs on the GPU (their images: FrameStart::viewDepthGpu(),
//! viewNormalGpu()).
struct GpuViewInputs {
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
};

//! Marks that the frame's geometry is on the GPU (content hash of what was uploaded).
struct GpuScene {
    std::string hash;
    int frame = -1;
};

//! Options of the frame start.
struct FrameStartOptions {
    int width = 320;
    int height = 180;
};

//! What the frame start's passes did in the last frame they ran (columns of the row).
struct FrameStartStats {
    int remeshFrame = -1;        //!< the frame sdf_remesh last ran in
    std::string remesh;          //!< per SDF model, what SdfMesher::update did
    std::int64_t cellsMeshed = 0; //!< cells whose vertex was computed, all models
    std::int64_t cells = 0;       //!< cells of the models' grids
};

class FrameStart {
public:
    //! Names of the resources the frame start writes.
    static constexpr const char* kScene = "scene";
    static constexpr const char* kGeometry = "geometry";
    static constexpr const char* kGeometryKey = "geometry_key";
    static constexpr const char* kGBuffer = "gbuffer";
    static constexpr const char* kGBufferCpu = "gbuffer_cpu";
    static constexpr const char* kViewInputs = "view_inputs";
    static constexpr const char* kViewInputsGpu = "view_inputs_gpu";

    //! `scene` must outlive the FrameStart and the graph; the Vulkan device is opened through
    //! `gpu` when the first pass needs it.
    FrameStart(const scene::Scene& scene, gpu::Context& gpu, FrameStartOptions options);
    ~FrameStart();

    //! Adds the passes (see above) to `graph`.
    void addPasses(FrameGraph& graph);

    const scene::Scene& getScene() const { return mScene; }
    const scene::FeatureSet& getFeatures() const { return mFeatures; }
    gpu::Context& getGpu() const { return mGpu; }
    const FrameStartOptions& getOptions() const { return mOptions; }
    const FrameStartStats& getStats() const { return mStats; }
    //! The box holding every SDF triangle that a re-mesh after frame `since` removed or added
    //! (lo > hi when none did). False when that is not known: `since` is before the first
    //! meshing, or a re-mesh since then was a full one. What a pass that keeps its own copy of
    //! the geometry uses instead of comparing triangles.
    bool findSdfChangeSince(int since, glm::dvec3& lo, glm::dvec3& hi) const;

    // Typed handles of the resources, for the families' passes.
    Resource<scene::Scene> scene() const { return {kScene, ResourceType::value("scene")}; }
    //! The characters' capsules at this frame (written only for scenes with characters).
    Resource<std::vector<scene::PosedCapsule>> capsules() const
    {
        return {"capsules", ResourceType::table("posed capsules")};
    }
    //! The SDF models as meshes (written only for scenes with SDF models).
    Resource<std::vector<scene::SdfMesh>> sdfMeshes() const
    {
        return {"sdf_meshes", ResourceType::mesh("sdf meshes")};
    }
    Resource<scene::RenderScene> geometry() const
    {
        return {kGeometry, ResourceType::mesh("render scene")};
    }
    //! The geometry's RenderScene::computeContentHash, computed once per frame by the pass that
    //! assembles it: the passes that skip work on unchanged geometry compare this key instead of
    //! hashing the whole scene again (a few MB, hashed byte by byte).
    Resource<std::string> geometryKey() const
    {
        return {kGeometryKey, ResourceType::value("geometry content hash")};
    }
    Resource<GpuGBuffer> gbuffer() const
    {
        return {kGBuffer, ResourceType::gpuImage("gbuffer: 4 x rgba32f + r32ui", mOptions.width,
                                                 mOptions.height)};
    }
    //! The attachments themselves (render/gbuffer_pass.h), created by the graph when the
    //! `gbuffer` pass first draws and kept across frames; `gbuffer` points into them.
    Resource<gpu::RenderTarget> gbufferTarget() const;
    Resource<scene::GBuffer> gbufferCpu() const
    {
        return {kGBufferCpu, ResourceType::cpuImage("gbuffer", mOptions.width, mOptions.height)};
    }
    Resource<ViewInputs> viewInputs() const
    {
        return {kViewInputs, ResourceType::cpuImage("view normal + surface mask", mOptions.width,
                                                    mOptions.height)};
    }

    Resource<GpuViewInputs> viewInputsGpu() const
    {
        return {kViewInputsGpu, ResourceType::value("view and projection of the GPU view inputs")};
    }
    //! Linear depth (R32Float) and view-space normals (RGBA32Float) on the GPU, created by the
    //! graph (pipeline/gpu_resources.h): Vulkan techniques bind them.
    Resource<gpu::Image> viewDepthGpu() const;
    Resource<gpu::Image> viewNormalGpu() const;
    //! The G-buffer's world-space attachments as storage images (RGBA32Float; written by
    //! view_inputs_gpu): position with the linear depth in w (inf where there is no surface),
    //! and the shading normal. Vulkan techniques that work in world space bind them (voxel GI's
    //! resident gather: families/voxel_gi/voxel_gi.h VoxelGiGpuGBuffer).
    Resource<gpu::Image> positionDepthGpu() const;
    Resource<gpu::Image> worldNormalGpu() const;

private:
    const scene::Scene& mScene;
    scene::FeatureSet mFeatures;
    gpu::Context& mGpu;
    FrameStartOptions mOptions;
    std::unique_ptr<render::GBufferPass> mGBufferPass;
    std::unique_ptr<render::ViewInputsPass> mViewInputsPass;
    // What is reused between frames.
    std::vector<scene::SdfMesher> mMeshers; //!< one per SDF model, each keeps its grid
    struct SdfChange {
        int frame = 0;
        bool bounded = false; //!< false: meshed in full
        glm::dvec3 lo{1e300}, hi{-1e300};
    };
    std::vector<SdfChange> mSdfChanges; //!< one per re-mesh that changed a mesh, oldest first
    FrameStartStats mStats;
    std::uint64_t mMeshedEditKey = 0;
    int mMeshedFrame = -1;
    std::string mUploadedHash;
    int mUploadedFrame = -1;
    // assemble_geometry's static part (no characters), its content hash, and the count of
    // sdf_remesh runs it was made after (mSdfMeshVersion: incremented by each).
    scene::RenderScene mStaticGeometry;
    std::string mStaticKey;
    std::uint64_t mStaticVersion = 0, mSdfMeshVersion = 0;
    std::string mDrawnKey;
    int mDrawnFrame = -1;
    std::string mReadKey;
    int mReadFrame = -1;
};

} // namespace rtlab::pipeline
