#pragma once
// Family `occlusion`: screen-space ambient occlusion / obscurance from a G-buffer.
// Ground truth: rays from the same G-buffer points against the full scene, computing exactly the
// quantity the technique declares (cosine-weighted AO, or obscurance with its falloff and radius).

#include "core/error.h"
#include "core/image.h"
#include "plugin/technique.h"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <string>
#include <vector>

namespace rtlab::gpu {
class Context;
class Image;
} // namespace rtlab::gpu
namespace rtlab::scene {
struct RenderScene;
struct GBuffer;
} // namespace rtlab::scene

namespace rtlab::plugin {

//! Which integral a technique estimates; the ground truth integrates the same one.
enum class OcclusionQuantity {
    CosineAo,   //!< 1/pi * integral of V(w) cos(theta) over the hemisphere, V=1 if unoccluded in
                //!< radius
    UniformAo,  //!< 1/(2 pi) * integral of V(w) over the hemisphere
    Obscurance, //!< cosine-weighted, occluders at distance d weighted by falloff(d / radius)
};

//! Obscurance falloff rho(x), x = distance / radius: 1 (unoccluded) for x >= 1 and for no hit.
enum class OcclusionFalloff {
    Linear,     //!< rho(x) = x
    Smoothstep, //!< rho(x) = 3x^2 - 2x^3
};

struct OcclusionDefinition {
    OcclusionQuantity quantity = OcclusionQuantity::CosineAo;
    double radius = 1.0; //!< world units; occluders farther than this do not count
    OcclusionFalloff falloff = OcclusionFalloff::Linear; //!< Obscurance only
};

//! A view of the G-buffer. View space: camera at the origin looking down -z, y up, x right; row 0
//! of the images is the top of the screen.
struct OcclusionInput {
    const Image<float>* linearDepth =
        nullptr; //!< view-space distance along -z, world units; inf = sky
    const Image<glm::vec3>* normal =
        nullptr; //!< view-space unit normals facing the camera (zero where no surface)
    glm::mat4 projection{1.0f}; //!< view -> Vulkan clip space (gbuffer.h), jitter included
    glm::mat4 view{
        1.0f}; //!< world -> view (to bring world directions, e.g. the 16 cones, to view space)
    int frameIndex = 0; //!< for techniques that rotate samples over frames
    //! The Vulkan device to run on. Null: run the plain C++ version (parity tests, CPU studies).
    //! GPU work goes through gpu::Context::run with labelled dispatches; the harness reads their
    //! timestamps from the context's run log, so a technique never reports its own time.
    gpu::Context* gpu = nullptr;
    //! The frame's triangles and its world-space G-buffer, for ray-traced baselines
    //! (occlusion/raytraced_ao) only: a screen-space technique must not read them, or it is no
    //! longer screen space. May be null (family suites, synthetic inputs).
    const scene::RenderScene* scene = nullptr;
    const scene::GBuffer* gbuffer = nullptr;
    //! The same view on the GPU, when the frame keeps its G-buffer there (pipeline/frame_start.h):
    //! R32Float linear depth and RGBA32Float view-space normals (w unused), storage images of the
    //! G-buffer's size, made by the frame's `view_inputs_gpu` pass. A technique whose
    //! acceptsGpuInputs() is true binds them instead of uploading linearDepth and normal, which
    //! are then null; the others always get the CPU images.
    const gpu::Image* gpuLinearDepth = nullptr;
    const gpu::Image* gpuNormal = nullptr;
    //! False: a technique whose outputsOnGpu() is true may return from a GPU compute() with only
    //! OcclusionOutput::gpu filled; OcclusionTechnique::readBack() then fills the CPU images.
    //! The frame graph does so when a pass that runs reads them (metrics, images), so a lit
    //! frame without them keeps the result on the GPU.
    bool readBack = true;
};

//! A technique's results still on the GPU after a compute() with OcclusionInput::gpu set: images
//! the technique owns, valid until its next compute(), of the G-buffer's size. The lit frame
//! binds them (pipeline/compose.h) instead of uploading the CPU images again.
struct OcclusionGpuOutput {
    const gpu::Image* ambient = nullptr; //!< R32Float: OcclusionOutput::ambient
    //! RGBA32Float: cone k of OcclusionOutput::coneVisibility in channel k % 4 of image k / 4;
    //! all null when the technique gives no cone visibilities.
    std::array<const gpu::Image*, 4> coneVisibility{};
};

struct OcclusionOutput {
    Image<float> ambient;        //!< AO or obscurance in [0, 1], 1 = unoccluded; 1 where no surface
    Image<glm::vec3> bentNormal; //!< view space, unit length; zero where no surface
    //! Half-angle in radians, [0, pi/2], in the cosine convention of the ground truth:
    //! sin^2(aperture) = cosine-weighted visible fraction (reference.h, "bent").
    Image<float> coneAperture;
    //! Optional: visibility in [0, 1] of each of the 16 fixed cone directions (scene/sky.h,
    //! world space), in that order; empty when the technique does not produce it.
    std::vector<Image<float>> coneVisibility;
    //! Set by a GPU compute() of a technique whose outputsOnGpu() is true; null otherwise.
    OcclusionGpuOutput gpu;
};

class OcclusionTechnique : public Technique {
public:
    static constexpr const char* kFamily = "occlusion";
    //! The quantity and radius this instance estimates (depends on its parameters).
    virtual OcclusionDefinition definition() const = 0;
    virtual void compute(const OcclusionInput& input, OcclusionOutput& out) = 0;
    //! Whether compute() fills bentNormal and coneAperture. The frame graph skips the ray-traced
    //! bent-cone ground truth for techniques that do not (nothing would read it).
    virtual bool outputsBentCone() const { return true; }
    //! Whether compute() with OcclusionInput::gpu set reads gpuLinearDepth and gpuNormal (and
    //! needs no CPU copy of the G-buffer). The frame graph then skips the G-buffer read-back unless
    //! another pass reads it.
    virtual bool acceptsGpuInputs() const { return false; }
    //! Whether compute() with OcclusionInput::gpu set leaves its results on the GPU
    //! (OcclusionOutput::gpu) and, with OcclusionInput::readBack false, reads them back only in
    //! readBack(). The family suite checks that the deferred read-back equals the immediate one.
    virtual bool outputsOnGpu() const { return false; }
    //! Fills the CPU images of `out` from the last GPU compute() (see outputsOnGpu()); keeps
    //! out.gpu. Throws rtlab::Error for a technique that keeps nothing on the GPU or before its
    //! first GPU compute().
    virtual void readBack(OcclusionOutput& /*out*/)
    {
        throw Error("this occlusion technique keeps no result on the GPU to read back");
    }
};

} // namespace rtlab::plugin
