// bentcone_ssdo: screen-space directional occlusion into 2-band spherical harmonics, converted to
// a bent cone and intersected with the 16 cone-tracing directions.
//
// Registry key: occlusion/bentcone_ssdo
//
// Talk: J. McLaren, "The Technology of The Tomorrow Children", GDC 2015 (seed
// shared/seeds/000_3da000e866ebc485.txt, "Screen Space Directional Occlusion": "We do something
// similar to Screen-Space Bent cones from GPU Pro 3 / And integrate 2 band SH rather than a
// single scalar occlusion value. / This can be easily converted into a visibility cone at each
// pixel, that we can then intersect with the cones from our 16 trace directions").
// Papers: O. Klehm, T. Ritschel, E. Eisemann, H.-P. Seidel, "Bent Normals and Cones in
// Screen-space", VMV 2011, and "Screen-Space Bent Cones: A Practical Approach", GPU Pro 3, 2012
// (bent normal = average unoccluded direction, a by-product of SSAO's hemisphere samples).
// Cone intersection: O. Mazonka, "Solid Angle of Conical Surfaces, Polyhedral Cones, and
// Intersecting Spherical Caps", arXiv:1205.1396, 2012 (exact, Gauss-Bonnet); A. Van Oosterom,
// J. Strackee, "The Solid Angle of a Plane Triangle", IEEE TBME 30(2), 1983 (the excess);
// C. Oat, P. Sander, "Ambient Aperture Lighting", I3D 2007 (smoothstep approximation).
// Interleaved sampling: A. Keller, W. Heidrich, "Interleaved Sampling", EGWR 2001. Tangent frame:
// T. Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 6(1), 2017.
//
// Quantity: CosineAo with `radius` (reference.h "ao" and "bent"): A = (1/pi) Int_H V_r cos, the
// bent normal = normalised cosine-weighted mean unoccluded direction, aperture sin^2 = A. The
// bent cone is what the talk feeds its cone tracer, and its visible fraction is cosine-weighted
// because its samples are. V_r is estimated by point samples inside the hemisphere (a sample at
// distance u r tests whether it lies behind the depth buffer), so occluders beyond a sample's
// own distance are missed: the estimate is biased toward "unoccluded" against ray-traced V_r
// (README.md gives the closed form for a wall).
//
// Algorithm, per pixel with a surface:
// 1. N samples in the normal-oriented hemisphere of radius r [Klehm et al. 2011]: a fixed
//    pattern, directions cosine-distributed (Malley) in antipodal pairs (so that an open
//    plane's bent normal is exactly its normal), elevations stratified, azimuths by base-2
//    radical inverse, distances r * u with P(u <= s) = s^3 (a uniform ball's radial law),
//    stratified in N strata permuted by the base-3 radical inverse. The pattern turns about the
//    normal by the pixel's rank in a 4x4 Bayer matrix (16 rotations, interleaved sampling
//    [Keller & Heidrich 2001]) plus frameIndex * 0.618 turns.
// 2. Each sample point is projected to the screen and the depth z_b of the pixel it lands in is
//    read (nearest). Occluded iff bias * z_s < z_s - z_b < r, i.e. the buffer surface is in front
//    of the sample by more than the bias and by less than the radius (the usual range check: a
//    foreground object far in front does not occlude), and the buffer point lies above the
//    tangent plane of the pixel by more than bias * depth (a point of the pixel's own plane,
//    reached through a neighbouring pixel centre at a grazing angle, never occludes). Samples
//    off screen, behind the camera, or over sky are unoccluded.
// 3. The unoccluded directions are projected onto 2-band real SH (Y00 = 0.282095,
//    Y1m = 0.488603 (y, z, x)) of the cosine-weighted visibility V(w) max(cos, 0): with
//    cosine-distributed samples each contributes pi/N * Y(w) [talk: "integrate 2 band SH"].
// 4. Cone [talk: "easy to convert this into a visibility cone"]: A = L00 / (pi Y00) = visible/N,
//    axis = normalize(L11, L1-1, L10) (the normal when nothing is visible), aperture
//    asin(sqrt(A)) (from a table of the N + 1 possible counts, shared by both paths).
// 5. The 16 fixed directions (scene/sky.h) in view space, each with a cone of 4pi/16 sr
//    (cos = 7/8): visibility = min(|C n B|, |C n H|) / |C|, B the bent cone, H the surface
//    hemisphere, |.| solid angles from the exact cap intersection [Mazonka 2012, Sec. 4] or the
//    smoothstep fit [Oat & Sander 2007]. Cones wholly below the surface get 0.
// Pixels without a surface (depth inf, NaN or <= 0, or a zero normal): ambient 1, bent normal 0,
// aperture 0, cone visibilities 1.
//
// Parameters
// | name              | type  | default | range / choices      | unit        |
// |-------------------|-------|---------|----------------------|-------------|
// | radius            | float | 0.5     | [0, 1e9]             | world units |
// | samples           | int   | 16      | [1, 256]             | samples     |
// | depth_bias        | float | 0.002   | [0, 0.1]             | of depth    |
// | cone_intersection | enum  | exact   | {exact, smoothstep}  |             |
// radius: hemisphere radius and range-check distance. samples: sample points per pixel.
// depth_bias: a sample counts as occluded only when the buffer is in front of it by more than
// depth_bias times its linear depth, and the buffer point is above the pixel's tangent plane by
// more than depth_bias times the pixel's depth (against self-occlusion).
// cone_intersection: solid angle of cone-cone intersections, exact or the smoothstep fit.
//
// Config:
//   techniques:
//     occlusion: {technique: bentcone_ssdo, params: {radius: 0.5}}

#include "bentcone_ssdo_cpu.h"
#include "bentcone_ssdo_gpu.h"

#include "families/occlusion/occlusion.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rtlab::bentcone_ssdo {
namespace {

constexpr double kDefaultRadius = 0.5;
constexpr int kDefaultSamples = 16;
constexpr double kDefaultDepthBias = 0.002;
constexpr double kMaxDepthBias = 0.1;

ConeIntersection parseConeIntersection(const std::string& name)
{
    if (name == "exact")
        return ConeIntersection::Exact;
    if (name == "smoothstep")
        return ConeIntersection::Smoothstep;
    throw std::invalid_argument("bentcone_ssdo: unknown cone_intersection '" + name + "'");
}

const char* getConeIntersectionName(ConeIntersection mode)
{
    return mode == ConeIntersection::Smoothstep ? "smoothstep" : "exact";
}

class BentConeSsdo final : public plugin::OcclusionTechnique {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "screen-space directional occlusion into 2-band SH, bent cone, "
                           "visibility of the 16 cone-tracing directions",
                .reference = "Klehm et al., Bent Normals and Cones in Screen-space, VMV 2011; "
                             "Screen-Space Bent Cones: A Practical Approach, GPU Pro 3, 2012",
                .seed = "000_3da000e866ebc485.txt"};
    }

    static config::ParamSchema declareParams()
    {
        config::ParamSchema schema;
        schema.addFloat("radius", kDefaultRadius, 0.0, kMaxRadius, "world units",
                        "hemisphere radius of the samples; occluders farther in depth are ignored");
        schema.addInt("samples", kDefaultSamples, kMinSamples, kMaxSamples, "samples",
                      "sample points per pixel");
        schema.addFloat("depth_bias", kDefaultDepthBias, 0.0, kMaxDepthBias, "of depth",
                        "minimum depth difference for occlusion, as a fraction of the "
                        "sample's linear depth");
        schema.addEnum("cone_intersection", "exact", {"exact", "smoothstep"},
                       "solid angle of cone-cone intersections: exact spherical caps or the "
                       "smoothstep approximation");
        return schema;
    }

    explicit BentConeSsdo(const config::ParamSet& params)
        : mRadius(std::clamp(params.getFloat("radius"), 0.0, kMaxRadius)),
          mDepthBias(std::clamp(params.getFloat("depth_bias"), 0.0, kMaxDepthBias))
    {
        mSettings.radius = float(mRadius);
        mSettings.sampleCount =
            int(std::clamp<std::int64_t>(params.getInt("samples"), kMinSamples, kMaxSamples));
        mSettings.depthBias = float(mDepthBias);
        mSettings.coneIntersection = parseConeIntersection(params.getString("cone_intersection"));
        mPattern = makeSamplePattern(mSettings.sampleCount);
        mApertureTable = makeApertureTable(mSettings.sampleCount);
    }

    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p;
        p.set("radius", mRadius);
        p.set("samples", std::int64_t(mSettings.sampleCount));
        p.set("depth_bias", mDepthBias);
        p.set("cone_intersection",
              std::string(getConeIntersectionName(mSettings.coneIntersection)));
        return p;
    }

    plugin::OcclusionDefinition definition() const override
    {
        return {plugin::OcclusionQuantity::CosineAo, mRadius};
    }

    bool acceptsGpuInputs() const override { return true; }
    bool outputsOnGpu() const override { return true; }
    void readBack(plugin::OcclusionOutput& out) override { mGpu.readBack(out); }

    void compute(const plugin::OcclusionInput& input, plugin::OcclusionOutput& out) override
    {
        if (input.gpu != nullptr && input.gpuLinearDepth != nullptr && input.gpuNormal != nullptr) {
            mGpu.compute(*input.gpu, makeFrameSetup(mSettings, mPattern, mApertureTable, input),
                         input, out);
            return;
        }
        if (input.linearDepth == nullptr || input.normal == nullptr)
            throw std::invalid_argument("bentcone_ssdo: the input needs depth and normals");
        if (input.linearDepth->width != input.normal->width ||
            input.linearDepth->height != input.normal->height)
            throw std::invalid_argument("bentcone_ssdo: depth and normal sizes differ");
        const int w = input.linearDepth->width, h = input.linearDepth->height;
        if (w <= 0 || h <= 0) {
            out.ambient = Image<float>(w, h);
            out.bentNormal = Image<glm::vec3>(w, h);
            out.coneAperture = Image<float>(w, h);
            out.coneVisibility.assign(std::size_t(kConeCount), Image<float>(w, h));
            return;
        }
        const FrameSetup frame = makeFrameSetup(mSettings, mPattern, mApertureTable, input);
        if (input.gpu != nullptr)
            mGpu.compute(*input.gpu, frame, input, out);
        else
            computeOnCpu(frame, input, out);
    }

private:
    double mRadius;    //!< world units, as declared (the shader gets it as float)
    double mDepthBias; //!< fraction of depth
    Settings mSettings;
    std::vector<glm::vec4> mPattern;
    std::vector<glm::vec4> mApertureTable;
    GpuPath mGpu;
};

} // namespace
} // namespace rtlab::bentcone_ssdo

RTLAB_REGISTER_TECHNIQUE(occlusion, bentcone_ssdo, rtlab::bentcone_ssdo::BentConeSsdo)
