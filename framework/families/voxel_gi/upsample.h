#pragma once
// Reduced-resolution gathering for voxel_gi techniques: trace at one pixel per factor x factor
// block and upsample with depth- and normal-aware weights. The Tomorrow Children traced its pixel
// cones at a quarter of each dimension (1/16 of the pixels) and upsampled "in a geometrically
// aware way" (shared/seeds/000_3da000e866ebc485.txt, "Trace at a lower resolution"); the weights
// here are joint bilateral upsampling (Kopf et al., "Joint Bilateral Upsampling", SIGGRAPH 2007):
// bilinear weights of the four nearest low-resolution samples times a depth term and a normal
// term, so that light does not bleed across depth discontinuities or creases.

#include "core/image.h"
#include "scene/gbuffer.h"
#include "scene/scene.h"

#include <glm/vec3.hpp>

#include <functional>
#include <vector>

namespace rtlab::voxelgi {

//! The low-resolution view of a G-buffer: one representative pixel per block (the block's centre
//! pixel when it has a surface, else its first surface pixel in row order, else none).
struct ReducedGBuffer {
    int factor = 1;
    scene::GBuffer gbuffer;          //!< ceil(w / factor) x ceil(h / factor)
    std::vector<int> representative; //!< per low-res pixel: full-res pixel index, -1 = none
};

//! `factor` in [1, 16]; factor 1 copies the G-buffer.
ReducedGBuffer reduceGBuffer(const scene::GBuffer& full, int factor);

//! Per-cone images (16) restricted to the representative pixels, or empty when `full` is null.
std::vector<Image<float>> reduceConeImages(const std::vector<Image<float>>* full,
                                           const ReducedGBuffer& reduced);

//! Upsamples `low` (irradiance at the representative pixels) to the full G-buffer. A pixel whose
//! four neighbours all fail the depth and normal tests takes the most similar of its 3 x 3
//! low-resolution neighbours; pixels without a surface get 0.
Image<glm::vec3> upsampleIrradiance(const Image<glm::vec3>& low, const ReducedGBuffer& reduced,
                                    const scene::GBuffer& full);

//! Where the characters' capsules are tested against the 16 cones: at every pixel of the combine
//! (`Full`), or at the traced pixels only (`Traced`: one per traceStep^2 block, the capsules'
//! share of each cone multiplied into the cone's radiance there, then upsampled with it, as the
//! occlusion is part of what the cones see). The talk tests them per pixel into "a 16 layer deep
//! screen space texture array" of unstated resolution (shared/seeds/000_3da000e866ebc485.txt,
//! "Characters"); `Traced` costs 1/traceStep^2 of the tests and blurs the capsules' shadows over
//! a block, where the cones' light is already blurred.
enum class CapsuleResolution { Full, Traced };

//! The final combine of the talk ("Screen Space Directional Occlusion", "Characters"): the
//! radiance each of the 16 cones gathered at the representative pixels (`coneRadiance`,
//! [low-res pixel * 16 + cone]) is upsampled per cone, multiplied per pixel by the occlusion
//! family's 16 visibilities (when given) and by the characters' capsules' occlusion of each
//! cone (when given), and integrated with the pixel's own irradiance weights
//! (cone_tracing.h computeIrradianceWeights), the capsules tested where `capsuleResolution`
//! says. Full resolution in, full resolution out.
struct ConeCombineInputs {
    const std::vector<glm::vec3>* coneRadiance = nullptr;
    const ReducedGBuffer* reduced = nullptr;
    const scene::GBuffer* full = nullptr;
    const std::vector<Image<float>>* visibility = nullptr;      //!< 16 full-res images, or null
    const std::vector<scene::PosedCapsule>* capsules = nullptr; //!< or null
    double coneHalfAngle = 0.5;                                 //!< radians
    CapsuleResolution capsuleResolution = CapsuleResolution::Full;
};
Image<glm::vec3> combineCones(const ConeCombineInputs& in);

//! The capsules at the traced pixels (CapsuleResolution::Traced): every non-zero cone radiance of
//! `traced`'s pixels
//! ([pixel * 16 + cone]) times the share of the cone the capsules leave open.
void occludeTracedCones(const scene::GBuffer& traced, std::vector<glm::vec3>& coneRadiance,
                        const std::vector<scene::PosedCapsule>& capsules, double coneHalfAngle);

//! The sky and emitters the cones of a gather saw ([low-res pixel * 16 + cone], cone_tracing.h
//! computeConeSkyRadiance) and the reduced G-buffer they were traced from, kept until the frame
//! composes them (combineConeSky). Empty `cones` when the gather traced none.
struct ConeSkyTrace {
    std::vector<glm::vec3> cones;
    ReducedGBuffer reduced;
    bool capsulesApplied = false; //!< the capsules were multiplied into `cones` already

    bool isValid() const
    {
        return !cones.empty() &&
               cones.size() == std::size_t(reduced.gbuffer.width) *
                                   std::size_t(reduced.gbuffer.height) * std::size_t(16);
    }
};

//! A cone-traced structure's pixel gather as the family runs it (cascades, svo): the G-buffer
//! reduced to one pixel per traceStep^2 block, `traceCones(reduced, coneRadiance, skyCones)`
//! fills [low-res pixel * 16 + cone] there, and combineCones brings it back to full resolution
//! with the cone visibilities and capsules (either may be null), the capsules tested where
//! `capsuleResolution` says. `combineMs`, when given, receives the wall time of the reduction,
//! the capsules and the combine (the gather's time beyond `traceCones`). With `sky`,
//! `skyCones` points to sky->cones, which traceCones fills with the cones' sky and emitters (or
//! leaves empty), kept with the reduced G-buffer for combineConeSky; without, it is null.
Image<glm::vec3> gatherConesReduced(
    const scene::GBuffer& full, int traceStep, double coneHalfAngle,
    const std::vector<Image<float>>* visibility, const std::vector<scene::PosedCapsule>* capsules,
    const std::function<void(const scene::GBuffer&, std::vector<glm::vec3>&, std::vector<glm::vec3>*)>&
        traceCones,
    double* combineMs = nullptr, CapsuleResolution capsuleResolution = CapsuleResolution::Full,
    ConeSkyTrace* sky = nullptr);

//! Completes `sky` for cones traced at the representative pixels of `full` reduced by
//! `traceStep` outside gatherConesReduced (a gather whose light is combined on Vulkan): the
//! reduced G-buffer, and the capsules multiplied into the cones when `capsuleResolution` says
//! they are tested at the traced pixels.
void keepConeSky(ConeSkyTrace& sky, const scene::GBuffer& full, int traceStep, double coneHalfAngle,
                 const std::vector<scene::PosedCapsule>* capsules, CapsuleResolution capsuleResolution);

//! The irradiance from the sky and emitters of `sky` at every pixel of `full` (the G-buffer
//! the gather was given): the same combine as the gather's light (combineCones: upsampled per
//! cone, times the cone visibilities and the capsules' occlusion, integrated with the pixel's
//! irradiance weights), so the occlusion family's 16 visibilities refine each direction at
//! small scale as the Tomorrow Children's final combine did. Throws rtlab::Error when `sky`
//! is not valid.
Image<glm::vec3> combineConeSky(const ConeSkyTrace& sky, const scene::GBuffer& full, double coneHalfAngle,
                                const std::vector<Image<float>>* visibility,
                                const std::vector<scene::PosedCapsule>* capsules);

//! The error split's rays (voxel_gi.h traceVoxelRays) at the same representative pixels as
//! gatherConesReduced, upsampled the same way: `traceRays(reduced, irradiance)`.
Image<glm::vec3> traceRaysReduced(const scene::GBuffer& full, int traceStep,
                                  const std::function<void(const scene::GBuffer&, Image<glm::vec3>&)>& traceRays);

//! Share of a cone (axis `dir`, half-angle `coneHalfAngle`) from `p` that a capsule hides: the
//! capsule is replaced by the sphere on its segment nearest the cone's axis, and the overlap of
//! the two spherical caps is approximated by the smoothstep of C. Oat, P. Sander, "Ambient
//! Aperture Lighting", I3D 2007 (as the Last of Us did for its capsule occluders, M. Iwanicki,
//! "Lighting Technology of The Last of Us", SIGGRAPH 2013, in one direction; the Tomorrow
//! Children in 16). 0 when p lies on or inside the capsule (its own character's surface).
double computeCapsuleConeOcclusion(const glm::dvec3& p, const glm::dvec3& dir, double coneHalfAngle,
                                   const glm::vec3& a, const glm::vec3& b, float radius);

} // namespace rtlab::voxelgi
