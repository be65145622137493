#pragma once
// Cone tracing shared by every voxel_gi structure (cascades, octree, 64-ary tree): the 16 fixed
// cone directions, the front-to-back march, and light injection into the voxels' light buffers.
// A structure provides a Sampler (below); everything else is the same code for all of them, so
// the structures differ only in how they store and filter the voxels.
//
// The Tomorrow Children (shared/seeds/000_3da000e866ebc485.txt, "Core Lighting Update Logic" to
// "Need to light pixels"): 16 fixed directions, a spherical design, used for the cones from voxels
// and from pixels alike; sky light as 16 SRBF lobes on those directions, gathered by cone tracing;
// emission injected directly; bounce light by tracing the same 16 cones through the direct
// buffer, and again for the second bounce.

#include "scene/render_scene.h"
#include "scene/sky.h"

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

namespace rtlab::voxelgi {

inline constexpr int kConeCount = scene::kConeDirectionCount;

//! The light buffers of a voxel face, as the structures store them (premultiplied by the face's
//! occupancy when sampled).
enum Field : int {
    kEmission = 0, //!< emitted radiance (injected directly)
    kDirect = 1,   //!< reflected direct light: albedo/pi * E_0 (sky, point lights, emission)
    kBounce1 = 2,  //!< reflected first bounce: albedo/pi * E_1
    kBounce2 = 3,  //!< reflected second bounce: albedo/pi * E_2
};
inline constexpr int kFieldCount = 4;

//! The 16 cones: directions (scene/sky.h's design) and a common half-angle.
struct ConeSet {
    std::array<glm::dvec3, kConeCount> directions{};
    double halfAngle = 0.0;    //!< radians
    double tanHalfAngle = 0.0;

    //! `halfAngleDegrees` in (0, 90). 29 degrees makes the 16 cones' solid angles sum to the
    //! sphere's (2 pi (1 - cos a) = 4 pi / 16).
    static ConeSet make(double halfAngleDegrees);
};

//! Weights w_k (sum over k of w_k = pi) that turn the 16 incoming radiances into irradiance
//! about normal n: E = sum_k w_k L_k, w_k proportional to max(0, dot(w_k, n)). Exact for a
//! constant radiance (the furnace) whatever n; zero weights for cones below the surface.
std::array<double, kConeCount> computeIrradianceWeights(const ConeSet& cones, const glm::dvec3& n);

//! Mean sky radiance over each cone's solid angle (quadrature on the cone), what a cone that
//! leaves the structure unoccluded sees.
std::array<glm::vec3, kConeCount> computeSkyPerCone(const scene::Sky& sky, const ConeSet& cones);

//! The optical depth of a voxel of occupancy `alpha` across its own size, -ln(1 - alpha), the
//! occupancy capped at 1 - 1e-4 (an opaque voxel lets 1e-4 through: kOpaqueOpticalDepth).
inline float computeOpticalDepth(float alpha)
{
    return -std::log(1.0f - std::clamp(alpha, 0.0f, 0.9999f));
}
inline const float kOpaqueOpticalDepth = computeOpticalDepth(1.0f);

//! One filtered sample of a structure at a cone's footprint.
struct ConeSample {
    float alpha = 0.0f;                         //!< occupancy seen along the cone's direction
    std::array<glm::vec3, kFieldCount> light{}; //!< premultiplied by alpha
    double voxelSize = 1.0;                     //!< size of the voxels sampled (opacity correction)
    //! The same voxels' optical depths (computeOpticalDepth of each voxel's occupancy seen along
    //! the cone) with the same weights as alpha: what the sky's transmittance is marched with
    //! (marchCone), given when `wantsDepth`. 0 from a sampler that does not give it: its voxels
    //! do not hide the sky.
    float depth = 0.0f;
    //! Set by marchCone before a sample whose optical depth it uses (a logarithm per voxel the
    //! sample reads, which the light's march and the injection do without); kept by clear().
    bool wantsDepth = false;

    //! Back to an empty sample, keeping wantsDepth (what a sampler starts with).
    void clear()
    {
        const bool keep = wantsDepth;
        *this = ConeSample{};
        wantsDepth = keep;
    }
};

struct ConeMarchSettings {
    double tanHalfAngle = 0.55; //!< of the cone
    double startDistance = 0.0; //!< world units along the cone before the first sample
    double stepScale = 0.5;     //!< step = stepScale * size of the voxels sampled
    double maxOpacity = 0.99;   //!< stop when the accumulated occupancy reaches it
    double maxDistance = 1e30;  //!< world units (point-light shadow cones stop at the light)
    int maxSteps = 1024;
    //! March the sky's own transmittance (ConeResult::skyTransmittance) in optical depth, from
    //! skyStartDistance on, and on past the light's end until the sky is hidden too. Off: the
    //! sky's transmittance is the light's.
    bool sky = false;
    //! How the sky's transmittance is marched: in optical depth (true; the leaks marchCone
    //! describes are gone, a footprint partly on a surface weighs more) or, as the light, in
    //! occupancy composited front to back (false, every technique's default: `sky_occlusion`).
    bool skyOpticalDepth = false;
    //! World units along the cone from which its voxels shadow the sky (ConeResult::
    //! skyTransmittance); nearer occluders are left to the occlusion family's visibilities.
    double skyStartDistance = 0.0;
    //! The surface the cone leaves (unit normal, 0 for none) and the origin's height above it:
    //! the part of a sample below that plane is left out of the sky's occupancy (see marchCone).
    glm::dvec3 skyPlaneNormal{0.0};
    double skyPlaneHeight = 0.0;
};

struct ConeResult {
    std::array<glm::vec3, kFieldCount> light{}; //!< radiance of each field seen along the cone
    double transmittance = 1.0;                 //!< 1 - accumulated occupancy
    //! What the voxels at or beyond ConeMarchSettings::skyStartDistance let through to the sky,
    //! exp(-their optical depth) (ConeMarchSettings::sky; else transmittance).
    double skyTransmittance = 1.0;
    bool escaped = false;                       //!< left the structure (sees the sky)
    //! Left the structure, also after the light was done (marching on for the sky only).
    bool skyEscaped = false;
    int steps = 0;
};

//! Marches one cone front to back. Sampler: `bool sample(const glm::dvec3& p, double diameter,
//! int cone, const glm::dvec3& dir, ConeSample& out) const` returns false when p is outside the
//! structure. Opacity is corrected for the step length, a' = 1 - (1 - a)^(step / voxelSize), and
//! the radiance composited with the same a' (Engel et al., Real-Time Volume Graphics; the
//! step-length correction of shared/research/voxelgi.md section 8.1).
//!
//! The sky's transmittance (ConeMarchSettings::sky) may be marched in optical depth instead
//! (ConeMarchSettings::skyOpticalDepth): exp(-sum of ConeSample::depth * step / voxelSize). The occupancy of a trilinear sample is the
//! tent-weighted mean of its voxels', and a march compositing it lets light through an opaque
//! voxel: stepping half voxels past a one-voxel wall whose centre falls between two samples, the
//! samples read it at 0.25, 0.75, 0.75, 0.25 and keep sqrt(0.75 * 0.25 * 0.25 * 0.75) = 19 % of
//! the light; the 6-face blend (weights dir^2) does the same to a slab seen at 45 degrees (half
//! its opaque face, half its thin side). Interpolated optical depth has neither leak: the tent
//! weights of a lattice sum to one voxel per voxel size marched, so the march crosses each
//! voxel's whole optical depth whatever the offset, and an opaque face stays opaque however little
//! of it the blend weighs (Max, "Optical models for direct volume rendering", IEEE TVCG 1995:
//! transmittance is the exponential of the integrated extinction, which is what a linear filter
//! may interpolate). The light keeps the occupancy, as the GPU gathers composite it.
//! Whether a sample at `t` along a cone lies at or past the sky's start distance. The samples
//! lie on sums of half-voxel steps and the usual start is a whole number of voxels, so a sample
//! falls on it: the test takes 1e-4 of it as margin, so that t summed in float (the Vulkan
//! gathers) or in double decides alike (cone_march.glsl).
inline bool isPastSkyStart(double t, double skyStartDistance)
{
    return t >= skyStartDistance * (1.0 - 1e-4);
}

template <class Sampler>
ConeResult marchCone(const Sampler& sampler, const glm::dvec3& origin, const glm::dvec3& dir, int cone,
                     const ConeMarchSettings& s)
{
    ConeResult r;
    double occupied = 0.0;
    double skyDepth = 0.0; // optical depth toward the sky (s.sky)
    // The sky is hidden when its transmittance is as low as the light's limit.
    const double skyHidden = -std::log(std::max(1e-12, 1.0 - s.maxOpacity));
    bool lightDone = false; // the occupancy reached maxOpacity: no more light
    double t = s.startDistance;
    ConeSample sample;
    for (int step = 0; step < s.maxSteps; ++step) {
        if (t >= s.maxDistance)
            break;
        const double diameter = 2.0 * t * s.tanHalfAngle;
        const glm::dvec3 p = origin + t * dir;
        const bool pastSkyStart = isPastSkyStart(t, s.skyStartDistance);
        sample.wantsDepth = s.sky && s.skyOpticalDepth && pastSkyStart;
        if (!sampler.sample(p, diameter, cone, dir, sample)) {
            r.escaped = !lightDone;
            r.skyEscaped = true;
            break;
        }
        ++r.steps;
        // Steps follow the voxels actually sampled: the footprint's level, or a coarser one
        // where the point lies only in coarse levels, or a finer one where the footprint has
        // outgrown the coarsest level (stepping by the footprint there would jump over walls).
        const double dt = s.stepScale * sample.voxelSize;
        const double stepAlpha = std::min(1.0, std::max(0.0, double(sample.alpha)));
        if (stepAlpha > 0.0) {
            // The opacity of a step of dt through voxels of opacity alpha per voxel size:
            // 1 - (1 - alpha)^(dt / size). The exponent is the step scale (0.5 by default, where
            // the power is a square root: correctly rounded, where glibc's pow differs from it by
            // an ulp for 0.09 % of arguments, at a fraction of pow's time).
            const double transparent = 1.0 - std::min(stepAlpha, 0.999999);
            const double exponent = dt / sample.voxelSize;
            const double corrected = 1.0 - (exponent == 0.5   ? std::sqrt(transparent)
                                            : exponent == 1.0 ? transparent
                                                              : std::pow(transparent, exponent));
            if (!lightDone) {
                const double weight = (1.0 - occupied) * corrected / stepAlpha;
                for (int f = 0; f < kFieldCount; ++f)
                    r.light[std::size_t(f)] += float(weight) * sample.light[std::size_t(f)];
                occupied += (1.0 - occupied) * corrected;
                lightDone = occupied >= s.maxOpacity;
            }
            if (s.sky && pastSkyStart) {
                // The sky through the part of the sample the surface the cone leaves does not
                // fill. Voxels of size v hold the box average of the occupancy, and a trilinear
                // sample averages them again: the solid half-space below a plane (the surface,
                // voxelized solid, opaque voxels) read h above it weighs the degree-1 B-spline
                // of width 2v, b = (1 - h/v)^2 / 2 for 0 <= h <= v (1/2 on it, 0 a voxel above),
                // so it adds b times an opaque voxel's optical depth to the sample's. What
                // occludes the sky seen from the surface is the rest. This takes the surface's
                // own occupancy out of the samples just above it; a wide cone at a low angle
                // still reads its surface through coarse voxels (h/v tends to sin(elevation) /
                // (2 tan(half-angle))), the part that skyStartDistance leaves out.
                // In occupancy, the surface's part b of the union: max(0, alpha - b) / (1 - b).
                double depth = s.skyOpticalDepth ? double(sample.depth) : 0.0;
                double skyAlpha = stepAlpha;
                if (s.skyPlaneNormal != glm::dvec3(0.0)) {
                    const double h = s.skyPlaneHeight + t * glm::dot(dir, s.skyPlaneNormal);
                    const double u = std::clamp(h / sample.voxelSize, -1.0, 1.0);
                    const double below = u >= 0.0 ? 0.5 * (1.0 - u) * (1.0 - u)
                                                  : 1.0 - 0.5 * (1.0 + u) * (1.0 + u);
                    depth = std::max(0.0, depth - below * double(kOpaqueOpticalDepth));
                    skyAlpha = below < 1.0 ? std::max(0.0, stepAlpha - below) / (1.0 - below) : 0.0;
                }
                if (!s.skyOpticalDepth)
                    depth = -std::log(1.0 - std::min(skyAlpha, 0.999999));
                skyDepth += depth * exponent;
            }
            // Done when the light is (the occupancy) and so is the sky: occluders nearer than
            // skyStartDistance do not end the cone's view of it.
            if (lightDone && (!s.sky || skyDepth >= skyHidden))
                break;
        }
        t += dt;
    }
    r.transmittance = 1.0 - occupied;
    r.skyTransmittance = s.sky ? std::exp(-skyDepth) : r.transmittance;
    return r;
}

//! What a pixel's cone sees past the structure's voxels besides the reflected light: the sky,
//! where the cone leaves the structure, times the transmittance of the voxels from
//! ConeMarchSettings::skyStartDistance on (nearer ones, the surface the cone starts from among
//! them at coarse levels, are the occlusion family's part), plus the emission of the
//! voxels it meets (the field kEmission of the sampler's result). The Tomorrow Children lit
//! pixels so ("Sky Light": the sky as 16 SRBF lobes on the cone directions, gathered along the
//! same cones as the bounce light through the cascades; emission injected into the light the
//! cones gather), so walls far beyond a screen-space radius shadow the sky.
inline glm::vec3 computeConeSkyRadiance(const ConeResult& r, const glm::vec3& skyOfCone)
{
    glm::vec3 sky = r.light[kEmission];
    if (r.skyEscaped)
        sky += float(r.skyTransmittance) * skyOfCone;
    return glm::max(sky, glm::vec3(0.0f));
}

//! Where traceGBufferCones also writes the cones' sky and emitters (computeConeSkyRadiance):
//! `skyPerCone` the mean sky radiance of each cone (computeSkyPerCone), `out` [pixel * 16 + cone].
struct ConeSkyOutput {
    std::array<glm::vec3, kConeCount> skyPerCone{};
    std::vector<glm::vec3>* out = nullptr;
};

//! The Tomorrow Children's extrapolated extra bounce ("Extra Magic": places that received more
//! second bounce than first are surmised to get more from a third, and boosted): from the
//! reflected radiance of the last two bounces, per channel, next = last * min(last / prev, 1).
//! Where each bounce keeps a fraction g < 1 of the one before (a room of albedo a: g = a) this
//! is the geometric series' next term, exact in the furnace; where the later bounce is the
//! larger (g >= 1, the talk's case) the boost is capped at one more bounce as large as the last.
inline glm::vec3 extrapolateBounce(const glm::vec3& prev, const glm::vec3& last)
{
    glm::vec3 next(0.0f);
    for (int c = 0; c < 3; ++c) {
        if (!(last[c] > 0.0f))
            continue;
        const float gain = prev[c] > 0.0f ? std::min(last[c] / prev[c], 1.0f) : 1.0f;
        next[c] = last[c] * gain;
    }
    return next;
}

//! Changes exactly when the point lights or the sky change (what light injection depends on
//! besides the voxels).
std::string computeLightsKey(const scene::RenderScene& scene);

//! The light of the frame that voxels receive directly.
struct InjectionLights {
    const std::vector<scene::PointLight>* pointLights = nullptr;
    std::array<glm::vec3, kConeCount> skyPerCone{}; //!< computeSkyPerCone
    bool hasSky = false;
};

//! A surface voxel to light: its centre, mean normal (may be 0) and faces (albedo, occupancy).
struct InjectionVoxel {
    glm::dvec3 centre{0.0};
    glm::vec3 normal{0.0f};
    double voxelSize = 1.0;
    const glm::vec4* faces = nullptr; //!< 6 faces
};

//! Irradiance per face from the 16 cones and the point lights, for each reflected field:
//! E[kDirect] from emission, sky and point lights (E_0), E[kBounce1] from the direct buffer
//! (E_1), E[kBounce2] from the first bounce (E_2). The caller turns them into radiance
//! (albedo / pi * E) for the fields it updates.
struct FaceIrradiance {
    std::array<std::array<glm::vec3, 6>, kFieldCount> e{};
};

struct InjectionSettings {
    ConeMarchSettings march;     //!< startDistance is set per voxel from startOffset
    double startOffset = 1.0;    //!< voxels: cone start distance and origin offset along the normal
    double pointLightTan = 0.05; //!< half-angle tangent of the shadow cones toward point lights
};

//! The face normal the irradiance of face f is integrated about: the voxel's surface normal when
//! the surface faces that side, else the face's axis.
glm::dvec3 getShadingNormal(const InjectionVoxel& voxel, int face);

template <class Sampler>
FaceIrradiance gatherVoxelIrradiance(const Sampler& sampler, const InjectionVoxel& voxel,
                                     const ConeSet& cones, const InjectionLights& lights,
                                     const InjectionSettings& settings)
{
    FaceIrradiance out;
    const glm::dvec3 n(voxel.normal);
    const glm::dvec3 origin = voxel.centre + n * (0.5 * settings.startOffset * voxel.voxelSize);
    ConeMarchSettings march = settings.march;
    march.tanHalfAngle = cones.tanHalfAngle;
    march.startDistance = settings.startOffset * voxel.voxelSize;
    // Incoming radiance per cone and field (the sky where the cone escapes).
    std::array<std::array<glm::vec3, kFieldCount>, kConeCount> incoming{};
    for (int k = 0; k < kConeCount; ++k) {
        const ConeResult c = marchCone(sampler, origin, cones.directions[std::size_t(k)], k, march);
        incoming[std::size_t(k)] = c.light;
        if (c.escaped && lights.hasSky)
            incoming[std::size_t(k)][kEmission] +=
                float(c.transmittance) * lights.skyPerCone[std::size_t(k)];
    }
    for (int face = 0; face < 6; ++face) {
        const glm::dvec3 shading = getShadingNormal(voxel, face);
        const auto w = computeIrradianceWeights(cones, shading);
        glm::dvec3 e0(0.0), e1(0.0), e2(0.0);
        for (int k = 0; k < kConeCount; ++k) {
            const double wk = w[std::size_t(k)];
            if (wk == 0.0)
                continue;
            e0 += wk * glm::dvec3(incoming[std::size_t(k)][kEmission]);
            e1 += wk * glm::dvec3(incoming[std::size_t(k)][kDirect]);
            e2 += wk * glm::dvec3(incoming[std::size_t(k)][kBounce1]);
        }
        out.e[kDirect][std::size_t(face)] = glm::vec3(e0);
        out.e[kBounce1][std::size_t(face)] = glm::vec3(e1);
        out.e[kBounce2][std::size_t(face)] = glm::vec3(e2);
    }
    // Point lights: inverse-square irradiance, shadowed by a thin cone toward the light.
    if (lights.pointLights != nullptr)
        for (const scene::PointLight& light : *lights.pointLights) {
            const glm::dvec3 toLight = glm::dvec3(light.position) - origin;
            const double d2 = glm::dot(toLight, toLight);
            if (!(d2 > 0.0))
                continue;
            const double d = std::sqrt(d2);
            const glm::dvec3 l = toLight / d;
            ConeMarchSettings shadow = march;
            shadow.tanHalfAngle = settings.pointLightTan;
            shadow.maxDistance = d;
            const double visible = marchCone(sampler, origin, l, -1, shadow).transmittance;
            if (visible <= 0.0)
                continue;
            for (int face = 0; face < 6; ++face) {
                const double c = glm::dot(getShadingNormal(voxel, face), l);
                if (c > 0.0)
                    out.e[kDirect][std::size_t(face)] +=
                        glm::vec3(glm::dvec3(light.intensity) * (c * visible / d2));
            }
        }
    return out;
}

} // namespace rtlab::voxelgi
