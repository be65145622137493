// lsao: Line-Sweep Ambient Obscurance, as Quantum Break shipped it.
//
// Registry key: occlusion/lsao
//
// Paper: V. Timonen, "Line-Sweep Ambient Obscurance", Computer Graphics Forum 32(4) (Proc.
// EGSR 2013), 97-105. Seed: 002_2c73d3b2bb6f7a13.txt (Quantum Break, screen-space lighting:
// "For occlusion, we have SSAO which is based on LSAO": 36 directions, long ~10 px steps, lines
// ~2 px apart, steps jittered along each line for an even sample distribution, one near-field
// sample per pixel and direction roughly half-way from the receiver to the nearest sweep sample,
// occluders clamped to the hemisphere of the pixel's normal, 4 rotating sets of directions).
//
// Quantity: Obscurance with falloff rho and radius r, the reference's
//   W = (1/pi) Int_H rho(d(w)/r) cos(theta) dw,  rho(x) = x or 3x^2 - 2x^3, 1 beyond r or no hit.
// LSAO solves obscurance per azimuthal direction from horizons [Timonen 2013: sweeps], which is
// this integral written over half-slices: with w(theta) = cos(theta) v + sin(theta) t in the plane
// through the eye that contains the screen line (v toward the eye, t toward the upstream side),
// dw = sin(theta) dtheta dphi and
//   W = 1 - (1/pi) Int_0^2pi Int_occluded (1 - rho) dot(n, w) sin(theta) dtheta dphi,
// evaluated at N azimuths as W = 1 - (2/N) sum_k O_k (exact for an unoccluded pixel).
//
// Algorithm
// - Layout: N directions phi_k = 2 pi (k + s/S)/N, s = frameIndex mod S (direction_sets) [Quantum
//   Break seed: 4 sets of 36]. Per direction, parallel screen lines line_spacing px apart cover
//   the image; each line is cut into strata of `step` px with one sample per stratum, at a hashed
//   position (jitter, "for an even sample distribution") or the stratum middle (regular).
// - Sample points: the point on the line, at the depth of the tangent plane (depth, normal) of
//   the pixel that contains it; where that plane is seen edge-on (depth changes more than 2x
//   within the pixel) or the normal is zero, the pixel centre's depth (and in the gather its
//   G-buffer point). The paper takes the nearest pixel's depth; on tilted planes that staircase
//   poses as horizons (a quantisation step one pixel back can out-slope a wall far along the
//   line) and the hull then loses the true dominant occluder.
// - Pass 1 "lsao.sweep", one invocation per line [Timonen 2013: sweeps]: the line is walked from
//   one side of the depth buffer to the other. In (t, 1/depth) (t along the line) the plane of the
//   line through the eye maps projectively so that eye rays are vertical: the horizon of a sample
//   over ALL earlier samples of the line is the largest slope back, i.e. the tangent to the upper
//   convex hull of the earlier samples. The hull lives on a stack [Timonen 2013: occluder hull]:
//   each sample pops the vertices on or below the chord to it (never a horizon again), the top is
//   its dominant occluder, then it is pushed - amortised O(1), independent of the radius. The
//   test is division-free (1/depth kept as a fraction) so CPU and GPU take identical decisions.
//   The stack holds 32 entries as a ring; a push onto a full ring forgets the farthest vertex
//   (answers are then exact among the retained vertices). Per sample, the stratum index of its
//   dominant occluder is stored (uint32; no occluder: 0xffffffff).
// - Pass 2 "lsao.gather", per pixel and direction. `gather: nearest` (the default) [Quantum
//   Break seed: "average distance to the nearest step is less than 3 px"]: the line nearest to
//   the pixel and, on it, the sample nearest to the pixel; `gather: bilinear` [Timonen 2013:
//   gathering]: the two lines that bracket the pixel (weights by distance) and, on each, the two
//   samples that bracket it along the line (weights by position), four occluder sets for about
//   three times the gather's time (experiments/lsao_gather.yaml). Unlike the paper, which
//   interpolates obscurance computed at the samples, every occluder is re-evaluated from the
//   receiver (its G-buffer point and normal, as Quantum Break clamps occluders with the pixel's
//   normal): an upstream sample contributes itself and its dominant occluder, a downstream sample
//   its dominant occluder (which lies at or before the upstream sample), and both the near-field
//   sample half-way between the receiver and the upstream sample of the line (at least 1 px)
//   [Quantum Break seed]. Points of neighbouring lines are moved into the receiver's slice plane
//   along its tangent plane (exact for samples of the receiver's plane at any incidence); their
//   side (upstream or not) is taken relative to the eye.
// - Per half-slice (w(theta) = cos(theta) v + sin(theta) t, theta from the view vector v toward
//   the upstream side t): up to three occluders at angles theta_i with distances d_i; each blocks
//   the rays from theta_i down to the tangent plane, and a ray is weighted 1 - rho(d/r) with d the
//   distance of the nearest occluder above it. So the occluded part of the slice is weighted by
//   the distance of the occluder that defines it (the dominant occluder's above the near samples'
//   horizons). Cosine-weighted measures are closed-form, GTAO's slice integral:
//   F(h) = Int_0^h dot(n, w) sin(theta) dtheta = nv sin^2(h)/2 + nt (h - sin h cos h)/2.
// - Walls below occluders (`walls`, an addition to the paper, lsao_core.h): an occluder whose
//   foot (the occluder projected along the receiver's normal onto its tangent plane) is the
//   visible surface in the depth buffer stands on a wall; the rays below it at elevation phi meet
//   that wall at u / cos(phi) (u its distance along the tangent plane) when that is nearer than
//   the occluders above them, integrated in closed form. It is what a crease (a floor against a
//   wall) needs: the wall's top, the only hull vertex, lies beyond the radius. A foreground
//   object hides its own foot, so it casts no halo. Obscurance only: visibility keeps the
//   occluders' distances.
// - Interleaving [Quantum Break seed: "We cycle through the 36 directions on 9 pixel
//   neighborhoods"]: pixel (x, y) gathers only the directions k = (x mod n) + n (y mod n) mod n^2
//   (n = interleave; 36 directions, n = 3: 4 directions 90 degrees apart per pixel). Pass 3
//   "lsao.resolve" averages the sums over the n x n window around each pixel (one pixel of each
//   class), each scaled from its share of the directions to all N and weighted by how well the
//   neighbour lies on the receiver's tangent plane and shares its normal, so each pixel ends
//   with all N directions for 1/n^2 of the gather. n is lowered until every class has a
//   direction (n^2 <= N); n = 1 is the plain per-pixel gather.
// - Visibility (bent normal, aperture) uses rho = step at r: an occluder counts if d < r.
//   A = 1 - (2/N) sum_k V_k, aperture = asin(sqrt(A)) (sin^2 = A, cosine convention); bent normal
//   = normalize((2 pi/3) n - (2 pi/N) sum_k M_k), M_k = Int_occluded w dot(n, w) sin dtheta, the
//   occluded first moment of the half-slice (the unoccluded hemisphere gives (2 pi/3) n); n where
//   nothing is visible.
// - Deviations from the reference integral: one depth layer, thin objects occlude as if infinitely
//   thick, off-screen geometry is missing (as every screen-space method); with interleaving, a
//   pixel's directions come from receivers up to floor(n/2) px away; per half-slice only
//   horizons are known, so every ray below one counts as blocked at that occluder's distance, or
//   at its wall's where its foot is seen; the dominant occluder is the largest horizon over the
//   whole line, so a higher occluder beyond the radius hides a lower one within it unless a wall
//   stands below it (the near-field and upstream samples keep some of it); between two samples
//   of a line only the near-field sample is seen; N discrete azimuths. See README.md for
//   measured errors.
//
// Parameters
// | name            | type  | default | range / choices        | unit        |
// |-----------------|-------|---------|------------------------|-------------|
// | directions      | int   | 36      | [1, 128]               |             |
// | line_spacing    | float | 2       | [0.5, 64]              | px          |
// | step            | float | 10      | [1, 256]               | px          |
// | jitter          | bool  | true    |                        |             |
// | near_field      | bool  | true    |                        |             |
// | direction_sets  | int   | 4       | [1, 64]                |             |
// | interleave      | int   | 3       | [1, 4]                 | px          |
// | radius          | float | 1       | [0, inf)               | world units |
// | falloff         | enum  | linear  | {linear, smoothstep}   |             |
// | walls           | bool  | true    |                        |             |
// | gather          | enum  | nearest | {bilinear, nearest}    |             |
//
// Config:
//   techniques:
//     occlusion: {technique: lsao, params: {radius: 0.5}}

#include "lsao.h"

#include "lsao_cpu.h"
#include "lsao_gpu.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace rtlab::occlusion::lsao {
namespace {

const std::vector<std::string> kFalloffChoices = {"linear", "smoothstep"};
const std::vector<std::string> kGatherChoices = {"bilinear", "nearest"};

void checkRange(const char* name, double value, double lo, double hi)
{
    if (!(value >= lo && value <= hi))
        throw std::invalid_argument(std::string("lsao: ") + name + " " + std::to_string(value) +
                                    " is outside [" + std::to_string(lo) + ", " +
                                    std::to_string(hi) + "]");
}

//! The index of `value` among an enum parameter's choices; throws naming them otherwise.
std::size_t findChoice(const char* name, const std::string& value,
                       const std::vector<std::string>& choices)
{
    for (std::size_t i = 0; i < choices.size(); ++i)
        if (value == choices[i])
            return i;
    std::string list;
    for (const std::string& c : choices)
        list += (list.empty() ? "" : ", ") + c;
    throw std::invalid_argument(std::string("lsao: ") + name + " '" + value + "' is not one of " +
                                list);
}

} // namespace

plugin::TechniqueInfo Lsao::describe()
{
    plugin::TechniqueInfo info;
    info.summary = "Line-sweep ambient obscurance: per-direction line sweeps keep a convex hull "
                   "of occluders, dominant occluders from the whole depth buffer";
    info.reference = "Timonen 2013, Line-Sweep Ambient Obscurance (CGF 32(4), EGSR)";
    info.seed = "002_2c73d3b2bb6f7a13.txt (Quantum Break screen-space lighting: SSAO based on "
                "LSAO)";
    return info;
}

config::ParamSchema Lsao::declareParams()
{
    config::ParamSchema schema;
    schema.addInt("directions", 36, 1, 128, "",
                  "sweep directions over the full circle (each one half-slice)");
    schema.addFloat("line_spacing", 2.0, 0.5, 64.0, "px",
                    "distance between parallel sweep lines of one direction");
    schema.addFloat("step", 10.0, 1.0, 256.0, "px",
                    "sample spacing along a line (one sample "
                    "per stratum of this length)");
    schema.addBool("jitter", true,
                   "jittered sample positions within each step stratum (else "
                   "regular, at the stratum middles)");
    schema.addBool("near_field", true,
                   "one extra sample per pixel and direction half-way to "
                   "the nearest upstream sweep sample");
    schema.addInt("direction_sets", 4, 1, 64, "",
                  "rotated direction sets, frameIndex modulo this picks the set");
    schema.addInt("interleave", 3, 1, 4, "px",
                  "tiles of interleave x interleave pixels share the directions out (each "
                  "pixel gathers 1/interleave^2 of them), then a geometry-aware average over "
                  "the tile window restores all of them; 1: every pixel gathers every direction");
    schema.addFloat("radius", 1.0, 0.0, std::numeric_limits<double>::infinity(), "world units",
                    "obscurance falloff radius: occluders at or beyond it do not count");
    schema.addEnum("falloff", "linear", kFalloffChoices,
                   "obscurance falloff rho(d/r): linear x or smoothstep 3x^2-2x^3");
    schema.addBool("walls", true,
                   "a wall below each occluder whose foot on the receiver's tangent plane is the "
                   "visible surface: the rays below the occluder meet it at their own distance "
                   "(creases); false: at the occluder's distance, as in the paper");
    schema.addEnum("gather", "nearest", kGatherChoices,
                   "per direction, the occluders of the sample nearest to the pixel on the "
                   "nearest line (nearest, as Quantum Break), or a bilinear blend over the two "
                   "bracketing lines and the two bracketing samples on each (bilinear, as the "
                   "paper's gather): four occluder sets instead of one");
    return schema;
}

Lsao::Lsao(const config::ParamSet& params)
{
    checkRange("directions", double(params.getInt("directions")), 1, 128);
    checkRange("line_spacing", params.getFloat("line_spacing"), 0.5, 64.0);
    checkRange("step", params.getFloat("step"), 1.0, 256.0);
    checkRange("direction_sets", double(params.getInt("direction_sets")), 1, 64);
    checkRange("interleave", double(params.getInt("interleave")), 1, 4);
    checkRange("radius", params.getFloat("radius"), 0.0, std::numeric_limits<double>::infinity());
    mParams.directions = int(params.getInt("directions"));
    mParams.lineSpacing = float(params.getFloat("line_spacing"));
    mParams.step = float(params.getFloat("step"));
    mParams.jitter = params.getBool("jitter");
    mParams.nearField = params.getBool("near_field");
    mParams.directionSets = int(params.getInt("direction_sets"));
    mParams.interleave = int(params.getInt("interleave"));
    mParams.radius = params.getFloat("radius");
    mParams.walls = params.getBool("walls");
    mParams.gather = findChoice("gather", params.getString("gather"), kGatherChoices) == 0
                         ? Gather::Bilinear
                         : Gather::Nearest;
    mParams.falloff = findChoice("falloff", params.getString("falloff"), kFalloffChoices) == 0
                          ? Falloff::Linear
                          : Falloff::Smoothstep;
}

Lsao::~Lsao() = default;

config::ParamSet Lsao::effectiveParams() const
{
    config::ParamSet p;
    p.set("directions", std::int64_t(mParams.directions));
    p.set("line_spacing", double(mParams.lineSpacing));
    p.set("step", double(mParams.step));
    p.set("jitter", mParams.jitter);
    p.set("near_field", mParams.nearField);
    p.set("direction_sets", std::int64_t(mParams.directionSets));
    p.set("interleave", std::int64_t(mParams.interleave));
    p.set("radius", mParams.radius);
    p.set("falloff", kFalloffChoices[mParams.falloff == Falloff::Linear ? 0 : 1]);
    p.set("walls", mParams.walls);
    p.set("gather", kGatherChoices[mParams.gather == Gather::Bilinear ? 0 : 1]);
    return p;
}

plugin::OcclusionDefinition Lsao::definition() const
{
    return {plugin::OcclusionQuantity::Obscurance, mParams.radius,
            mParams.falloff == Falloff::Linear ? plugin::OcclusionFalloff::Linear
                                               : plugin::OcclusionFalloff::Smoothstep};
}

void Lsao::compute(const plugin::OcclusionInput& input, plugin::OcclusionOutput& out)
{
    if (input.gpu != nullptr && input.gpuLinearDepth != nullptr && input.gpuNormal != nullptr) {
        // The frame's G-buffer stays on the GPU: bind it, upload nothing.
        const int w = int(input.gpuLinearDepth->getDesc().width);
        const int h = int(input.gpuLinearDepth->getDesc().height);
        const plugin::ScreenProjection projection =
            plugin::ScreenProjection::fromMatrix(input.projection, w, h);
        const Layout layout = buildLayout(w, h, projection, mParams, input.frameIndex);
        if (!mGpu || &mGpu->getContext() != input.gpu)
            mGpu = std::make_unique<GpuRunner>(*input.gpu, mParams);
        mGpu->run(layout, projection, mParams, *input.gpuLinearDepth, *input.gpuNormal, out,
                  input.readBack);
        return;
    }
    if (input.linearDepth == nullptr || input.normal == nullptr)
        throw std::invalid_argument("lsao: OcclusionInput needs linearDepth and normal");
    const Image<float>& depth = *input.linearDepth;
    const Image<glm::vec3>& normal = *input.normal;
    if (depth.width != normal.width || depth.height != normal.height)
        throw std::invalid_argument("lsao: depth and normal images differ in size");
    const int w = depth.width, h = depth.height;
    if (w <= 0 || h <= 0) {
        out.ambient = Image<float>(w, h);
        out.bentNormal = Image<glm::vec3>(w, h);
        out.coneAperture = Image<float>(w, h);
        out.coneVisibility.clear();
        return;
    }
    const plugin::ScreenProjection projection =
        plugin::ScreenProjection::fromMatrix(input.projection, w, h);
    const Layout layout = buildLayout(w, h, projection, mParams, input.frameIndex);
    if (input.gpu == nullptr) {
        computeOnCpu(layout, projection, mParams, depth, normal, out);
        return;
    }
    if (!mGpu || &mGpu->getContext() != input.gpu)
        mGpu = std::make_unique<GpuRunner>(*input.gpu, mParams);
    mGpu->run(layout, projection, mParams, depth, normal, out, input.readBack);
}

void Lsao::readBack(plugin::OcclusionOutput& out)
{
    if (!mGpu)
        throw Error("lsao: nothing computed on the GPU to read back");
    mGpu->readBack(out);
}

} // namespace rtlab::occlusion::lsao

RTLAB_REGISTER_TECHNIQUE(occlusion, lsao, rtlab::occlusion::lsao::Lsao)
