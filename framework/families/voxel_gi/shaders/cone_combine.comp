#version 450
#extension GL_EXT_control_flow_attributes : require
// The final combine of a cone-traced gather on Vulkan, per full-resolution pixel: the 16 cone
// radiances of the reduced pixels around it upsampled with depth- and normal-aware weights (joint
// bilateral upsampling, Kopf et al. 2007), times the occlusion family's 16 visibilities and the
// characters' capsules' occlusion of each cone (Oat and Sander, "Ambient Aperture Lighting",
// I3D 2007), integrated with the pixel's irradiance weights. The same algorithm as
// voxelgi::combineCones (framework/families/voxel_gi/upsample.cpp), in float. The Tomorrow
// Children, GDC 2015 (shared/seeds/000_3da000e866ebc485.txt, "Trace at a lower resolution",
// "Screen Space Directional Occlusion", "Characters").
//
// With flags.w = 1 the same shader runs over the reduced pixels instead and multiplies their cone
// radiances by the capsules' visibility in place (upsample.h CapsuleResolution::Traced); the
// combine then runs with no capsules.
//
// The G-buffer arrives as the frame holds it (float positions, normals and depth, one word of
// material per pixel), so that the upload is a copy; positions are made relative to an anchor
// near the camera here, which is exact for the float inputs wherever the capsule tests matter.
// Compiled with GBUFFER_IMAGES it reads the G-buffer and the visibilities from the GPU images the
// frame keeps and writes an image (the resident combine); otherwise from uploaded buffers.

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

// [low pixel * 16 + cone]; written only by the capsules at the traced pixels (flags.w = 1).
layout(std430, binding = 0) buffer ConeBuffer { vec4 coneRadiance[]; };
layout(std430, binding = 1) readonly buffer RepresentativeBuffer { int representative[]; }; // [low pixel]: full pixel, -1: none
#ifdef GBUFFER_IMAGES
// The resident combine: the G-buffer and the visibilities as the frame keeps them on the GPU
// (voxel_gi.h VoxelGiGpuGBuffer; compose.h coneVisibilityGpuSlot), the irradiance into an image
// the lighting pass binds. No surface: an infinite depth (the G-buffer's clear value).
layout(binding = 2, rgba32f) uniform readonly image2D gPositionDepth; // xyz world, w linear depth
layout(binding = 3, rgba32f) uniform readonly image2D gNormal;
layout(binding = 9, rgba32f) uniform readonly image2D gVisibility0; // cone k: channel k % 4 of image k / 4
layout(binding = 10, rgba32f) uniform readonly image2D gVisibility1;
layout(binding = 11, rgba32f) uniform readonly image2D gVisibility2;
layout(binding = 12, rgba32f) uniform readonly image2D gVisibility3;
layout(binding = 8, rgba32f) uniform writeonly image2D outIrradiance;
#else
layout(std430, binding = 2) readonly buffer PositionBuffer { float positions[]; };  // 3 per full pixel, world
layout(std430, binding = 3) readonly buffer NormalBuffer { float normals[]; };      // 3 per full pixel
layout(std430, binding = 4) readonly buffer DepthBuffer { float depths[]; };        // linear depth, inf: none
layout(std430, binding = 5) readonly buffer MaterialBuffer { uint materials[]; };   // ~0u: no surface
layout(std430, binding = 6) readonly buffer VisibilityBuffer { float visibility[]; }; // [cone][full pixel]
layout(std430, binding = 8) writeonly buffer OutputBuffer { vec4 irradiance[]; }; // [full pixel]
#endif
// Per capsule, 4 vec4, relative to the anchor: (a, radius), (b - a, 1 / |b - a|^2 or 0),
// (centre of the segment, radius of the sphere around the capsule), (near^2, reach^2, 0, 0).
layout(std430, binding = 7) readonly buffer CapsuleBuffer { vec4 capsules[]; };
// The 16 directions as constants (scene/sky.h getConeDirections, defined by the caller), so that
// the unrolled loops over the cones read immediates rather than memory.
const vec3 kCones[16] = vec3[16](CONE_DIRECTIONS);

layout(push_constant) uniform Constants {
    ivec4 size;   // full width, height; low width, height
    ivec4 flags;  // x: factor, y: capsules, z: 1 = visibility given, w: 1 = the capsules at the traced pixels
    vec4 angle;   // cone half-angle, its cosine, its sine, 1 - its cosine
    vec4 anchor;  // xyz: what positions are made relative to
} pc;

const uint kNoMaterial = 0xffffffffu;

#ifdef GBUFFER_IMAGES
ivec2 toXy(int pixel)
{
    return ivec2(pixel % pc.size.x, pixel / pc.size.x);
}

vec3 readPosition(int pixel)
{
    return imageLoad(gPositionDepth, toXy(pixel)).xyz - pc.anchor.xyz;
}

vec3 readNormal(int pixel)
{
    return imageLoad(gNormal, toXy(pixel)).xyz;
}

float readDepth(int pixel)
{
    return imageLoad(gPositionDepth, toXy(pixel)).w;
}

bool hasSurface(int pixel)
{
    const float d = readDepth(pixel);
    return !isinf(d) && !isnan(d);
}

float readVisibility(int k, int pixel)
{
    const ivec2 p = toXy(pixel);
    const vec4 v = k < 4 ? imageLoad(gVisibility0, p)
                 : k < 8 ? imageLoad(gVisibility1, p)
                 : k < 12 ? imageLoad(gVisibility2, p) : imageLoad(gVisibility3, p);
    return v[k % 4];
}

void writeIrradiance(int pixel, vec3 e)
{
    imageStore(outIrradiance, toXy(pixel), vec4(e, 0.0));
}
#else
vec3 readPosition(int pixel)
{
    return vec3(positions[3 * pixel], positions[3 * pixel + 1], positions[3 * pixel + 2]) - pc.anchor.xyz;
}

vec3 readNormal(int pixel)
{
    return vec3(normals[3 * pixel], normals[3 * pixel + 1], normals[3 * pixel + 2]);
}

float readDepth(int pixel)
{
    return depths[pixel];
}

bool hasSurface(int pixel)
{
    return materials[pixel] != kNoMaterial;
}

float readVisibility(int k, int pixel)
{
    return visibility[k * pc.size.x * pc.size.y + pixel];
}

void writeIrradiance(int pixel, vec3 e)
{
    irradiance[pixel] = vec4(e, 0.0);
}
#endif

// Geometric similarity of low-resolution sample s to the pixel (p, n, view depth d): distance of
// the sample from the pixel's tangent plane against 2 % of the depth, and cos^8 of the normals.
float similarity(int s, vec3 p, vec3 n, float d)
{
    const int r = representative[s];
    if (r < 0)
        return 0.0;
    const float plane = abs(dot(n, readPosition(r) - p)) / max(0.02 * d, 1e-6);
    const float c = max(0.0, dot(n, readNormal(r)));
    const float c2 = c * c, c4 = c2 * c2;
    return exp(-plane * plane) * c4 * c4;
}

// upsample.cpp findUpsampleSamples: the four low-resolution samples around the pixel, bilinear
// times similarity; when all four fail, the most similar of the 3 x 3 around. Unused slots get
// weight 0 (and sample 0), so that callers sum all four without indexing by a count. Returns
// false for no sample.
bool findSamples(int x, int y, vec3 p, vec3 n, float d, out ivec4 samples, out vec4 weights)
{
    samples = ivec4(0);
    weights = vec4(0.0);
    const int f = pc.flags.x;
    const int lw = pc.size.z, lh = pc.size.w;
    if (f == 1) {
        samples.x = y * lw + x;
        weights.x = 1.0;
        return true;
    }
    const float u = (float(x) + 0.5) / float(f) - 0.5, v = (float(y) + 0.5) / float(f) - 0.5;
    const int i0 = int(floor(u)), j0 = int(floor(v));
    const float fu = u - float(i0), fv = v - float(j0);
    const int ia = clamp(i0, 0, lw - 1), ib = clamp(i0 + 1, 0, lw - 1);
    const int ja = clamp(j0, 0, lh - 1), jb = clamp(j0 + 1, 0, lh - 1);
    samples = ivec4(ja * lw + ia, ja * lw + ib, jb * lw + ia, jb * lw + ib);
    weights = vec4((1.0 - fu) * (1.0 - fv), fu * (1.0 - fv), (1.0 - fu) * fv, fu * fv) *
              vec4(similarity(samples.x, p, n, d), similarity(samples.y, p, n, d), similarity(samples.z, p, n, d),
                   similarity(samples.w, p, n, d));
    weights = max(weights, vec4(0.0));
    const float total = weights.x + weights.y + weights.z + weights.w;
    if (total > 1e-6) {
        weights /= total;
        return true;
    }
    const int ci = clamp(x / f, 0, lw - 1), cj = clamp(y / f, 0, lh - 1);
    float best = -1.0;
    int bestSample = -1;
    for (int j = max(0, cj - 1); j <= min(lh - 1, cj + 1); ++j)
        for (int i = max(0, ci - 1); i <= min(lw - 1, ci + 1); ++i) {
            const int s = j * lw + i;
            if (representative[s] < 0)
                continue;
            const float w = similarity(s, p, n, d) - 1e-3 * float(abs(i - ci) + abs(j - cj));
            if (w > best) {
                best = w;
                bestSample = s;
            }
        }
    samples = ivec4(max(bestSample, 0), 0, 0, 0);
    weights = vec4(bestSample >= 0 ? 1.0 : 0.0, 0.0, 0.0, 0.0);
    return bestSample >= 0;
}

// atan2(y, x) for y >= 0 in [0, pi], to a few float ulps. Vulkan lets the built-in atan, asin
// and sin be off by 4096 ulps (and sin by 2^-11 absolute), which the smoothstep below turns into
// 1e-3 of a capsule's occlusion; this uses only arithmetic. Reduced to t in [0, 1] by the octant,
// then to |t'| <= tan(pi / 12) by atan(t) = pi / 6 + atan((sqrt(3) t - 1) / (sqrt(3) + t)), then
// the Taylor series to t'^11 (remainder below 3e-9).
float preciseAtan2(float y, float x)
{
    const float ax = abs(x);
    const bool swapped = y > ax;
    float t = swapped ? ax / y : (ax > 0.0 ? y / ax : 0.0);
    float base = 0.0;
    if (t > 0.26794919) {
        t = (1.7320508 * t - 1.0) / (1.7320508 + t);
        base = 0.52359878;
    }
    const float t2 = t * t;
    float a = base + t * (1.0 + t2 * (-1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (-1.0 / 7.0 + t2 * (1.0 / 9.0 - t2 / 11.0)))));
    if (swapped)
        a = 1.57079633 - a;
    return x < 0.0 ? 3.14159265 - a : a;
}

vec3 closestOnSegment(vec3 q, vec3 a, vec3 u, float inverseLength2)
{
    return a + clamp(dot(q - a, u) * inverseLength2, 0.0, 1.0) * u;
}

// upsample.cpp occludeCone: the share of the cone (axis dir) from p that capsule c hides.
float occludeCone(vec3 p, vec3 dir, int c)
{
    const vec3 a = capsules[4 * c].xyz;
    const float r = capsules[4 * c].w;
    const vec3 u = capsules[4 * c + 1].xyz;
    const float inverseLength2 = capsules[4 * c + 1].w;
    const float uu = dot(u, u);
    // On or inside the capsule: its own character's surface is not occluded by it.
    if (length(p - closestOnSegment(p, a, u, inverseLength2)) <= 1.05 * r)
        return 0.0;
    // The point of the segment nearest the cone's axis (closest points of a segment and a ray);
    // a segment within float rounding of parallel to the axis takes its first end, as in C++.
    const vec3 w0 = a - p;
    const float ud = dot(u, dir), uw = dot(u, w0), dw = dot(dir, w0);
    const float denom = uu - ud * ud;
    const float s = denom > 1e-6 * uu ? clamp((ud * dw - uw) / denom, 0.0, 1.0) : 0.0;
    const float t = max(0.0, dot(a + s * u - p, dir));
    const vec3 toCentre = closestOnSegment(p + t * dir, a, u, inverseLength2) - p;
    const float distance = length(toCentre);
    if (!(distance > r))
        return 0.0;
    const float sinCap = min(1.0, r / distance), cosCap = sqrt(max(0.0, 1.0 - sinCap * sinCap));
    const float cosHalf = pc.angle.y, sinHalf = pc.angle.z;
    const float cosBetween = clamp(dot(toCentre / distance, dir), -1.0, 1.0);
    // Disjoint caps, tested on cosines (the margin keeps float rounding from returning 0 for a
    // touching cap; the exact test on angles below decides).
    if (cosBetween < cosHalf * cosCap - sinHalf * sinCap - 1e-5)
        return 0.0;
    // Solid angles / 2 pi: 1 - cos of the smaller angle, as sin^2 / (1 + cos) for the cap (1 - cos
    // loses most of a float's digits for the small caps of far capsules).
    const float coneSolid = pc.angle.w;
    const float smaller = cosCap > cosHalf ? sinCap * sinCap / (1.0 + cosCap) : coneSolid;
    if (cosBetween >= cosHalf * cosCap + sinHalf * sinCap)
        return clamp(smaller / coneSolid, 0.0, 1.0);
    // Between the two: Oat and Sander's smoothstep in the angle between the caps, the angles from
    // atan2 of well-conditioned pairs rather than acos and asin.
    const float capAngle = preciseAtan2(sinCap, cosCap);
    const float between = preciseAtan2(length(cross(toCentre, dir)), dot(toCentre, dir));
    const float outer = pc.angle.x + capAngle, inner = abs(pc.angle.x - capAngle);
    if (between >= outer)
        return 0.0;
    float share = 1.0;
    if (between > inner) {
        const float x = clamp(1.0 - (between - inner) / (outer - inner), 0.0, 1.0);
        share = x * x * (3.0 - 2.0 * x);
    }
    return clamp(smaller * share / coneSolid, 0.0, 1.0);
}

// Whether capsule c can hide part of a cone from p (within 40 radii of its segment, p not on
// it), with the cosine below which a cone direction's angle to the centre of the sphere around
// the capsule is too wide for the cone to touch it (-2: no such bound). upsample.cpp
// CapsuleOccluders::collect.
bool isCapsuleNear(vec3 p, int c, out vec3 towardCentre, out float cosLimit)
{
    towardCentre = vec3(0.0);
    cosLimit = -2.0;
    const vec4 centre = capsules[4 * c + 2];
    const vec4 reach = capsules[4 * c + 3];
    const vec3 toCentre = centre.xyz - p;
    const float d2 = dot(toCentre, toCentre);
    if (d2 >= reach.y)
        return false;
    const vec3 fromSegment = p - closestOnSegment(p, capsules[4 * c].xyz, capsules[4 * c + 1].xyz,
                                                 capsules[4 * c + 1].w);
    if (dot(fromSegment, fromSegment) >= reach.x)
        return false;
    if (d2 > centre.w * centre.w) {
        const float distance = sqrt(d2);
        const float sinB = centre.w / distance, cosB = sqrt(max(0.0, 1.0 - sinB * sinB));
        towardCentre = toCentre / distance;
        cosLimit = pc.angle.y * cosB - pc.angle.z * sinB;
    }
    return true;
}

// The capsules at the traced pixels (upsample.h CapsuleResolution::Traced): per reduced pixel,
// every non-zero cone radiance times the share of the cone the capsules leave open, in place,
// before the combine upsamples the cones (upsample.cpp occludeTracedCones).
void occludeTracedCones()
{
    const int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y);
    const int lw = pc.size.z, lh = pc.size.w;
    if (x >= lw || y >= lh)
        return;
    const int s = y * lw + x;
    const int r = representative[s];
    if (r < 0 || !hasSurface(r))
        return;
    const vec3 p = readPosition(r), n = readNormal(r);
    if (dot(n, n) < 0.5)
        return;
    float visible[16];
    [[unroll]] for (int k = 0; k < 16; ++k)
        visible[k] = 1.0;
    for (int c = 0; c < pc.flags.y; ++c) {
        vec3 towardCentre;
        float cosLimit;
        if (!isCapsuleNear(p, c, towardCentre, cosLimit))
            continue;
        [[unroll]] for (int k = 0; k < 16; ++k)
            if (coneRadiance[s * 16 + k].rgb != vec3(0.0) && dot(towardCentre, kCones[k]) >= cosLimit - 1e-5)
                visible[k] *= 1.0 - occludeCone(p, kCones[k], c);
    }
    [[unroll]] for (int k = 0; k < 16; ++k)
        if (visible[k] != 1.0)
            coneRadiance[s * 16 + k].rgb *= visible[k];
}

void main()
{
    if (pc.flags.w == 1) {
        occludeTracedCones();
        return;
    }
    const int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y);
    const int w = pc.size.x, h = pc.size.y;
    if (x >= w || y >= h)
        return;
    const int pixel = y * w + x;
    writeIrradiance(pixel, vec3(0.0));
    if (!hasSurface(pixel))
        return;
    const vec3 p = readPosition(pixel), n = readNormal(pixel);
    const float depth = readDepth(pixel);
    const float d = isinf(depth) || isnan(depth) ? 1.0 : depth;
    ivec4 samples;
    vec4 weights;
    if (!findSamples(x, y, p, n, d, samples, weights) || dot(n, n) < 0.5)
        return;
    // cone_tracing.cpp computeIrradianceWeights: the clamped cosines, scaled to sum to pi. The
    // loops over the 16 cones are unrolled so that their arrays stay in registers.
    float coneWeight[16];
    float visible[16];
    float sum = 0.0;
    [[unroll]] for (int k = 0; k < 16; ++k) {
        coneWeight[k] = max(0.0, dot(kCones[k], n));
        sum += coneWeight[k];
        visible[k] = 1.0;
    }
    if (pc.flags.z != 0)
        [[unroll]] for (int k = 0; k < 16; ++k)
            visible[k] = clamp(readVisibility(k, pixel), 0.0, 1.0);
    // The capsules in order (as the C++ combine multiplies them per cone): those within 40 radii
    // of the pixel, and in them the cones that can reach the sphere around the capsule.
    for (int c = 0; c < pc.flags.y; ++c) {
        vec3 towardCentre;
        float cosLimit;
        if (!isCapsuleNear(p, c, towardCentre, cosLimit))
            continue;
        [[unroll]] for (int k = 0; k < 16; ++k)
            if (coneWeight[k] > 0.0 && dot(towardCentre, kCones[k]) >= cosLimit - 1e-5)
                visible[k] *= 1.0 - occludeCone(p, kCones[k], c);
    }
    vec3 e = vec3(0.0);
    const float scale = sum > 0.0 ? 3.14159265358979 / sum : 0.0;
    [[unroll]] for (int k = 0; k < 16; ++k) {
        if (coneWeight[k] == 0.0)
            continue;
        const vec3 radiance = weights.x * coneRadiance[samples.x * 16 + k].rgb +
                              weights.y * coneRadiance[samples.y * 16 + k].rgb +
                              weights.z * coneRadiance[samples.z * 16 + k].rgb +
                              weights.w * coneRadiance[samples.w * 16 + k].rgb;
        e += (coneWeight[k] * scale) * visible[k] * radiance;
    }
    writeIrradiance(pixel, max(e, vec3(0.0)));
}
