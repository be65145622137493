// GTAO main pass [Jimenez et al. 2016]: per pixel, `slices` slices around the view vector, a
// horizon search of `steps` depth samples on each side, and the analytic cosine-weighted
// visibility and bent normal of the visible arcs. The GLSL twin of gtao_cpu.cpp (same formulas,
// same order); see gtao.cpp for the algorithm and gtao_math.h for the closed forms.
#version 450

#include <screen_space.glsl>

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, r32f) uniform readonly image2D linearDepth;
layout(set = 0, binding = 1, rgba32f) uniform readonly image2D viewNormal;
layout(set = 0, binding = 2, r32f) uniform writeonly image2D ambientOut;
layout(set = 0, binding = 3, rgba32f) uniform writeonly image2D bentNormalOut;
layout(set = 0, binding = 4, r32f) uniform writeonly image2D apertureOut;

// GtaoFrameConstants (gtao_kernel.h).
layout(push_constant, std430) uniform FrameConstants
{
    vec2 projScale;
    vec2 projOffset;
    vec2 size;
    float radius;
    float falloffStart;
    float falloffScale;
    float maxPixelRadius;
    float sliceAngle;
    float temporalRotation;
    float temporalStepOffset;
    int slices;
    int steps;
    uint flags;
} pc;

const uint kFlagNormalize = 1u;
const uint kFlagSphereExtent = 2u;
const float kHalfPi = 1.57079632679489661923;
const float kFloatMax = 3.402823466e+38;
const uint kBayer4x4[16] = uint[16](0u, 8u, 2u, 10u, 12u, 4u, 14u, 6u, 3u, 11u, 1u, 9u, 15u, 7u,
                                    13u, 5u);

// Sample positions, the radius test and the horizon cosines decide which depth samples count (a
// sample at the radius is in or out), so they are computed with the same IEEE operations as
// gtao_cpu.cpp: `precise` (no fused multiply-add), explicit dot/cross/length, and polynomials
// instead of the driver's sin/cos/acos (gtao_math.h, same coefficients).

precise float dot3(vec3 a, vec3 b)
{
    precise float r = a.x * b.x + a.y * b.y + a.z * b.z;
    return r;
}

precise float length3(vec3 a)
{
    precise float r = sqrt(dot3(a, a));
    return r;
}

precise vec3 cross3(vec3 a, vec3 b)
{
    precise vec3 r = vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
    return r;
}

precise float length2(vec2 a)
{
    precise float r = sqrt(a.x * a.x + a.y * a.y);
    return r;
}

// (cos(phi), sin(phi)) for phi in [0, pi] (gtao_math.h, computeCosSin).
precise vec2 computeCosSin(float phi)
{
    precise float x = phi - 1.57079637;
    precise float x2 = x * x;
    precise float sinPoly = -2.50521079e-08;
    sinPoly = sinPoly * x2 + 2.75573188e-06;
    sinPoly = sinPoly * x2 - 0.000198412701;
    sinPoly = sinPoly * x2 + 0.00833333377;
    sinPoly = sinPoly * x2 - 0.166666672;
    sinPoly = sinPoly * x2 + 1.0;
    precise float cosPoly = 2.08767559e-09;
    cosPoly = cosPoly * x2 - 2.755732e-07;
    cosPoly = cosPoly * x2 + 2.48015876e-05;
    cosPoly = cosPoly * x2 - 0.00138888892;
    cosPoly = cosPoly * x2 + 0.0416666679;
    cosPoly = cosPoly * x2 - 0.5;
    cosPoly = cosPoly * x2 + 1.0;
    precise vec2 r = vec2(-(x * sinPoly), cosPoly);
    return r;
}

// acos to ~1e-7 rad: Abramowitz & Stegun 4.4.46 (gtao_math.h, computeAcos).
precise float computeAcos(float x)
{
    precise float a = abs(x);
    precise float poly = -0.0012624911;
    poly = poly * a + 0.0066700899;
    poly = poly * a - 0.0170881264;
    poly = poly * a + 0.0308918804;
    poly = poly * a - 0.0501743034;
    poly = poly * a + 0.0889789909;
    poly = poly * a - 0.214598805;
    poly = poly * a + 1.57079625;
    precise float r = sqrt(1.0 - a) * poly;
    precise float result = x >= 0.0 ? r : 3.14159274 - r;
    return result;
}

bool isSurfaceDepth(float depth)
{
    return depth > 0.0 && depth <= kFloatMax;
}

// a(h) = (-cos(2h - gamma) + cos(gamma) + 2 h sin(gamma)) / 4 [Jimenez et al. 2016, inner integral]
float integrateArc(float h, float gamma)
{
    return 0.25 * (-cos(2.0 * h - gamma) + cos(gamma) + 2.0 * h * sin(gamma));
}

float integrateBentS(float h, float gamma)
{
    return (8.0 * sin(gamma) - sin(3.0 * h - gamma) + 6.0 * sin(h - gamma) -
            3.0 * sin(h + gamma)) / 12.0;
}

float integrateBentV(float h, float gamma)
{
    return (4.0 * cos(gamma) - cos(3.0 * h - gamma) - 3.0 * cos(h + gamma)) / 12.0;
}

// Bilinear 1 / depth at continuous pixel `pos` (planes are reproduced exactly); false when a texel
// has no surface.
bool sampleViewPosition(vec2 pos, out vec3 q)
{
    precise vec2 f = pos - 0.5;
    int x0 = int(floor(f.x));
    int y0 = int(floor(f.y));
    int x1 = min(x0 + 1, int(pc.size.x) - 1);
    int y1 = min(y0 + 1, int(pc.size.y) - 1);
    precise float fx = f.x - float(x0);
    precise float fy = f.y - float(y0);
    float d00 = imageLoad(linearDepth, ivec2(x0, y0)).r;
    float d10 = imageLoad(linearDepth, ivec2(x1, y0)).r;
    float d01 = imageLoad(linearDepth, ivec2(x0, y1)).r;
    float d11 = imageLoad(linearDepth, ivec2(x1, y1)).r;
    q = vec3(0.0);
    if (!(isSurfaceDepth(d00) && isSurfaceDepth(d10) && isSurfaceDepth(d01) &&
          isSurfaceDepth(d11)))
        return false;
    precise float top = 1.0 / d00 + (1.0 / d10 - 1.0 / d00) * fx;
    precise float bottom = 1.0 / d01 + (1.0 / d11 - 1.0 / d01) * fx;
    precise float inverseDepth = top + (bottom - top) * fy;
    precise vec3 position =
        screenToView(pos, 1.0 / inverseDepth, pc.projScale, pc.projOffset, pc.size);
    q = position;
    return true;
}

// Screen-space search length on side `sideSign` of slice direction s, px.
precise float computeExtent(vec3 p, vec3 u, vec3 s, float sideSign)
{
    if ((pc.flags & kFlagSphereExtent) == 0u) {  // [Jimenez et al. 2016]: radius at p's depth
        precise float projected = worldToPixelLength(pc.radius, -p.z, pc.projScale, pc.size);
        return min(projected, pc.maxPixelRadius);
    }
    // Tangent rays from the camera to the radius sphere within the slice plane.
    precise float sinAngle = pc.radius / length3(p);
    if (!(sinAngle < 1.0))
        return pc.maxPixelRadius;
    precise float cosAngle = sqrt(1.0 - sinAngle * sinAngle);
    precise vec3 tangent = cosAngle * u + (sideSign * sinAngle) * s;
    if (!(tangent.z < 0.0))
        return pc.maxPixelRadius;
    // Screen distance between the projections of the tangent ray and of p (the jitter offset
    // cancels): 0.5 size projScale (tangent.xy / -tangent.z - p.xy / -p.z).
    precise vec2 offset = (0.5 * pc.size * pc.projScale) * (tangent.xy / -tangent.z - p.xy / -p.z);
    precise float extent = length2(offset);
    return extent < pc.maxPixelRadius ? extent : pc.maxPixelRadius;
}

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSize(ambientOut))))
        return;

    float depth = imageLoad(linearDepth, pixel).r;
    precise vec3 n = imageLoad(viewNormal, pixel).xyz;
    precise float normalLength2 = dot3(n, n);
    if (!isSurfaceDepth(depth) || !(normalLength2 > 1e-12) || !(normalLength2 <= kFloatMax)) {
        imageStore(ambientOut, pixel, vec4(1.0));
        imageStore(bentNormalOut, pixel, vec4(0.0));
        imageStore(apertureOut, pixel, vec4(0.0));
        return;
    }
    n = n / sqrt(normalLength2);

    precise vec2 centre = vec2(pixel) + 0.5;
    precise vec3 p = screenToView(centre, depth, pc.projScale, pc.projOffset, pc.size);
    precise vec3 u = p / length3(p);
    precise vec3 v = -u;
    // Frame of the plane orthogonal to v: slice angles are uniform around v.
    precise vec3 t1 = vec3(1.0, 0.0, 0.0) - v.x * v;
    t1 = t1 / length3(t1);
    precise vec3 t2 = cross3(v, t1);

    uint bayerIndex = (uint(pixel.y) & 3u) * 4u + (uint(pixel.x) & 3u);
    precise float rotation = (float(kBayer4x4[bayerIndex]) + pc.temporalRotation) * 0.0625;
    precise float jitter = (float(uint(pixel.y - pixel.x) & 3u) + pc.temporalStepOffset) * 0.25;
    vec2 lowCorner = vec2(0.5);
    precise vec2 highCorner = pc.size - 0.5;

    float visibleSum = 0.0;
    float fullSum = 0.0;
    vec3 bentVisible = vec3(0.0);
    vec3 bentFull = vec3(0.0);
    for (int slice = 0; slice < pc.slices; ++slice) {
        // [Jimenez et al. 2016, Alg. 1] slice direction, projected normal, its angle gamma.
        precise float phi = (float(slice) + rotation) * pc.sliceAngle;
        precise vec2 cosSin = computeCosSin(phi);
        precise vec3 s = cosSin.x * t1 + cosSin.y * t2;
        precise float ns = dot3(n, s);
        precise float nv = dot3(n, v);
        precise float projectedLength = sqrt(ns * ns + nv * nv);
        precise float cosGamma = projectedLength > 0.0 ? nv / projectedLength : 1.0;
        precise float gammaMagnitude = min(computeAcos(clamp(cosGamma, -1.0, 1.0)), kHalfPi);
        precise float gamma = ns < 0.0 ? -gammaMagnitude : gammaMagnitude;

        // Screen direction of the slice at p: the derivative of the projection along s.
        precise vec2 dir = vec2(pc.size.x * pc.projScale.x * (s.x * depth + p.x * s.z),
                                pc.size.y * pc.projScale.y * (s.y * depth + p.y * s.z));
        precise float dirLength = length2(dir);
        dir = dirLength > 0.0 ? dir / dirLength : vec2(0.0);

        // Horizon search on both sides: the largest cos(angle to v) of the samples within the
        // radius, from the normal's hemisphere boundary. [Jimenez et al. 2016, Alg. 1]
        float horizonCos[2];
        for (int side = 0; side < 2; ++side) {
            float sideSign = side == 0 ? 1.0 : -1.0;
            precise float lowCos = -sideSign * sin(gamma);  // cos(gamma +- pi/2)
            precise float maxCos = lowCos;
            precise float extent = dirLength > 0.0 ? computeExtent(p, u, s, sideSign) : 0.0;
            for (int step = 0; step < pc.steps && extent > 1.0; ++step) {
                precise float t =
                    1.0 + (extent - 1.0) * ((float(step) + jitter) / float(pc.steps));
                precise vec2 pos = centre + (sideSign * t) * dir;
                if (!(pos.x >= lowCorner.x && pos.y >= lowCorner.y && pos.x <= highCorner.x &&
                      pos.y <= highCorner.y))
                    break;  // farther steps are farther off screen
                precise vec3 q;
                if (!sampleViewPosition(pos, q))
                    continue;
                precise vec3 delta = q - p;
                precise float dist = length3(delta);
                if (!(dist <= pc.radius) || !(dist > 0.0) || !(dist <= kFloatMax))
                    continue;  // occluders beyond the radius do not count
                precise float weight = dist <= pc.falloffStart
                                           ? 1.0
                                           : 1.0 - (dist - pc.falloffStart) * pc.falloffScale;
                precise float sampleCos = dot3(delta, v) / dist;
                maxCos = max(maxCos, lowCos + (sampleCos - lowCos) * weight);
            }
            horizonCos[side] = maxCos;
        }
        // Signed horizon angles clamped to the normal's hemisphere. [Jimenez et al. 2016, Alg. 1]
        precise float h2 = min(computeAcos(clamp(horizonCos[0], -1.0, 1.0)), gamma + kHalfPi);
        precise float h1 = max(-computeAcos(clamp(horizonCos[1], -1.0, 1.0)), gamma - kHalfPi);

        // Cosine-weighted visible arc weighted by |n_p|, and its cosine-weighted direction.
        // [Jimenez et al. 2016, inner integral; bent normals]
        visibleSum += projectedLength * (integrateArc(h1, gamma) + integrateArc(h2, gamma));
        fullSum += projectedLength * (cos(gamma) + gamma * sin(gamma));
        float bs = integrateBentS(h1, gamma) + integrateBentS(h2, gamma);
        float bv = integrateBentV(h1, gamma) + integrateBentV(h2, gamma);
        bentVisible += projectedLength * (bs * s + bv * v);
        bentFull += projectedLength * ((4.0 / 3.0) * sin(gamma) * s +
                                       (2.0 / 3.0) * cos(gamma) * v);
    }

    float ambient;
    vec3 bent;
    if ((pc.flags & kFlagNormalize) != 0u) {
        // Ratio to the unoccluded integral of the same slices; the exact unoccluded bent vector
        // (2/3) n per slice minus the estimated occluded part.
        ambient = fullSum > 0.0 ? visibleSum / fullSum : 1.0;
        bent = ((2.0 / 3.0) * float(pc.slices)) * n - (bentFull - bentVisible);
    } else {
        ambient = visibleSum / float(pc.slices);
        bent = bentVisible;
    }
    ambient = clamp(ambient, 0.0, 1.0);
    float bentLength = length3(bent);
    vec3 bentNormal = bentLength > 1e-6 ? bent / bentLength : n;
    imageStore(ambientOut, pixel, vec4(ambient));
    imageStore(bentNormalOut, pixel, vec4(bentNormal, 0.0));
    // sin^2(alpha) = A: alpha = asin(sqrt(A)) = pi/2 - acos(sqrt(A)).
    imageStore(apertureOut, pixel, vec4(kHalfPi - computeAcos(sqrt(ambient))));
}
