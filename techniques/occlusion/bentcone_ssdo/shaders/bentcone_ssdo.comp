// bentcone_ssdo.main: screen-space directional occlusion into 2-band SH, converted to a bent cone
// and intersected with the 16 cone-tracing directions. One invocation per pixel.
// The GLSL twin of bentcone_ssdo_cpu.cpp (shadePixel) and bentcone_ssdo_math.cpp: the same
// operations in the same order, `precise` so that no multiply-add is fused, which keeps the
// sample classification of both paths identical.
#version 450
#include <screen_space.glsl>

layout(local_size_x = 8, local_size_y = 8) in;

layout(push_constant) uniform Params {
    vec2 projScale;   // (p[0][0], p[1][1])
    vec2 projOffset;  // (p[2][0], p[2][1]), jitter
    vec2 size;        // image size in pixels
    float radius;     // world units
    float depthBias;  // fraction of the sample's linear depth
    float shWeight;   // pi / N
    int sampleCount;  // N
    int coneMode;     // 0 exact, 1 smoothstep
    float padding;
    vec4 coneCap;     // direction cones: (half-angle, cos = 7/8, sin, versine = 1/8)
} params;

layout(set = 0, binding = 0, r32f) uniform readonly image2D uDepth;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D uNormal;
// rotations[16] (xy = cos, sin per 4x4 cell), cones[16] (xyz, view space), pattern[N],
// apertures[N + 1] (bent cone of each visible count: angle, cos, sin, versine)
layout(set = 0, binding = 2, std430) readonly buffer Frame { vec4 frameData[]; };
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D uBentAmbient;  // bent xyz, A
layout(set = 0, binding = 4, r32f) uniform writeonly image2D uAperture;
layout(set = 0, binding = 5, rgba32f) uniform writeonly image2D uVisibility0;  // cones 0..3
layout(set = 0, binding = 6, rgba32f) uniform writeonly image2D uVisibility1;  // cones 4..7
layout(set = 0, binding = 7, rgba32f) uniform writeonly image2D uVisibility2;  // cones 8..11
layout(set = 0, binding = 8, rgba32f) uniform writeonly image2D uVisibility3;  // cones 12..15

const float kPi = 3.14159265358979323846;
const float kShY00 = 0.282095;
const float kShY1 = 0.488603;
const float kFloatMax = 3.402823466e38;
const int kRotationBase = 0;
const int kConeBase = 16;
const int kPatternBase = 32;

bool isSurfaceDepth(float depth)
{
    return depth > 0.0 && depth < kFloatMax;
}

// Solid angle of two intersecting caps (angle, cos, sin, versine) whose axes are the angle
// with cosine cosD and sine sinD apart (bentcone_ssdo_math.cpp, intersectCaps).
float intersectCaps(float cosD, float sinD, vec4 a, vec4 b)
{
    float smallerCap = 2.0 * kPi * min(a.w, b.w);
    float oneMinusCosD = cosD > 0.0 ? sinD * sinD / (1.0 + cosD) : 1.0 - cosD;
    float onePlusCosD = cosD < 0.0 ? sinD * sinD / (1.0 - cosD) : 1.0 + cosD;
    float sinDifference = a.z * b.y - a.y * b.z;
    float cosDifference = a.y * b.y + a.z * b.z;
    float oneMinusCosDifference = sinDifference * sinDifference / (1.0 + cosDifference);
    float sinSum = a.z * b.y + a.y * b.z;
    float cosSum = a.y * b.y - a.z * b.z;
    float onePlusCosSum = cosSum < 0.0 ? sinSum * sinSum / (1.0 - cosSum) : 1.0 + cosSum;
    float inner = oneMinusCosD - oneMinusCosDifference;
    float outer = onePlusCosD - onePlusCosSum;
    if (inner <= 0.0)
        return smallerCap;
    if (outer <= 0.0)
        return 0.0;
    if (params.coneMode == 1) {
        float d = atan(sinD, cosD);
        float lo = abs(a.x - b.x);
        float hi = a.x + b.x;
        float x = clamp(1.0 - (d - lo) / (hi - lo), 0.0, 1.0);
        return smallerCap * (x * x * (3.0 - 2.0 * x));
    }
    float r = sqrt(inner * outer);
    float betaA = atan(r, (a.w - b.w) + a.y * oneMinusCosD);
    float betaB = atan(r, (b.w - a.w) + b.y * oneMinusCosD);
    float excess = 2.0 * atan(r, (onePlusCosD + a.y) + b.y);
    float omega = 2.0 * ((a.w * betaA + b.w * betaB) - excess);
    return clamp(omega, 0.0, smallerCap);
}

float computeConeVisibility(vec3 direction, vec3 axis, vec4 bent, vec3 n)
{
    const vec4 hemisphere = vec4(0.5 * kPi, 0.0, 1.0, 1.0);
    float coneArea = 2.0 * kPi * params.coneCap.w;
    float aboveSurface =
        intersectCaps(dot(direction, n), length(cross(direction, n)), params.coneCap, hemisphere);
    if (aboveSurface <= 0.0)
        return 0.0;
    float inBent =
        intersectCaps(dot(direction, axis), length(cross(direction, axis)), params.coneCap, bent);
    return clamp(min(inBent, aboveSurface) / coneArea, 0.0, 1.0);
}

void main()
{
    ivec2 pix = ivec2(gl_GlobalInvocationID.xy);
    ivec2 extent = ivec2(params.size);
    if (pix.x >= extent.x || pix.y >= extent.y)
        return;

    float centreDepth = imageLoad(uDepth, pix).r;
    vec3 normalIn = imageLoad(uNormal, pix).xyz;
    precise float length2 =
        normalIn.x * normalIn.x + normalIn.y * normalIn.y + normalIn.z * normalIn.z;
    if (!isSurfaceDepth(centreDepth) || !(length2 > 1e-12 && length2 < 1e30)) {
        imageStore(uBentAmbient, pix, vec4(0.0, 0.0, 0.0, 1.0));
        imageStore(uAperture, pix, vec4(0.0));
        imageStore(uVisibility0, pix, vec4(1.0));
        imageStore(uVisibility1, pix, vec4(1.0));
        imageStore(uVisibility2, pix, vec4(1.0));
        imageStore(uVisibility3, pix, vec4(1.0));
        return;
    }
    precise float inverseLength = 1.0 / sqrt(length2);
    precise vec3 n = vec3(normalIn.x * inverseLength, normalIn.y * inverseLength,
                          normalIn.z * inverseLength);
    precise vec3 p = screenToView(vec2(pix) + 0.5, centreDepth, params.projScale,
                                  params.projOffset, params.size);

    // Tangent frame [Duff et al. 2017], turned by the pixel's 4x4 cell rotation.
    float sgn = n.z >= 0.0 ? 1.0 : -1.0;
    precise float a = -1.0 / (sgn + n.z);
    precise float b = n.x * n.y * a;
    precise vec3 t = vec3(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
    precise vec3 bt = vec3(b, sgn + n.y * n.y * a, -n.y);
    vec2 rotation = frameData[kRotationBase + (pix.y & 3) * 4 + (pix.x & 3)].xy;
    precise vec3 tr = vec3(rotation.x * t.x + rotation.y * bt.x,
                           rotation.x * t.y + rotation.y * bt.y,
                           rotation.x * t.z + rotation.y * bt.z);
    precise vec3 br = vec3(rotation.x * bt.x - rotation.y * t.x,
                           rotation.x * bt.y - rotation.y * t.y,
                           rotation.x * bt.z - rotation.y * t.z);

    float visible = 0.0;
    precise vec3 sum = vec3(0.0);
    for (int k = 0; k < params.sampleCount; ++k) {
        vec4 s = frameData[kPatternBase + k];
        precise float len = params.radius * s.w;
        precise float ox = s.x * len;
        precise float oy = s.y * len;
        precise float oz = s.z * len;
        precise vec3 q = vec3(p.x + ((ox * tr.x + oy * br.x) + oz * n.x),
                              p.y + ((ox * tr.y + oy * br.y) + oz * n.y),
                              p.z + ((ox * tr.z + oy * br.z) + oz * n.z));
        float sampleDepth = -q.z;
        bool occluded = false;
        if (sampleDepth > 0.0) {
            precise vec2 pixel = viewToScreen(q, params.projScale, params.projOffset, params.size);
            if (pixel.x >= 0.0 && pixel.y >= 0.0 && pixel.x < params.size.x &&
                pixel.y < params.size.y) {
                ivec2 occluderPixel = ivec2(pixel);
                float bufferDepth = imageLoad(uDepth, occluderPixel).r;
                if (isSurfaceDepth(bufferDepth)) {
                    precise float difference = sampleDepth - bufferDepth;
                    precise float threshold = params.depthBias * sampleDepth;
                    precise vec3 o = screenToView(vec2(occluderPixel) + 0.5, bufferDepth,
                                                  params.projScale, params.projOffset, params.size);
                    precise float aboveTangent =
                        ((o.x - p.x) * n.x + (o.y - p.y) * n.y) + (o.z - p.z) * n.z;
                    precise float tangentThreshold = params.depthBias * centreDepth;
                    occluded = difference > threshold && difference < params.radius &&
                               aboveTangent > tangentThreshold;
                }
            }
        }
        if (!occluded) {
            visible += 1.0;
            sum.x += s.x;
            sum.y += s.y;
            sum.z += s.z;
        }
    }

    // 2-band SH of the cosine-weighted visibility, then the bent cone.
    precise vec3 bent = vec3(sum.x * tr.x + sum.y * br.x + sum.z * n.x,
                             sum.x * tr.y + sum.y * br.y + sum.z * n.y,
                             sum.x * tr.z + sum.y * br.z + sum.z * n.z);
    precise vec4 sh = vec4(params.shWeight * kShY00 * visible, params.shWeight * kShY1 * bent.y,
                           params.shWeight * kShY1 * bent.z, params.shWeight * kShY1 * bent.x);
    float ambient = visible / float(params.sampleCount);
    precise vec3 l1 = vec3(sh.w, sh.y, sh.z);
    precise float l1Length2 = l1.x * l1.x + l1.y * l1.y + l1.z * l1.z;
    vec3 axis = n;
    if (l1Length2 > 0.0) {
        precise float inverse = 1.0 / sqrt(l1Length2);
        axis = vec3(l1.x * inverse, l1.y * inverse, l1.z * inverse);
    }
    vec4 bentCap = frameData[kPatternBase + params.sampleCount + int(visible)];

    // Four cones per image, each written as one vec4 (no local array, which would spill).
    vec4 visibility0, visibility1, visibility2, visibility3;
    for (int c = 0; c < 4; ++c) {
        visibility0[c] = computeConeVisibility(frameData[kConeBase + c].xyz, axis, bentCap, n);
        visibility1[c] = computeConeVisibility(frameData[kConeBase + 4 + c].xyz, axis, bentCap, n);
        visibility2[c] = computeConeVisibility(frameData[kConeBase + 8 + c].xyz, axis, bentCap, n);
        visibility3[c] =
            computeConeVisibility(frameData[kConeBase + 12 + c].xyz, axis, bentCap, n);
    }

    imageStore(uBentAmbient, pix, vec4(axis, ambient));
    imageStore(uAperture, pix, vec4(bentCap.x));
    imageStore(uVisibility0, pix, visibility0);
    imageStore(uVisibility1, pix, visibility1);
    imageStore(uVisibility2, pix, visibility2);
    imageStore(uVisibility3, pix, visibility3);
}
