#pragma once
// The pieces of Line-Sweep Ambient Obscurance that both paths share: parameters, the line layout,
// the step jitter, the occluder hull of the sweep and the per-direction obscurance of the gather.
// shaders/lsao_common.glsl mirrors every function here. Those whose results decide discrete
// choices (sample positions, hull pops, which lines and steps bracket a pixel, the near-field
// pixel) are written with the same float operations in the same order as the GLSL, which marks
// them `precise`, and the build turns floating-point contraction off, so both paths take the same
// decisions and differ only by the rounding of continuous quantities.

#include "plugin/screen_space.h"

#include <glm/ext/vector_int2.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace rtlab::occlusion::lsao {

//! Marks "no dominant occluder" in the sweep buffer (no earlier sample, sky, or outside).
constexpr std::uint32_t kNoOccluder = 0xffffffffu;
//! Entries of the hull stack of one line (a ring buffer; see OccluderHull).
constexpr int kHullCapacity = 32;
//! Largest sweep buffer of one batch of directions (entries of 4 bytes): 64 MiB.
constexpr std::size_t kMaxBatchEntries = std::size_t(16) << 20;

enum class Falloff { Linear, Smoothstep };

//! Which sweep samples a receiver evaluates per direction (Params::gather).
enum class Gather {
    //! The two lines that bracket the receiver and the two samples that bracket it on each
    //! [Timonen 2013: gathering]: up to four occluder sets, weighted bilinearly.
    Bilinear,
    //! The nearest line and, on it, the nearest sample [Quantum Break seed: "average distance to
    //! the nearest step is less than 3 px"]: one occluder set.
    Nearest,
};

//! The technique's parameters (lsao.cpp declares them with units and ranges).
struct Params {
    int directions = 36;      //!< sweep directions over the full circle, [1, 128]
    float lineSpacing = 2.0f; //!< px between parallel lines of one direction
    float step = 10.0f;       //!< px between samples along a line (mean, with jitter)
    bool jitter = true;       //!< jittered step positions instead of regular ones
    bool nearField = true;    //!< one extra sample per pixel and direction near the receiver
    int directionSets = 4;    //!< rotated direction sets, one per frame in turn
    int interleave = 3;       //!< tiles of interleave^2 pixels share the directions out
    double radius = 1.0;      //!< world units: falloff radius
    Falloff falloff = Falloff::Linear;
    bool walls = true; //!< walls below occluders whose foot is the visible surface
    Gather gather = Gather::Nearest;
};

//! One direction of the layout, as the shaders read it (std430, 64 bytes).
struct Direction {
    glm::vec2 dir{1.0f, 0.0f};  //!< unit screen direction of the sweep (pixels, y down)
    glm::vec2 perp{0.0f, 1.0f}; //!< (-dir.y, dir.x): lines are offset along it
    glm::vec4 axis{0.0f};       //!< xyz: unit view-space direction of a step along dir
    float tMin = 0.0f;          //!< px: smallest dot(pixel, dir) over the image corners
    float cMin = 0.0f;          //!< px: offset of line 0 along perp
    std::uint32_t lineCount = 0;
    std::uint32_t stepCount = 0; //!< step strata per line
    std::uint32_t base = 0;      //!< first entry of this direction in its batch's sweep buffer
    std::uint32_t pad[3] = {0, 0, 0};
};
static_assert(sizeof(Direction) == 64, "must match lsao_common.glsl");

//! Directions [begin, end) whose sweep results fit one buffer.
struct Batch {
    std::uint32_t begin = 0;
    std::uint32_t end = 0;
    std::size_t entryCount = 0;
};

//! Where every line and step of a frame lies.
struct Layout {
    int width = 0;
    int height = 0;
    std::uint32_t setIndex = 0; //!< direction set of this frame
    bool jitter = true;         //!< jittered step positions (else regular)
    float spacing = 2.0f;
    float invSpacing = 0.5f;
    float step = 10.0f;
    float invStep = 0.1f;
    glm::vec2 projOffset{0.0f}; //!< ScreenProjection::offset
    glm::vec2 invScale{1.0f};   //!< 1 / ScreenProjection::scale
    glm::vec2 invSize{1.0f};    //!< 1 / image size
    std::vector<Direction> directions;
    std::vector<Batch> batches;
    std::uint32_t maxLineCount = 0;
    std::size_t maxBatchEntries = 0;
    //! Side of the pixel tiles that share the directions out (1: every pixel takes every
    //! direction); Params::interleave limited so that every pixel of a tile gets one.
    int interleave = 1;
};

//! Push constants of both shaders (std430 push-constant block, 96 bytes).
struct Constants {
    glm::vec2 projScale{1.0f};
    glm::vec2 projOffset{0.0f};
    glm::vec2 size{1.0f};
    glm::vec2 invScale{1.0f};
    glm::vec2 invSize{1.0f};
    std::int32_t width = 0;
    std::int32_t height = 0;
    float spacing = 2.0f;
    float invSpacing = 0.5f;
    float step = 10.0f;
    float invStep = 0.1f;
    float radius = 1.0f;
    float invRadius = 1.0f;
    std::uint32_t dirBegin = 0;
    std::uint32_t dirEnd = 0;
    std::uint32_t dirCount = 0; //!< all directions of the frame (normalisation)
    std::uint32_t flags = 0;
    std::uint32_t setIndex = 0;
    std::uint32_t interleave = 1; //!< Layout::interleave
};
static_assert(sizeof(Constants) == 96, "must match lsao_common.glsl");

constexpr std::uint32_t kFlagJitter = 1u;
constexpr std::uint32_t kFlagNearField = 2u;
constexpr std::uint32_t kFlagSmoothstep = 4u;
constexpr std::uint32_t kFlagFirstBatch = 8u;
constexpr std::uint32_t kFlagLastBatch = 16u;

//! The lines and steps of all directions for one frame. The direction set is frameIndex modulo
//! directionSets; set s rotates every direction by 2 pi s / (directionSets * directions).
Layout buildLayout(int width, int height, const plugin::ScreenProjection& projection,
                   const Params& params, int frameIndex,
                   std::size_t maxBatchEntries = kMaxBatchEntries);

//! The push constants of batch `batch` of `layout`.
Constants makeConstants(const Layout& layout, const plugin::ScreenProjection& projection,
                        const Params& params, std::size_t batch);

// ---- Interleaved directions [Quantum Break seed: "We cycle through the 36 directions on 9 pixel
// neighborhoods"] -------------------------------------------------------------------------------
// Pixel (x, y) of a tile of n x n pixels has the class (x mod n) + n (y mod n) and gathers the
// directions k with k mod n^2 = class (36 directions, n = 3: 4 per pixel, 90 degrees apart and
// rotated by 10 degrees from class to class). The resolve pass then averages the per-direction
// sums over the n x n window around each pixel, which holds one pixel of every class, over the
// neighbours on the receiver's surface (isSameSurface), so every pixel ends with all N
// directions at 1/n^2 of the gather cost.

//! The largest tile side not above `requested` whose n^2 classes each get one direction.
inline int computeEffectiveInterleave(int requested, int directions)
{
    int n = std::max(requested, 1);
    while (n > 1 && n * n > directions)
        --n;
    return n;
}

//! The class of pixel (x, y) in tiles of side n.
inline std::uint32_t computePixelClass(int x, int y, int n)
{
    return std::uint32_t(x % n + n * (y % n));
}

//! How many of the directions [0, directionCount) class `pixelClass` gathers (tiles of side n).
inline std::uint32_t countClassDirections(std::uint32_t pixelClass, std::uint32_t directionCount,
                                          int n)
{
    const std::uint32_t classes = std::uint32_t(n * n);
    return directionCount / classes + (pixelClass < directionCount % classes ? 1u : 0u);
}

//! First offset of the n x n resolve window around a pixel along each axis (-1 for n = 3).
inline int computeWindowBegin(int n)
{
    return -((n - 1) / 2);
}

//! Whether neighbour pixel j counts in receiver i's resolve: its normal within 25.8 degrees of
//! the receiver's (cos^2 >= 0.81) and its point within 7.1 degrees of the receiver's tangent
//! plane seen from the receiver (plane distance <= separation / 8), so edges, creases and depth
//! jumps keep their own directions. A discrete decision: written with the same float operations
//! as lsaoIsSameSurface (no division, raw normals, positions scaled by projScale.x * projScale.y),
//! so both paths keep the same neighbours.
inline bool isSameSurface(glm::vec2 pixelI, float zi, const glm::vec3& ni, glm::vec2 pixelJ,
                          float zj, const glm::vec3& nj, glm::vec2 projScale, glm::vec2 projOffset,
                          glm::vec2 invSize)
{
    const float dn = ni.x * nj.x + ni.y * nj.y + ni.z * nj.z;
    const float lenI = ni.x * ni.x + ni.y * ni.y + ni.z * ni.z;
    const float lenJ = nj.x * nj.x + nj.y * nj.y + nj.z * nj.z;
    if (!(dn > 0.0f) || !(dn * dn >= 0.81f * (lenI * lenJ)))
        return false;
    // View x = z (ndc.x + offset.x) / scale.x: differences times scale.x * scale.y.
    const float uxi = zi * ((pixelI.x * invSize.x * 2.0f - 1.0f) + projOffset.x);
    const float uyi = zi * ((pixelI.y * invSize.y * 2.0f - 1.0f) + projOffset.y);
    const float uxj = zj * ((pixelJ.x * invSize.x * 2.0f - 1.0f) + projOffset.x);
    const float uyj = zj * ((pixelJ.y * invSize.y * 2.0f - 1.0f) + projOffset.y);
    const float dx = (uxj - uxi) * projScale.y;
    const float dy = (uyj - uyi) * projScale.x;
    const float dz = (zi - zj) * (projScale.x * projScale.y);
    const float plane = ni.x * dx + ni.y * dy + ni.z * dz;
    const float separation2 = dx * dx + dy * dy + dz * dz;
    return plane * plane <= 0.015625f * (separation2 * lenI);
}

// ---- Line layout and jitter --------------------------------------------------------------

inline std::uint32_t mixHash(std::uint32_t h, std::uint32_t value)
{
    h ^= value * 0x9e3779b9u;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

//! Position of the sample in stratum `stepIndex` of a line, as a fraction of the step in [0, 1):
//! 0.5 without jitter (regular steps), else a hash of direction, line, stratum and set.
inline float computeStepJitter(std::uint32_t direction, std::uint32_t line, std::uint32_t stepIndex,
                               std::uint32_t setIndex, bool jitter)
{
    if (!jitter)
        return 0.5f;
    std::uint32_t h = mixHash(0x4c53414fu, direction);
    h = mixHash(h, line);
    h = mixHash(h, stepIndex);
    h = mixHash(h, setIndex);
    return float(h >> 8) * (1.0f / 16777216.0f);
}

//! px: offset of line `line` along Direction::perp.
inline float computeLineOffset(const Direction& d, std::uint32_t line, float spacing)
{
    return d.cMin + float(line) * spacing;
}

//! px: position along Direction::dir of the sample in stratum `stepIndex`, whose position
//! within its stratum is `fraction` (computeStepJitter).
inline float computeSampleT(const Direction& d, std::uint32_t stepIndex, float fraction, float step)
{
    return d.tMin + (float(stepIndex) + fraction) * step;
}

//! Continuous pixel coordinate of the point at (t along dir, c along perp).
inline glm::vec2 computeLinePoint(const Direction& d, float t, float c)
{
    return {t * d.dir.x + c * d.perp.x, t * d.dir.y + c * d.perp.y};
}

//! A sample of a line: its stratum, position along the line and pixel (the one containing the
//! point on the line; its depth is the sample's depth). `exists` when the stratum is in range
//! and the point lies inside the image.
struct LineSample {
    bool exists = false;
    int stratum = -1;
    float t = 0.0f;
    glm::ivec2 pixel{-1};
};

//! The sample in stratum `stratum` of line `line` (offset c) of direction k.
inline LineSample locateSample(const Layout& layout, const Direction& d, std::uint32_t k,
                               std::uint32_t line, float c, int stratum)
{
    LineSample s;
    s.stratum = stratum;
    if (stratum < 0 || stratum >= int(d.stepCount))
        return s;
    const float xi =
        computeStepJitter(k, line, std::uint32_t(stratum), layout.setIndex, layout.jitter);
    s.t = computeSampleT(d, std::uint32_t(stratum), xi, layout.step);
    const glm::vec2 pos = computeLinePoint(d, s.t, c);
    s.pixel = glm::ivec2(int(std::floor(pos.x)), int(std::floor(pos.y)));
    s.exists =
        s.pixel.x >= 0 && s.pixel.y >= 0 && s.pixel.x < layout.width && s.pixel.y < layout.height;
    return s;
}

//! Inverse depth of a sample as a fraction a / b (b > 0), free of divisions so that both paths
//! round it identically. `onLine`: the tangent-plane depth at the line point; else the depth of
//! the pixel centre (the gather then uses the pixel centre's G-buffer point).
struct SampleHeight {
    float a = 1.0f;
    float b = 1.0f;
    bool onLine = false;
};

//! The sample at line point `q` takes its depth from the tangent plane of the pixel that contains
//! it (centre depth `z`, normal `n`, any length): the eye ray through q, r = (view at depth 1),
//! meets the plane {X : dot(X, n) = dot(P, n)} at depth dot(P, n) / dot(r, n). So every sample
//! lies exactly on its line and, on planar surfaces, exactly on the surface: a plane stays a
//! straight line in (t, 1/depth) instead of a staircase of pixel depths whose steps would pose as
//! horizons. Falls back to 1 / z when the normal is zero, the plane is seen edge-on, or the
//! corrected depth leaves [z/2, 2z] (grazing incidence). Same arithmetic as
//! ScreenProjection::toView, with reciprocals instead of divisions.
inline SampleHeight computeSampleHeight(const Layout& layout, glm::vec2 q, glm::ivec2 pixel,
                                        float z, const glm::vec3& n)
{
    const float cx = float(pixel.x) + 0.5f;
    const float cy = float(pixel.y) + 0.5f;
    const float px =
        z * (((2.0f * cx) * layout.invSize.x - 1.0f + layout.projOffset.x) * layout.invScale.x);
    const float py =
        z * (((2.0f * cy) * layout.invSize.y - 1.0f + layout.projOffset.y) * layout.invScale.y);
    const float rx =
        ((2.0f * q.x) * layout.invSize.x - 1.0f + layout.projOffset.x) * layout.invScale.x;
    const float ry =
        ((2.0f * q.y) * layout.invSize.y - 1.0f + layout.projOffset.y) * layout.invScale.y;
    float a = rx * n.x + ry * n.y - n.z;
    float b = px * n.x + py * n.y - z * n.z;
    if (b < 0.0f) {
        a = -a;
        b = -b;
    }
    const float az = a * z;
    if (b > 0.0f && a > 0.0f && az >= 0.5f * b && az <= 2.0f * b)
        return {a, b, true};
    return {1.0f, z, false};
}

// ---- Occluder hull of a line [Timonen 2013: occluder hull] ------------------------------

//! True when B lies on or below the chord from A to C in the (t, 1/depth) plane, t increasing
//! from A to C. In that plane (a projective image of the line's plane through the eye) the eye
//! rays are vertical and the horizon seen from a point is the largest slope back to earlier
//! points. With 1/depth = a/b (b > 0) the test is division-free: both sides multiplied by
//! bA bB bC > 0.
inline bool isOnOrBelowChord(float tA, SampleHeight hA, float tB, SampleHeight hB, float tC,
                             SampleHeight hC)
{
    const float lhs = ((hB.a * hA.b - hA.a * hB.b) * hC.b) * (tC - tA);
    const float rhs = ((hC.a * hA.b - hA.a * hC.b) * hB.b) * (tB - tA);
    return lhs <= rhs;
}

//! The upper convex hull of the samples of one line seen so far, in (t, 1/depth), kept on a
//! stack [Timonen 2013: occluder hull]. findDominant(q) pops the vertices that lie on or below
//! the chord from their predecessor to q (they can never be the horizon of q or of any later
//! sample), and the vertex left on top is the dominant occluder of q: the earlier sample with
//! the largest horizon angle seen from q over the whole line, found in amortised O(1).
//! The stack is a ring of kHullCapacity entries: pushing onto a full ring overwrites the bottom,
//! i.e. forgets the farthest hull vertex; the answers are then the exact dominant occluder among
//! the retained vertices (overflowed() tells). Ties (collinear samples) keep the farther sample.
class OccluderHull {
public:
    //! The id of the dominant occluder of the sample (t, height) among the pushed samples, or
    //! kNoOccluder when none was pushed. `t` must exceed the t of every pushed sample.
    std::uint32_t findDominant(float t, SampleHeight height)
    {
        while (mSize >= 2) {
            const Entry& b = mEntries[mTop & kMask];
            const Entry& a = mEntries[(mTop - 1) & kMask];
            if (!isOnOrBelowChord(a.t, a.height, b.t, b.height, t, height))
                break;
            --mTop;
            --mSize;
        }
        return mSize > 0 ? mEntries[mTop & kMask].id : kNoOccluder;
    }
    //! The same for a sample at linear depth `depth`.
    std::uint32_t findDominant(float t, float depth)
    {
        return findDominant(t, SampleHeight{1.0f, depth, false});
    }

    //! Adds a sample (call findDominant with it first, which removes what it hides).
    void push(float t, SampleHeight height, std::uint32_t id)
    {
        ++mTop;
        mEntries[mTop & kMask] = {t, height, id};
        if (mSize < kHullCapacity)
            ++mSize;
        else
            mOverflowed = true;
    }
    void push(float t, float depth, std::uint32_t id)
    {
        push(t, SampleHeight{1.0f, depth, false}, id);
    }

    int size() const { return mSize; }
    bool overflowed() const { return mOverflowed; }
    //! The id of the i-th retained vertex from the bottom (0 = farthest).
    std::uint32_t getVertexId(int i) const { return mEntries[(mTop - mSize + 1 + i) & kMask].id; }

private:
    static constexpr int kMask = kHullCapacity - 1;
    static_assert((kHullCapacity & kMask) == 0, "capacity must be a power of two");
    struct Entry {
        float t = 0.0f;
        SampleHeight height;
        std::uint32_t id = kNoOccluder;
    };
    std::array<Entry, kHullCapacity> mEntries{};
    int mTop = -1;
    int mSize = 0;
    bool mOverflowed = false;
};

// ---- Per-direction obscurance of the gather ----------------------------------------------

//! atan2 from a polynomial (|error| < 2e-6 rad), the same operations on both paths so that the
//! CPU and GPU agree far below the accuracy the estimator needs.
inline float computeAtan2(float y, float x)
{
    const float ax = std::fabs(x);
    const float ay = std::fabs(y);
    const float hi = std::max(ax, ay);
    const float lo = std::min(ax, ay);
    const float a = hi > 0.0f ? lo / hi : 0.0f;
    const float s = a * a;
    float r = -0.0117212f;
    r = r * s + 0.05265332f;
    r = r * s - 0.11643287f;
    r = r * s + 0.19354346f;
    r = r * s - 0.33262347f;
    r = r * s + 0.99997726f;
    r = r * a;
    if (ay > ax)
        r = 1.57079637f - r;
    if (x < 0.0f)
        r = 3.14159274f - r;
    return y < 0.0f ? -r : r;
}

//! An angle in a half-slice with its cosine and sine.
struct Angle {
    float theta = 0.0f; //!< radians from the view vector toward the upstream side, [0, pi]
    float c = 1.0f;
    float s = 0.0f;
};

inline Angle makeAngle(float c, float s)
{
    return {computeAtan2(s, c), c, s};
}

//! The half-slice of one direction at a receiver X: the plane through the eye that contains X
//! and the screen line through X along the sweep direction, restricted to the upstream side
//! (where the sweep's occluders lie). Directions w(theta) = cos(theta) v + sin(theta) t.
struct Slice {
    glm::vec3 v{0.0f}; //!< unit, from X toward the eye
    glm::vec3 t{0.0f}; //!< unit, perpendicular to v in the plane, toward -dir on screen
    glm::vec3 m{0.0f}; //!< unit normal of the plane
    float nv = 0.0f;   //!< dot(n, v)
    float nt = 0.0f;   //!< dot(n, t)
    //! A point at offset c along m moves into the plane along the receiver's tangent plane by
    //! c (kv v + kt t): k = dot(n, m) (nv, nt) / (nv^2 + nt^2), |k| <= 1000 (a half-slice
    //! weighs |(nv, nt)| in the integral, so the clamp only acts where it weighs < 1e-3).
    float kv = 0.0f;
    float kt = 0.0f;
    Angle lo;                   //!< where the hemisphere of n starts in the half-slice
    Angle hi;                   //!< where it ends (the tangent plane)
    float fHi = 0.0f;           //!< computeSliceF(hi)
    glm::vec3 gHi{0.0f};        //!< computeSliceG(hi)
    bool hasHemisphere = false; //!< false: the half-slice holds no direction of the hemisphere
};

//! Cosine-weighted measure of directions [0, a] of the half-slice, the integral of
//! dot(n, w) sin(theta) dtheta (solid angle in spherical coordinates around v).
inline float computeSliceF(const Slice& sl, const Angle& a)
{
    return sl.nv * (a.s * a.s) * 0.5f + sl.nt * (a.theta - a.s * a.c) * 0.5f;
}

//! The integral of w dot(n, w) sin(theta) dtheta over [0, a] (for the bent normal).
inline glm::vec3 computeSliceG(const Slice& sl, const Angle& a)
{
    const float c3 = a.c * a.c * a.c;
    const float s3 = a.s * a.s * a.s;
    const float gv = sl.nv * (1.0f - c3) * (1.0f / 3.0f) + sl.nt * s3 * (1.0f / 3.0f);
    const float gt = sl.nv * s3 * (1.0f / 3.0f) + sl.nt * (2.0f / 3.0f - a.c + c3 * (1.0f / 3.0f));
    return gv * sl.v + gt * sl.t;
}

//! The half-slice at view-space receiver `x` with unit normal `n` for the direction whose
//! view-space step is `axis`.
Slice makeSlice(const glm::vec3& x, const glm::vec3& n, const glm::vec3& axis);

//! An occluder point seen from the receiver in its half-slice.
struct Occluder {
    Angle angle;
    float distance = 0.0f; //!< world units, |p - x|
    bool valid = false;    //!< on the upstream side and not the receiver itself
    //! World units: where the occluder stands on the receiver's tangent plane (its foot is the
    //! visible surface, see findWallFoot), the distance from the receiver to the wall below it,
    //! measured in the slice along the tangent plane; the rays below the occluder then meet
    //! that wall at wall / cos(elevation). Infinity where no wall is known: every ray below the
    //! occluder takes the occluder's own distance.
    float wall = std::numeric_limits<float>::infinity();
};

//! Projects the view-space point `p` (a G-buffer sample, possibly from a neighbouring line)
//! into the half-slice of receiver `x` and takes its angle from v. With p - x = a v + b t + c m,
//! the point is moved into the slice plane along the receiver's tangent plane (the direction
//! m - dot(n, m) n_p / |n_p|^2 lies in it): a' = a + c kv, b' = b + c kt. That is exact for
//! samples of the receiver's own plane at any incidence (no false horizon from the offset of
//! neighbouring lines) and well-conditioned. The slice plane passes through the eye and
//! x = -|x| v, so c = p.m and b = p.t are taken relative to the eye: free of the rounding of x
//! (~1e-7 |x|), which would otherwise decide the side of points close to the receiver's eye ray.
//! Invalid when not upstream (b' <= 0) or closer than minDistance.
Occluder projectOccluder(const Slice& slice, const glm::vec3& x, const glm::vec3& p,
                         float minDistance);

// ---- Walls below occluders -----------------------------------------------------------------
// Screen-space horizons know where an occluder's top is, not what lies below it: the gather's
// model blocks every ray below an occluder at the occluder's own distance. Where a wall or a
// second plane meets the receiver's plane (a crease: a floor against a wall), the rays below the
// occluder's top meet the wall much nearer than its top, and with a distance falloff that is most
// of the occlusion; the top of a tall wall beyond the radius would count for nothing. The
// sweep's hull keeps only the top (the wall's lower samples are collinear with it in the
// projective plane, or below the chord to it). So the gather tests a hypothesis per occluder:
// a wall stands from the occluder down to the receiver's tangent plane. The hypothesis is
// accepted only when its foot, the occluder projected onto the tangent plane, is itself the
// visible surface in the depth buffer (the two planes really meet there; computeFootSupport). It is
// rejected where the foot is hidden, e.g. behind a foreground object in front of a wall facing the
// camera: the object stands off the wall, and the rays between them are free (the halo that a
// depth-thick wall would cast; the falloff by the occluder's own distance keeps that case).

//! The occluder's elevation above the tangent plane in the slice, and the foot of the
//! hypothetical wall below it: `height` = dot(p - x, n) above the plane (n unit), `foot` = p
//! projected along n onto the plane, `wall` = distance to the wall along the tangent plane in
//! the slice (o.distance cos(elevation)). `worth` is false where a wall could not change the
//! result: the occluder below the plane, or the wall beyond the radius everywhere.
struct WallFoot {
    glm::vec3 foot{0.0f};
    float height = 0.0f;
    float wall = std::numeric_limits<float>::infinity();
    bool worth = false;
};

inline WallFoot findWallFoot(const Slice& sl, const glm::vec3& x, const glm::vec3& n,
                             const glm::vec3& p, const Occluder& o, float radius)
{
    WallFoot f;
    if (!o.valid)
        return f;
    const float elevation = sl.hi.theta - o.angle.theta;
    f.height = glm::dot(p - x, n);
    if (!(sl.nv >= 0.0f) || !(elevation > 0.0f && elevation < 1.57079637f) ||
        !(f.height > 0.0f))
        return f;
    // cos(hi - theta) by the angle difference.
    f.wall = o.distance * (sl.hi.c * o.angle.c + sl.hi.s * o.angle.s);
    f.foot = p - f.height * n;
    f.worth = f.wall > 0.0f && f.wall < radius && f.foot.z < 0.0f;
    return f;
}

//! How far the foot at linear depth `footDepth` is the visible surface, whose depth at the foot's
//! screen position is `surfaceDepth` (the tangent plane of the pixel containing it), as the factor
//! the wall's distance is divided by: 1 within a tenth of the wall's height plus 1e-4 of the depth
//! (rounding of the projection), falling linearly to 0 (no wall) at twice that. A foreground
//! object hiding the foot stands off the plane by about the wall's height; the ramp keeps the
//! result continuous where a foot slides behind an edge.
inline float computeFootSupport(float footDepth, float surfaceDepth, float height)
{
    const float tolerance = 0.1f * height + 1e-4f * footDepth;
    return std::clamp(2.0f - std::fabs(surfaceDepth - footDepth) / tolerance, 0.0f, 1.0f);
}

//! A bound of the elevation range where a wall is the nearer hit: the elevation phi above the
//! tangent plane, its cosine and sine, and the slice measure F at the angle hi - phi.
struct WallBound {
    float phi = 0.0f;
    float c = 1.0f;
    float s = 0.0f;
    float f = 0.0f;
};

//! The bound at angle theta whose slice measure is f.
WallBound makeWallBound(const Slice& sl, const Angle& theta, float f);
//! The bound at the elevation whose cosine is x (in [0, 1]).
WallBound makeWallCutoff(const Slice& sl, float x);

//! The obscurance that a wall at distance a (in radii, along the tangent plane) adds over the
//! rays at elevations [lower.phi, upper.phi] above the tangent plane, beyond what they have with
//! weight `base`: the integral of (1 - rho(a / cos(phi)) - base) dF, in closed form
//! (lsao_core.cpp). Needs the slice's hemisphere to end at the tangent plane (nv >= 0), elevations
//! in [0, pi / 2) and a / cos(upper.phi) <= 1.
float computeWallObscurance(const Slice& sl, const WallBound& lower, const WallBound& upper,
                            float a, float base, bool smoothstep);

//! rho(distance / radius) as obscurance falloff: 1 at and beyond the radius.
inline float evaluateFalloff(float distance, float invRadius, bool smoothstep)
{
    const float x = distance * invRadius;
    if (!(x < 1.0f))
        return 1.0f;
    return smoothstep ? x * x * (3.0f - 2.0f * x) : x;
}

//! What one half-slice contributes: occluded measures (to be subtracted from the unoccluded
//! hemisphere) of the obscurance, of the visibility within the radius, and the visibility's
//! occluded first moment (for the bent normal).
struct Contribution {
    float obscurance = 0.0f;
    float visibility = 0.0f;
    glm::vec3 moment{0.0f};
};

//! The contribution of a half-slice with up to three occluders (invalid ones ignored; pass
//! Occluder{} for unused ones). A ray at angle theta is blocked by every occluder whose angle is
//! at most theta; it is weighted by 1 - rho of the nearest hit among those: the occluder's own
//! distance, or its wall's (wall / cos(elevation)) where it has one. Visibility: blocked by
//! those nearer than the radius (own distances; the walls are left out there, see the .cpp).
//! A 3-element sorting network, as in the shader.
Contribution evaluateOccluders(const Slice& slice, Occluder o0, Occluder o1, Occluder o2,
                               float radius, float invRadius, bool smoothstep);

//! Final outputs of a pixel from the sums of its half-slice contributions over all directions.
struct PixelResult {
    float ambient = 1.0f;
    glm::vec3 bentNormal{0.0f};
    float aperture = 0.0f;
};

PixelResult resolvePixel(const glm::vec3& n, float sumObscurance, float sumVisibility,
                         const glm::vec3& sumMoment, int directionCount);

} // namespace rtlab::occlusion::lsao
