// gtao: Ground-Truth-based Ambient Occlusion with bent normals, the horizon-based baseline.
//
// Registry key: occlusion/gtao
//
// Paper: J. Jimenez, X. Wu, A. Pesce, A. Jarabo, "Practical Real-Time Strategies for Accurate
// Indirect Occlusion", SIGGRAPH 2016 course Physically Based Shading in Theory and Practice,
// Activision tech report ATVI-TR-16-01. No seed transcript covers it; rtlab uses it as the
// horizon-based baseline that the other occlusion techniques (e.g. the LSAO of
// 002_2c73d3b2bb6f7a13.txt, Quantum Break) are measured against.
//
// Quantity: cosine-weighted ambient occlusion within `radius` (OcclusionQuantity::CosineAo),
// A = (1/pi) Int_H V_r(w) cos(theta) dw, the integral the paper calls ground truth; the
// reference's `ao` with the same radius. With falloff_fraction > 0 the horizon of occluders in the
// last fraction of the radius is blended toward the hemisphere boundary (the paper's falloff),
// which no longer estimates that exact quantity; definition() still names CosineAo.
//
// Algorithm (per pixel with a surface; gtao_cpu.cpp and shaders/gtao.comp compute the same)
// - p: view-space point of the pixel centre (plugin/screen_space.h conversions, jitter included),
//   v = -p / |p| the view vector, n the unit normal.
// - Slices [Alg. 1]: `slices` directions s_i orthogonal to v at angles phi_i = pi (i + r) / slices
//   around v, r = (bayer4x4(x, y) + T(frame)) / 16 with the paper's six temporal rotations
//   T = {60, 300, 180, 240, 120, 0} degrees (as fractions of a turn): a 4x4 tile over 6 frames
//   covers 96 rotations. The angles are uniform around v, the measure of the slice integral (the
//   paper takes uniform screen-space angles, the same thing at the image centre); the slice's
//   screen direction is the projection of s_i at p.
// - Search extent per side, clamped to max_pixel_radius: search_extent = sphere (default) uses the
//   screen interval onto which the radius sphere around p projects along the slice (the tangent
//   rays from the camera in the slice plane), so that every point within the radius is reached;
//   `depth` is the paper's radius projected at p's depth, which misses occluders within the radius
//   that are nearer the camera than p (they project farther out).
// - Horizons [Alg. 1]: `steps` samples per side at 1 + (extent - 1)(j + jitter) / steps px,
//   jitter = (((y - x) mod 4) + S(frame)) / 4 with the paper's temporal step offsets
//   S = {0, 1/2, 1/4, 3/4}. A sample's view position comes from bilinear interpolation of
//   1 / depth, which is affine in screen space on a plane: planes are reconstructed exactly, so a
//   flat receiver never occludes itself, and across a depth edge the samples lie on the segments
//   between texel points (never above the higher one). Samples farther than `radius` from p are
//   ignored (hard cutoff, or a linear fade over the last falloff_fraction of the radius, which
//   pulls the sample's horizon cosine toward the hemisphere boundary). The horizon cosine of a
//   side is the largest cos(angle to v), starting at the normal's hemisphere boundary; the signed
//   angles h1 <= 0 <= h2 are clamped to [gamma - pi/2, gamma + pi/2], gamma the angle of the
//   normal projected into the slice (normals facing away from v count as grazing).
// - Visibility [inner integral]: a(h) = (-cos(2h - gamma) + cos(gamma) + 2h sin(gamma)) / 4 per
//   side, weighted by the projected normal's length |n_p|, summed over slices. normalize = true
//   divides by the same sum for unoccluded arcs, sum |n_p| (cos(gamma) + gamma sin(gamma)): a
//   slice's unoccluded value varies around its mean 1 off the image centre, so the plain mean of
//   few slices misses 1 on an unoccluded plane by up to ~1 %; the ratio is exactly 1 there, stays
//   in [0, 1] and has the same limit. normalize = false is the paper's plain mean
//   (1/slices) sum, clamped to [0, 1].
// - Bent normal [bent normals]: per slice the cosine-weighted direction integral of the visible
//   arc, |n_p| Int |sin t| (sin t s + cos t v) cos(t - gamma) dt, in closed form (gtao_math.h),
//   summed over slices and normalised. With normalize, the exact unoccluded vector (2/3) n per
//   slice minus the estimated occluded part (so an unoccluded pixel gets exactly n); without, the
//   plain sum.
// - Aperture: sin^2(alpha) = A (cosine convention of the reference), alpha = asin(sqrt(A)).
// - No surface (depth not finite and positive, or a zero normal): ambient 1, bent normal 0,
//   aperture 0. Samples on sky (any of the four texels), outside the texel-centre hull of the
//   image or at non-finite positions do not occlude.
// - Float agreement of the two paths: what decides which samples count (positions, bilinear
//   weights, the radius test, the horizon cosines) is computed with the same IEEE operations in
//   the same order on both (`precise` in GLSL, -ffp-contract=off in C++, explicit dot/length,
//   polynomial cos/sin/acos with identical coefficients instead of the driver's functions), so on
//   lavapipe the paths pick identical samples and agree to ~3e-7.
// - GPU: one dispatch "gtao.main", 8x8 groups, storage images depth (R32F) and normal (RGBA32F)
//   in, ambient (R32F), bent normal (RGBA32F) and aperture (R32F) out. Pipeline and images are
//   made on the first frame and kept (images recreated on a size change; everything on a change
//   of Context object).
//
// Parameters
// | name             | type  | default | range / choices  | unit        |
// |------------------|-------|---------|------------------|-------------|
// | radius           | float | 1.0     | [0, inf]         | world units |
// | slices           | int   | 2       | [1, 32]          |             |
// | steps            | int   | 8       | [1, 64]          |             |
// | max_pixel_radius | float | 256     | [1, 4096]        | px          |
// | falloff_fraction | float | 0       | [0, 1]           |             |
// | normalize        | bool  | true    |                  |             |
// | temporal_rotation| bool  | true    |                  |             |
// | search_extent    | enum  | sphere  | {sphere, depth}  |             |
// radius: occluders farther from the receiver do not count. slices: slice directions per pixel
// and frame (the paper: 2). steps: depth samples per side of a slice. max_pixel_radius: limit of
// the screen-space search per side. falloff_fraction: the last fraction of the radius over which
// occluders fade out linearly (0 = hard cutoff, the exact definition). normalize: ratio to the
// unoccluded integral of the same slices (see above). temporal_rotation: rotate slices and steps
// with the frame index (false: frame 0's pattern on every frame). search_extent: sphere or depth.
//
// Config:
//   techniques:
//     occlusion: {technique: gtao, params: {radius: 0.5}}

#include "gtao.h"

#include "gtao_gpu.h"
#include "gtao_kernel.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace rtlab::occlusion {
namespace {

constexpr std::int64_t kMaxSlices = 32;
constexpr std::int64_t kMaxSteps = 64;
constexpr double kMaxPixelRadius = 4096.0;

const std::vector<std::string> kExtentChoices = {"sphere", "depth"};

double getCheckedFloat(const config::ParamSet& params, const char* name, double lo, double hi)
{
    const double value = params.getFloat(name);
    if (!(value >= lo && value <= hi))
        throw std::invalid_argument(std::string("gtao: ") + name + " = " + std::to_string(value) +
                                    " is outside [" + std::to_string(lo) + ", " +
                                    std::to_string(hi) + "]");
    return value;
}

int getCheckedInt(const config::ParamSet& params, const char* name, std::int64_t lo,
                  std::int64_t hi)
{
    const std::int64_t value = params.getInt(name);
    if (value < lo || value > hi)
        throw std::invalid_argument(std::string("gtao: ") + name + " = " + std::to_string(value) +
                                    " is outside [" + std::to_string(lo) + ", " +
                                    std::to_string(hi) + "]");
    return int(value);
}

} // namespace

plugin::TechniqueInfo Gtao::describe()
{
    plugin::TechniqueInfo info;
    info.summary = "GTAO: horizon search in slices around the view vector, analytic "
                   "cosine-weighted visibility and bent normals, hard radius cutoff";
    info.reference = "Jimenez, Wu, Pesce, Jarabo 2016, Practical Real-Time Strategies for "
                     "Accurate Indirect Occlusion (SIGGRAPH course, ATVI-TR-16-01)";
    info.seed = "";
    return info;
}

config::ParamSchema Gtao::declareParams()
{
    const double inf = std::numeric_limits<double>::infinity();
    config::ParamSchema schema;
    schema.addFloat("radius", 1.0, 0.0, inf, "world units",
                    "occluders farther than this from the receiver do not count");
    schema.addInt("slices", 2, 1, kMaxSlices, "",
                  "slice directions per pixel and frame, uniform in angle around the view vector");
    schema.addInt("steps", 8, 1, kMaxSteps, "", "depth samples per side of each slice");
    schema.addFloat("max_pixel_radius", 256.0, 1.0, kMaxPixelRadius, "px",
                    "limit of the screen-space horizon search on each side of a slice");
    schema.addFloat("falloff_fraction", 0.0, 0.0, 1.0, "",
                    "last fraction of the radius over which occluders fade out (0 = hard cutoff, "
                    "the exact cosine AO of the radius)");
    schema.addBool("normalize", true,
                   "divide by the unoccluded integral of the same slices (exact 1 on unoccluded "
                   "surfaces); false = plain mean over slices as in the paper");
    schema.addBool("temporal_rotation", true,
                   "rotate slice directions and step offsets with the frame index");
    schema.addEnum("search_extent", "sphere", kExtentChoices,
                   "screen search length: projection of the radius sphere along the slice, or "
                   "the radius projected at the pixel's depth");
    return schema;
}

Gtao::Gtao(const config::ParamSet& params)
{
    const double inf = std::numeric_limits<double>::infinity();
    mSettings.radius = getCheckedFloat(params, "radius", 0.0, inf);
    mSettings.slices = getCheckedInt(params, "slices", 1, kMaxSlices);
    mSettings.steps = getCheckedInt(params, "steps", 1, kMaxSteps);
    mSettings.maxPixelRadius = getCheckedFloat(params, "max_pixel_radius", 1.0, kMaxPixelRadius);
    mSettings.falloffFraction = getCheckedFloat(params, "falloff_fraction", 0.0, 1.0);
    mSettings.normalize = params.getBool("normalize");
    mSettings.temporalRotation = params.getBool("temporal_rotation");
    const std::string& extent = params.getString("search_extent");
    if (extent == kExtentChoices[0])
        mSettings.searchExtent = GtaoSearchExtent::Sphere;
    else if (extent == kExtentChoices[1])
        mSettings.searchExtent = GtaoSearchExtent::Depth;
    else
        throw std::invalid_argument("gtao: search_extent has no choice '" + extent + "'");
}

Gtao::~Gtao() = default;

config::ParamSet Gtao::effectiveParams() const
{
    config::ParamSet params;
    params.set("radius", mSettings.radius);
    params.set("slices", std::int64_t(mSettings.slices));
    params.set("steps", std::int64_t(mSettings.steps));
    params.set("max_pixel_radius", mSettings.maxPixelRadius);
    params.set("falloff_fraction", mSettings.falloffFraction);
    params.set("normalize", mSettings.normalize);
    params.set("temporal_rotation", mSettings.temporalRotation);
    params.set("search_extent",
               kExtentChoices[mSettings.searchExtent == GtaoSearchExtent::Sphere ? 0 : 1]);
    return params;
}

plugin::OcclusionDefinition Gtao::definition() const
{
    return {plugin::OcclusionQuantity::CosineAo, mSettings.radius};
}

void Gtao::compute(const plugin::OcclusionInput& input, plugin::OcclusionOutput& out)
{
    if (input.gpu != nullptr && input.gpuLinearDepth != nullptr && input.gpuNormal != nullptr) {
        // The frame's G-buffer stays on the GPU: bind it, upload nothing.
        const int width = int(input.gpuLinearDepth->getDesc().width);
        const int height = int(input.gpuLinearDepth->getDesc().height);
        if (!mGpu)
            mGpu = std::make_unique<GtaoGpu>();
        mGpu->compute(*input.gpu, makeGtaoFrameConstants(mSettings, input, width, height),
                      *input.gpuLinearDepth, *input.gpuNormal, out);
        if (input.readBack)
            mGpu->readBack(out);
        return;
    }
    if (input.linearDepth == nullptr || input.normal == nullptr)
        throw std::invalid_argument("gtao: OcclusionInput needs linearDepth and normal");
    const Image<float>& depth = *input.linearDepth;
    const Image<glm::vec3>& normal = *input.normal;
    if (depth.width != normal.width || depth.height != normal.height ||
        depth.pixels.size() != std::size_t(depth.width) * std::size_t(depth.height) ||
        normal.pixels.size() != depth.pixels.size())
        throw std::invalid_argument("gtao: linearDepth and normal differ in size");
    const GtaoFrameConstants constants =
        makeGtaoFrameConstants(mSettings, input, depth.width, depth.height);
    if (depth.width == 0 || depth.height == 0) {
        out = plugin::OcclusionOutput();
        out.ambient = Image<float>(depth.width, depth.height);
        out.bentNormal = Image<glm::vec3>(depth.width, depth.height);
        out.coneAperture = Image<float>(depth.width, depth.height);
        return;
    }
    if (input.gpu != nullptr) {
        if (!mGpu)
            mGpu = std::make_unique<GtaoGpu>();
        mGpu->compute(*input.gpu, constants, depth, normal, out);
        if (input.readBack)
            mGpu->readBack(out);
    } else {
        computeGtaoCpu(constants, depth, normal, out);
    }
}

void Gtao::readBack(plugin::OcclusionOutput& out)
{
    if (!mGpu)
        throw Error("gtao: nothing computed on the GPU to read back");
    mGpu->readBack(out);
}

} // namespace rtlab::occlusion

RTLAB_REGISTER_TECHNIQUE(occlusion, gtao, rtlab::occlusion::Gtao)
