// Line-Sweep Ambient Obscurance: what lsao_sweep.comp and lsao_gather.comp share. The GLSL twin of
// lsao_core.h / lsao_core.cpp (same formulas, same order of operations). Values that decide
// discrete choices (sample positions, hull pops, bracketing) are computed into `precise`
// variables so that no operation is fused or reordered, as in the C++ build (no contraction).
// Defines: LSAO_HULL_CAPACITY (power of two, = kHullCapacity); LSAO_WALLS (0 or 1,
// Params::walls), LSAO_SMOOTHSTEP (0 or 1, Params::falloff) and LSAO_GATHER_NEAREST (0 or 1,
// Params::gather, read by lsao_gather.comp): the code of the options not taken is left out,
// since lavapipe runs every branch of a shader for every lane; LSAO_INTERLEAVE
// (Layout::interleave, read by lsao_resolve.comp), so that the resolve's window loops unroll.
#ifndef LSAO_COMMON_GLSL
#define LSAO_COMMON_GLSL

#include <screen_space.glsl>

#define LSAO_NO_OCCLUDER 0xffffffffu
#define LSAO_FLAG_JITTER 1u
#define LSAO_FLAG_NEAR_FIELD 2u
#define LSAO_FLAG_SMOOTHSTEP 4u
#define LSAO_FLAG_FIRST_BATCH 8u
#define LSAO_FLAG_LAST_BATCH 16u

// lsao::Constants (96 bytes).
layout(push_constant) uniform Constants
{
    vec2 projScale;
    vec2 projOffset;
    vec2 size;
    vec2 invScale;
    vec2 invSize;
    int width;
    int height;
    float spacing;
    float invSpacing;
    float step;
    float invStep;
    float radius;
    float invRadius;
    uint dirBegin;
    uint dirEnd;
    uint dirCount;
    uint flags;
    uint setIndex;
    uint interleave;
} pc;

// lsao::Direction (std430, 64 bytes).
struct Direction {
    vec2 dir;
    vec2 perp;
    vec4 axis;
    float tMin;
    float cMin;
    uint lineCount;
    uint stepCount;
    uint base;
    uint pad0;
    uint pad1;
    uint pad2;
};

layout(set = 0, binding = 0, r32f) uniform readonly image2D depthImage;
layout(std430, set = 0, binding = 1) readonly buffer Directions { Direction directions[]; };
layout(set = 0, binding = 3, rgba32f) uniform readonly image2D normalImage;

#define LSAO_INF uintBitsToFloat(0x7f800000u)

// ---- Interleaved directions (lsao::computePixelClass and the rest) --------------------------

uint lsaoPixelClass(ivec2 pixel, int n)
{
    return uint(pixel.x % n + n * (pixel.y % n));
}

uint lsaoClassDirections(uint pixelClass, uint directionCount, int n)
{
    uint classes = uint(n * n);
    return directionCount / classes + (pixelClass < directionCount % classes ? 1u : 0u);
}

// lsao::isSameSurface, operation for operation, with the receiver's terms computed once.
struct SurfaceReceiver {
    float z;
    vec3 n;
    float len; // |n|^2
    float ux;
    float uy;
};

SurfaceReceiver lsaoMakeSurfaceReceiver(vec2 pixelI, float zi, vec3 ni)
{
    precise float lenI = ni.x * ni.x + ni.y * ni.y + ni.z * ni.z;
    precise float uxi = zi * ((pixelI.x * pc.invSize.x * 2.0 - 1.0) + pc.projOffset.x);
    precise float uyi = zi * ((pixelI.y * pc.invSize.y * 2.0 - 1.0) + pc.projOffset.y);
    return SurfaceReceiver(zi, ni, lenI, uxi, uyi);
}

bool lsaoIsSameSurface(SurfaceReceiver r, vec2 pixelJ, float zj, vec3 nj)
{
    vec3 ni = r.n;
    precise float dn = ni.x * nj.x + ni.y * nj.y + ni.z * nj.z;
    precise float lenJ = nj.x * nj.x + nj.y * nj.y + nj.z * nj.z;
    precise float cosBound = 0.81 * (r.len * lenJ);
    precise float dn2 = dn * dn;
    if (!(dn > 0.0) || !(dn2 >= cosBound))
        return false;
    precise float uxj = zj * ((pixelJ.x * pc.invSize.x * 2.0 - 1.0) + pc.projOffset.x);
    precise float uyj = zj * ((pixelJ.y * pc.invSize.y * 2.0 - 1.0) + pc.projOffset.y);
    precise float dx = (uxj - r.ux) * pc.projScale.y;
    precise float dy = (uyj - r.uy) * pc.projScale.x;
    precise float dz = (r.z - zj) * (pc.projScale.x * pc.projScale.y);
    precise float plane = ni.x * dx + ni.y * dy + ni.z * dz;
    precise float separation2 = dx * dx + dy * dy + dz * dz;
    precise float plane2 = plane * plane;
    precise float bound = 0.015625 * (separation2 * r.len);
    return plane2 <= bound;
}

// ---- Line layout and jitter -----------------------------------------------------------------

uint lsaoMixHash(uint h, uint value)
{
    h ^= value * 0x9e3779b9u;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return h;
}

// The first two rounds of lsao::computeStepJitter's hash, which depend on the line only: computed
// once per line, the same integers.
uint lsaoLineHash(uint direction, uint line)
{
    return lsaoMixHash(lsaoMixHash(0x4c53414fu, direction), line);
}

float lsaoStepJitter(uint lineHash, uint stepIndex)
{
    if ((pc.flags & LSAO_FLAG_JITTER) == 0u)
        return 0.5;
    uint h = lsaoMixHash(lineHash, stepIndex);
    h = lsaoMixHash(h, pc.setIndex);
    return float(h >> 8) * (1.0 / 16777216.0);
}

float lsaoLineOffset(Direction d, uint line)
{
    precise float c = d.cMin + float(line) * pc.spacing;
    return c;
}

struct LineSample {
    bool exists;
    int stratum;
    float t;
    ivec2 pixel;
};

LineSample lsaoLocateSample(Direction d, uint lineHash, float c, int stratum)
{
    LineSample s;
    s.exists = false;
    s.stratum = stratum;
    s.t = 0.0;
    s.pixel = ivec2(-1);
    if (stratum < 0 || stratum >= int(d.stepCount))
        return s;
    float xi = lsaoStepJitter(lineHash, uint(stratum));
    precise float t = d.tMin + (float(stratum) + xi) * pc.step;
    precise float px = t * d.dir.x + c * d.perp.x;
    precise float py = t * d.dir.y + c * d.perp.y;
    s.t = t;
    s.pixel = ivec2(int(floor(px)), int(floor(py)));
    s.exists = s.pixel.x >= 0 && s.pixel.y >= 0 && s.pixel.x < pc.width && s.pixel.y < pc.height;
    return s;
}

// Linear depth of `pixel`, or 0 for sky, invalid depth or outside the image.
float lsaoLoadDepth(ivec2 pixel)
{
    if (pixel.x < 0 || pixel.y < 0 || pixel.x >= pc.width || pixel.y >= pc.height)
        return 0.0;
    float z = imageLoad(depthImage, pixel).r;
    return z > 0.0 && z < LSAO_INF ? z : 0.0;
}

bool lsaoHasSurface(float depth, vec3 normal)
{
    return depth > 0.0 && depth < LSAO_INF && dot(normal, normal) > 1e-12;
}

// lsao::computeSampleHeight: 1/depth = h.x / h.y of the line point q, from the tangent plane
// of its pixel (centre depth z, normal n), else 1/z; h.z = 1 when on the line
// (SampleHeight::onLine).
vec3 lsaoSampleHeight(vec2 q, ivec2 pixel, float z, vec3 n)
{
    float cx = float(pixel.x) + 0.5;
    float cy = float(pixel.y) + 0.5;
    precise float px = z * (((2.0 * cx) * pc.invSize.x - 1.0 + pc.projOffset.x) * pc.invScale.x);
    precise float py = z * (((2.0 * cy) * pc.invSize.y - 1.0 + pc.projOffset.y) * pc.invScale.y);
    precise float rx = ((2.0 * q.x) * pc.invSize.x - 1.0 + pc.projOffset.x) * pc.invScale.x;
    precise float ry = ((2.0 * q.y) * pc.invSize.y - 1.0 + pc.projOffset.y) * pc.invScale.y;
    precise float a = rx * n.x + ry * n.y - n.z;
    precise float b = px * n.x + py * n.y - z * n.z;
    if (b < 0.0) {
        a = -a;
        b = -b;
    }
    precise float az = a * z;
    precise float halfB = 0.5 * b;
    precise float twiceB = 2.0 * b;
    if (b > 0.0 && a > 0.0 && az >= halfB && az <= twiceB)
        return vec3(a, b, 1.0);
    return vec3(1.0, z, 0.0);
}

// ---- Occluder hull [Timonen 2013: occluder hull] --------------------------------------------

// B on or below the chord A -> C in (t, 1/depth), 1/depth = h.x / h.y, multiplied through by
// hA.y hB.y hC.y > 0.
bool lsaoIsOnOrBelowChord(float tA, vec2 hA, float tB, vec2 hB, float tC, vec2 hC)
{
    precise float lhs = ((hB.x * hA.y - hA.x * hB.y) * hC.y) * (tC - tA);
    precise float rhs = ((hC.x * hA.y - hA.x * hC.y) * hB.y) * (tB - tA);
    return lhs <= rhs;
}

// ---- Per-direction obscurance of the gather ------------------------------------------------

float lsaoAtan2(float y, float x)
{
    float ax = abs(x);
    float ay = abs(y);
    float hi = max(ax, ay);
    float lo = min(ax, ay);
    float a = hi > 0.0 ? lo / hi : 0.0;
    float s = a * a;
    float r = -0.0117212;
    r = r * s + 0.05265332;
    r = r * s - 0.11643287;
    r = r * s + 0.19354346;
    r = r * s - 0.33262347;
    r = r * s + 0.99997726;
    r = r * a;
    if (ay > ax)
        r = 1.57079637 - r;
    if (x < 0.0)
        r = 3.14159274 - r;
    return y < 0.0 ? -r : r;
}

struct Angle {
    float theta;
    float c;
    float s;
};

Angle lsaoMakeAngle(float c, float s)
{
    return Angle(lsaoAtan2(s, c), c, s);
}

struct Slice {
    vec3 v;
    vec3 t;
    vec3 m;
    float nv;
    float nt;
    float kv;
    float kt;
    Angle lo;
    Angle hi;
    float fHi;
    vec3 gHi;
    bool hasHemisphere;
};

float lsaoSliceF(Slice sl, Angle a)
{
    return sl.nv * (a.s * a.s) * 0.5 + sl.nt * (a.theta - a.s * a.c) * 0.5;
}

vec3 lsaoSliceG(Slice sl, Angle a)
{
    float c3 = a.c * a.c * a.c;
    float s3 = a.s * a.s * a.s;
    float gv = sl.nv * (1.0 - c3) * (1.0 / 3.0) + sl.nt * s3 * (1.0 / 3.0);
    float gt = sl.nv * s3 * (1.0 / 3.0) + sl.nt * (2.0 / 3.0 - a.c + c3 * (1.0 / 3.0));
    return gv * sl.v + gt * sl.t;
}

Slice lsaoMakeSlice(vec3 x, vec3 n, vec3 axis)
{
    Slice sl;
    sl.v = normalize(-x);
    vec3 u = axis - dot(axis, sl.v) * sl.v;
    sl.t = -normalize(u);
    sl.m = cross(sl.v, sl.t);
    sl.kv = 0.0;
    sl.kt = 0.0;
    sl.nv = dot(n, sl.v);
    sl.nt = dot(n, sl.t);
    sl.lo = Angle(0.0, 1.0, 0.0);
    sl.hi = Angle(0.0, 1.0, 0.0);
    sl.fHi = 0.0;
    sl.gHi = vec3(0.0);
    sl.hasHemisphere = false;
    float np = sqrt(sl.nv * sl.nv + sl.nt * sl.nt);
    if (!(np > 1e-6))
        return sl;
    float cn = sl.nv / np;
    float sn = sl.nt / np;
    if (sl.nv >= 0.0) {
        sl.lo = Angle(0.0, 1.0, 0.0);
        sl.hi = lsaoMakeAngle(-sn, cn);
    } else if (sl.nt > 0.0) {
        sl.lo = lsaoMakeAngle(sn, -cn);
        sl.hi = Angle(3.14159274, -1.0, 0.0);
    } else {
        return sl;
    }
    sl.hasHemisphere = sl.hi.theta > sl.lo.theta;
    sl.fHi = lsaoSliceF(sl, sl.hi);
    sl.gHi = lsaoSliceG(sl, sl.hi);
    float slope = clamp(dot(n, sl.m) / np, -1000.0, 1000.0);
    sl.kv = slope * cn;
    sl.kt = slope * sn;
    return sl;
}

struct Occluder {
    Angle angle;
    float distance;
    bool valid;
    float wall; // lsao::Occluder::wall: LSAO_INF where no wall is known
};

Occluder lsaoNoOccluder()
{
    return Occluder(Angle(0.0, 1.0, 0.0), 0.0, false, LSAO_INF);
}

// lsao::projectOccluder: moved into the slice along the tangent plane; c and b eye-relative.
Occluder lsaoProjectOccluder(Slice sl, vec3 x, vec3 p, float minDistance)
{
    Occluder o = lsaoNoOccluder();
    float c = dot(p, sl.m);
    float a = dot(p - x, sl.v) + c * sl.kv;
    float b = dot(p, sl.t) + c * sl.kt;
    float r = sqrt(a * a + b * b);
    o.distance = length(p - x);
    if (!(b > 0.0) || !(r > minDistance))
        return o;
    o.angle = lsaoMakeAngle(a / r, b / r);
    o.valid = true;
    return o;
}

// lsao::WallFoot / findWallFoot: the foot of the wall below occluder o (point p) on the
// receiver's tangent plane (x, unit n); worth = false where a wall could not change the result.
struct WallFoot {
    vec3 foot;
    float height;
    float wall;
    bool worth;
};

WallFoot lsaoFindWallFoot(Slice sl, vec3 x, vec3 n, vec3 p, Occluder o)
{
    WallFoot f = WallFoot(vec3(0.0), 0.0, LSAO_INF, false);
    if (!o.valid)
        return f;
    float elevation = sl.hi.theta - o.angle.theta;
    f.height = dot(p - x, n);
    if (!(sl.nv >= 0.0) || !(elevation > 0.0 && elevation < 1.57079637) || !(f.height > 0.0))
        return f;
    f.wall = o.distance * (sl.hi.c * o.angle.c + sl.hi.s * o.angle.s);
    f.foot = p - f.height * n;
    f.worth = f.wall > 0.0 && f.wall < pc.radius && f.foot.z < 0.0;
    return f;
}

// lsao::computeFootSupport.
float lsaoFootSupport(float footDepth, float surfaceDepth, float height)
{
    float tolerance = 0.1 * height + 1e-4 * footDepth;
    return clamp(2.0 - abs(surfaceDepth - footDepth) / tolerance, 0.0, 1.0);
}

float lsaoFalloff(float distance)
{
    float x = distance * pc.invRadius;
    if (!(x < 1.0))
        return 1.0;
#if LSAO_SMOOTHSTEP
    return x * x * (3.0 - 2.0 * x);
#else
    return x;
#endif
}

struct Contribution {
    float obscurance;
    float visibility;
    vec3 moment;
};

Angle lsaoClampAngle(Slice sl, Angle a)
{
    if (a.theta <= sl.lo.theta)
        return sl.lo;
    if (a.theta >= sl.hi.theta)
        return sl.hi;
    return a;
}

Occluder lsaoPrepareOccluder(Occluder o)
{
    return o.valid ? o : Occluder(Angle(4.0, 1.0, 0.0), LSAO_INF, false, LSAO_INF);
}

// lsao::WallBound: (phi, cos phi, sin phi, F at hi - phi).
vec4 lsaoWallBound(Slice sl, Angle theta, float f)
{
    return vec4(sl.hi.theta - theta.theta, sl.hi.c * theta.c + sl.hi.s * theta.s,
                sl.hi.s * theta.c - sl.hi.c * theta.s, f);
}

vec4 lsaoWallCutoff(Slice sl, float x)
{
    float s = sqrt(max(0.0, 1.0 - x * x));
    float phi = lsaoAtan2(s, x);
    Angle theta = Angle(sl.hi.theta - phi, sl.hi.c * x + sl.hi.s * s, sl.hi.s * x - sl.hi.c * s);
    return vec4(phi, x, s, lsaoSliceF(sl, theta));
}

// lsao::computeWallObscurance: closed form, see lsao_core.cpp. Terms (a np I1, a^2 np I2,
// a^3 np I3) at bound w.
vec3 lsaoWallTerms(Slice sl, vec4 w, float a)
{
    float as = a / w.y;
    float logSecTan = log((1.0 + w.z) / w.y);
    vec3 t = vec3(a * (-sl.nv * w.y + sl.nt * (logSecTan - w.z)), 0.0, 0.0);
#if LSAO_SMOOTHSTEP
    {
        t.y = a * a * (-sl.nv * log(w.y) + sl.nt * (w.z / w.y - w.x));
        t.z = a * a * sl.nv * as + sl.nt * (as * as * a * w.z - a * a * a * logSecTan) * 0.5;
    }
#endif
    return t;
}

float lsaoWallObscurance(Slice sl, vec4 lower, vec4 upper, float a, float base)
{
    vec3 lo = lsaoWallTerms(sl, lower, a);
    vec3 hi = lsaoWallTerms(sl, upper, a);
    float measure = max(0.0, lower.w - upper.w);
#if LSAO_SMOOTHSTEP
    float weighted = measure - 3.0 * (hi.y - lo.y) + 2.0 * (hi.z - lo.z);
#else
    float weighted = measure - (hi.x - lo.x);
#endif
    return max(0.0, weighted - base * measure);
}

// lsao::integrateInterval: the rays in [a, b] weighted by 1 - rho of
// min(distance, wall / cos(elevation)).
float lsaoIntegrateInterval(Slice sl, Angle a, Angle b, float fa, float fb, float distance,
                            float wall)
{
    float base = 1.0 - lsaoFalloff(distance);
    float sum = base * max(0.0, fb - fa);
#if LSAO_WALLS
    float limit = min(distance, 1.0 / pc.invRadius);
    if (!(wall < limit) || !(fb > fa))
        return sum;
    vec4 lower = lsaoWallBound(sl, b, fb);
    vec4 cutoff = lsaoWallCutoff(sl, wall / limit);
    vec4 top = lsaoWallBound(sl, a, fa);
    vec4 upper = cutoff.x < top.x ? cutoff : top;
    if (!(upper.x > lower.x))
        return sum;
    return sum + lsaoWallObscurance(sl, lower, upper, wall * pc.invRadius, base);
#else
    return sum;
#endif
}

// lsao::evaluateOccluders: up to three occluders, a branch-free sorting network.
Contribution lsaoEvaluateOccluders(Slice sl, Occluder o0, Occluder o1, Occluder o2)
{
    o0 = lsaoPrepareOccluder(o0);
    o1 = lsaoPrepareOccluder(o1);
    o2 = lsaoPrepareOccluder(o2);
    Occluder tmp;
    if (o0.angle.theta > o1.angle.theta) {
        tmp = o0;
        o0 = o1;
        o1 = tmp;
    }
    if (o1.angle.theta > o2.angle.theta) {
        tmp = o1;
        o1 = o2;
        o2 = tmp;
    }
    if (o0.angle.theta > o1.angle.theta) {
        tmp = o0;
        o0 = o1;
        o1 = tmp;
    }
    Angle a0 = lsaoClampAngle(sl, o0.angle);
    Angle a1 = lsaoClampAngle(sl, o1.angle);
    Angle a2 = lsaoClampAngle(sl, o2.angle);
    float f0 = lsaoSliceF(sl, a0);
    float f1 = lsaoSliceF(sl, a1);
    float f2 = lsaoSliceF(sl, a2);
    // [Timonen 2013: obscurance; Zhukov 1998] rays from each occluder's horizon to the tangent
    // plane are weighted by 1 - rho of the nearest hit above them (an occluder, or its wall).
    float n0 = o0.distance;
    float n1 = min(n0, o1.distance);
    float n2 = min(n1, o2.distance);
    float w0 = o0.wall;
    float w1 = min(w0, o1.wall);
    float w2 = min(w1, o2.wall);
    Contribution c = Contribution(0.0, 0.0, vec3(0.0));
    c.obscurance = lsaoIntegrateInterval(sl, a0, a1, f0, f1, n0, w0) +
                   lsaoIntegrateInterval(sl, a1, a2, f1, f2, n1, w1) +
                   lsaoIntegrateInterval(sl, a2, sl.hi, f2, sl.fHi, n2, w2);
    // Visibility without the walls (see lsao::evaluateOccluders).
    bool in0 = o0.distance < pc.radius;
    bool in1 = o1.distance < pc.radius;
    bool in2 = o2.distance < pc.radius;
    if (in0 || in1 || in2) {
        Angle a = in0 ? a0 : (in1 ? a1 : a2);
        float f = in0 ? f0 : (in1 ? f1 : f2);
        c.visibility = max(0.0, sl.fHi - f);
        c.moment = sl.gHi - lsaoSliceG(sl, a);
    }
    return c;
}

struct PixelResult {
    float ambient;
    vec3 bentNormal;
    float aperture;
};

PixelResult lsaoResolvePixel(vec3 n, float sumObscurance, float sumVisibility, vec3 sumMoment)
{
    PixelResult r;
    float scale = 2.0 / float(pc.dirCount);
    r.ambient = clamp(1.0 - scale * sumObscurance, 0.0, 1.0);
    float visible = clamp(1.0 - scale * sumVisibility, 0.0, 1.0);
    vec3 b = n - (3.0 / float(pc.dirCount)) * sumMoment;
    float bl = length(b);
    r.bentNormal = visible > 0.0 && bl > 1e-3 ? b / bl : n; // see lsao::resolvePixel
    r.aperture = lsaoAtan2(sqrt(visible), sqrt(1.0 - visible));
    return r;
}

#endif
