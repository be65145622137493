#version 450
// The lit HDR frame from the G-buffer (render/lighting_pass.h): point lights with filtered cube
// shadow maps, the sky through 16 lobes with per-lobe visibility, emission and indirect
// irradiance. One invocation per pixel.

#include "cube_shadow.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D gPositionDepth; // xyz world, w depth
layout(binding = 1, rgba32f) uniform readonly image2D gNormal;        // faces the viewer
layout(binding = 2, rgba32f) uniform readonly image2D gAlbedo;
layout(binding = 3, rgba32f) uniform readonly image2D gEmission;
layout(binding = 4, r32f) uniform readonly image3D shadowAtlas; // slice 6 light + face

struct Light {
    vec4 position;  // xyz world units, w: first atlas slice, < 0 without shadow map
    vec4 intensity; // rgb radiant intensity
};
layout(std430, binding = 5) readonly buffer Lights {
    Light lights[];
};

layout(std430, binding = 6) readonly buffer Sky {
    vec4 parameters; // kind (0 none, 1 constant, 2 gradient, 3 srbf), sharpness, table size
    vec4 constant;
    vec4 zenith;
    vec4 horizon;
    vec4 ground;
    vec4 axes[16];         // the 16 cone directions a_k
    vec4 lobeRadiance[16]; // L_k
    float table[];         // I(c) at c = -1 + 2 i / (size - 1)
} sky;

layout(binding = 7, r32f) uniform readonly image2D ambientOcclusion;
// The 16 cone visibilities: cone 4 g + c in channel c of image g (binding 8 for g = 0, 12..14).
layout(binding = 8, rgba32f) uniform readonly image2D coneVisibility0;
layout(binding = 12, rgba32f) uniform readonly image2D coneVisibility1;
layout(binding = 13, rgba32f) uniform readonly image2D coneVisibility2;
layout(binding = 14, rgba32f) uniform readonly image2D coneVisibility3;
layout(binding = 9, rgba32f) uniform readonly image2D indirectIrradiance;
layout(binding = 10, rgba32f) uniform writeonly image2D outHdr;
layout(binding = 11, rgba32f) uniform writeonly image2D outDirect;
// The sky and emitters seen through a voxel GI technique's cones (flags.z = 1).
layout(binding = 15, rgba32f) uniform readonly image2D coneSkyIrradiance;

layout(push_constant) uniform Frame {
    mat4 inverseRelativeViewProjection; // clip -> camera-relative world
    vec4 cameraPosition;                // xyz world units, w: min light distance
    uvec4 sizeLightsVisibility;         // width, height, lights, visibility (0 none, 1 ao, 2 cones)
    uvec4 flags;                        // x: has indirect, y: shadow face size, z: has cone sky
    vec4 shadowParameters;              // PCF spacing, normal offset, slope offset (texels)
} frame;

const float kPi = 3.14159265358979;

// 1 where the stored occluder distance along `dir` is not closer than the receiver.
float fetchShadowTap(vec3 dir, float receiverDistance, int firstSlice, int size)
{
    const int face = computeCubeFace(dir);
    const vec2 st = computeCubeFaceCoords(dir, face);
    const ivec2 texel =
        clamp(ivec2(floor((st + 1.0) * 0.5 * float(size))), ivec2(0), ivec2(size - 1));
    const float stored = imageLoad(shadowAtlas, ivec3(texel, firstSlice + face)).r;
    return receiverDistance <= stored ? 1.0 : 0.0;
}

// Fraction of the light at `lightPosition` that reaches x: percentage-closer filtering of the
// cube map [Reeves et al. 1987] with 3 x 3 tent-weighted taps.
float computeShadow(vec3 x, vec3 n, vec3 lightPosition, float d, float cosTheta, int firstSlice)
{
    const int size = int(frame.flags.y);
    // The largest angle one texel subtends (at a face's centre: 2 / size radians).
    const float texelAngle = 2.0 / float(size);
    // Bias. A tap one texel-angle delta away from the receiver's own direction sees a plane
    // through x at a distance that differs by about d * delta * tan(theta), and the nearest
    // texel moves the direction by up to ~0.7 texel; the corner taps are sqrt(2) spacing away.
    // Moving the receiver along its normal by o puts it o / cos(theta) in front of its plane
    // along the light direction, which covers d * delta * tan(theta) when o >= d * delta *
    // sin(theta): a slope-scaled normal offset [Holbein 2011, "normal offset shadows"], with
    // slopeOffsetTexels (default 2.5, about tap reach + quantisation) texels of delta. The
    // constant part (normalOffsetTexels, default 0.5 texel) absorbs float rounding and curved
    // receivers. Both scale with d because a texel's footprint does.
    const float sinTheta = sqrt(max(0.0, 1.0 - cosTheta * cosTheta));
    const float offset = texelAngle * d *
                         (frame.shadowParameters.y + frame.shadowParameters.z * sinTheta);
    const vec3 v = x + n * offset - lightPosition;
    const float receiver = length(v);
    const int face = computeCubeFace(v);
    const vec2 st = computeCubeFaceCoords(v, face);
    // Taps in the receiver's face coordinates; each resolves its own face, so the kernel
    // continues across cube edges.
    const float spacing = frame.shadowParameters.x * texelAngle;
    float sum = 0.0;
    for (int j = -1; j <= 1; ++j) {
        for (int i = -1; i <= 1; ++i) {
            const float weight = float((2 - abs(i)) * (2 - abs(j)));
            const vec3 dir = computeCubeFaceDirection(face, st + vec2(i, j) * spacing);
            sum += weight * fetchShadowTap(dir, receiver, firstSlice, size);
        }
    }
    return sum / 16.0;
}

// I(c): irradiance of one lobe whose axis makes cosine c with the normal (linear interpolation
// in the table computed on the CPU, render/sky_irradiance.cpp).
float lookupLobeIrradiance(float c)
{
    const int n = int(sky.parameters.z);
    const float f = (clamp(c, -1.0, 1.0) + 1.0) * 0.5 * float(n - 1);
    const int i = min(int(f), n - 2);
    return mix(sky.table[i], sky.table[i + 1], f - float(i));
}

// Sky radiance toward unit direction w (scene::Sky::radiance).
vec3 evaluateSkyRadiance(vec3 w)
{
    const int kind = int(sky.parameters.x);
    if (kind == 1)
        return sky.constant.rgb;
    if (kind == 2)
        return w.y < 0.0 ? sky.ground.rgb : mix(sky.horizon.rgb, sky.zenith.rgb, min(1.0, w.y));
    if (kind == 3) {
        // The sky as 16 SRBFs on the cone directions [The Tomorrow Children, GDC 2015].
        vec3 sum = vec3(0.0);
        for (int k = 0; k < 16; ++k)
            sum += sky.lobeRadiance[k].rgb *
                   exp(sky.parameters.y * (dot(w, sky.axes[k].xyz) - 1.0));
        return sum;
    }
    return vec3(0.0);
}

void main()
{
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    const uvec2 size = frame.sizeLightsVisibility.xy;
    if (pixel.x >= int(size.x) || pixel.y >= int(size.y))
        return;

    const vec4 positionDepth = imageLoad(gPositionDepth, pixel);
    if (isinf(positionDepth.w)) {
        // No surface: the sky along the camera ray through the pixel's sample (the projection
        // carries the jitter, so the pixel centre in NDC is the sample).
        const vec2 ndc = (vec2(pixel) + 0.5) / vec2(size) * 2.0 - 1.0;
        const vec4 far = frame.inverseRelativeViewProjection * vec4(ndc, 1.0, 1.0);
        const vec3 w = normalize(far.xyz / far.w);
        imageStore(outHdr, pixel, vec4(evaluateSkyRadiance(w), 1.0));
        imageStore(outDirect, pixel, vec4(0.0));
        return;
    }

    const vec3 x = positionDepth.xyz;
    const vec3 n = imageLoad(gNormal, pixel).xyz;
    const vec3 rho = imageLoad(gAlbedo, pixel).rgb;
    const vec3 emission = imageLoad(gEmission, pixel).rgb;
    const float minDistance = frame.cameraPosition.w;

    // Point lights: I cos(theta) / d^2, shadowed.
    vec3 lightIrradiance = vec3(0.0);
    for (uint i = 0u; i < frame.sizeLightsVisibility.z; ++i) {
        const vec3 toLight = lights[i].position.xyz - x;
        const float d = length(toLight);
        // A light on the surface point itself has no direction: it adds nothing.
        const float cosTheta = d > 0.0 ? max(0.0, dot(n, toLight / d)) : 0.0;
        if (cosTheta <= 0.0)
            continue;
        const float dClamped = max(d, minDistance);
        float shadow = 1.0;
        if (lights[i].position.w >= 0.0)
            shadow = computeShadow(x, n, lights[i].position.xyz, d, cosTheta,
                                   int(lights[i].position.w));
        lightIrradiance += lights[i].intensity.rgb * (cosTheta * shadow / (dClamped * dClamped));
    }

    // Sky: E = Sum_k V_k L_k I(n . a_k), V_k from the visibility input. The Tomorrow Children
    // intersect each pixel's SSDO visibility cone with the 16 cone directions "and modulate the
    // incoming light accordingly" [GDC 2015, "Screen Space Directional Occlusion"].
    // With a cone sky (a voxel GI technique ran) the sky and the emitters come through its 16
    // cones past its voxels, the visibilities V_k already applied per cone [GDC 2015, "Sky
    // Light": the sky gathered along the same cones as the bounce light].
    vec3 skyIrradiance = vec3(0.0);
    if (frame.flags.z != 0u) {
        skyIrradiance = imageLoad(coneSkyIrradiance, pixel).rgb;
    } else if (int(sky.parameters.x) != 0) {
        const uint visibility = frame.sizeLightsVisibility.w;
        const float ao = visibility == 1u ? imageLoad(ambientOcclusion, pixel).r : 1.0;
        vec4 cones[4] = vec4[4](vec4(ao), vec4(ao), vec4(ao), vec4(ao));
        if (visibility == 2u) {
            cones[0] = imageLoad(coneVisibility0, pixel);
            cones[1] = imageLoad(coneVisibility1, pixel);
            cones[2] = imageLoad(coneVisibility2, pixel);
            cones[3] = imageLoad(coneVisibility3, pixel);
        }
        for (int k = 0; k < 16; ++k) {
            const float v = cones[k >> 2][k & 3];
            skyIrradiance +=
                v * sky.lobeRadiance[k].rgb * lookupLobeIrradiance(dot(n, sky.axes[k].xyz));
        }
    }

    // Fitted lobes (constant and gradient skies) may be negative; partial visibility must not
    // turn the sum negative.
    skyIrradiance = max(skyIrradiance, vec3(0.0));

    const vec3 indirect =
        frame.flags.x != 0u ? imageLoad(indirectIrradiance, pixel).rgb : vec3(0.0);
    const vec3 direct = rho / kPi * (lightIrradiance + skyIrradiance);
    const vec3 hdr = emission + direct + rho / kPi * indirect;
    imageStore(outHdr, pixel, vec4(hdr, 1.0));
    // Alpha: the luminance (Rec. 709) of the sky's part of direct, for the frame's terms.
    const vec3 skyPart = rho / kPi * skyIrradiance;
    imageStore(outDirect, pixel, vec4(direct, dot(skyPart, vec3(0.2126, 0.7152, 0.0722))));
}
