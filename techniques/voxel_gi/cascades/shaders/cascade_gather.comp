#version 450
// The pixel gather of the voxel texture cascades on Vulkan: per G-buffer pixel, the 16 fixed cones
// above the surface marched front to back through the pre-combined direction buffers of the
// levels, with step-corrected opacity; the same algorithm as CascadeVolume::gather and
// voxelgi::marchCone (cascade_volume.cpp, framework/families/voxel_gi/cone_tracing.h), in float.
// Positions are relative to an anchor (the coarsest level's centre), so that coordinates far from
// the origin keep their precision. The Tomorrow Children, GDC 2015 (seed
// shared/seeds/000_3da000e866ebc485.txt, "Need to light pixels", "Cascade selection",
// "Pre-Combine Anisotropic Voxels"). Asked for the cones' sky (pc.sky.x), the same march
// (<cone_march.glsl>) also gives each cone's sky and emitters past the voxels ("Sky Light"), the
// far cones' too.

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

#include "cascade_common.glsl"

layout(std430, binding = 1) readonly buffer CombinedBuffer { vec4 combined[]; };
layout(std430, binding = 2) readonly buffer PositionBuffer { vec4 positions[]; }; // w: 1 = surface
// The pixels' normals; for far cones (flags.z = 1) w is the voxel size of the centre's level.
layout(std430, binding = 3) readonly buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = 4) writeonly buffer OutputBuffer { vec4 coneRadiance[]; }; // [pixel][cone]
// [k]: cone k's direction; [16 + k]: the mean sky radiance over its solid angle (pc.sky.x == 1).
layout(std430, binding = 5) readonly buffer ConeBuffer { vec4 cones[32]; };
// Split near/far cones (noise.y > 0): [level][voxel] the slot of the voxel centre's far cones
// (~0u: not traced), and [slot][cone] their radiance (CascadeVolume::prepareFarCones). Resident
// (flags.w = 1): [level][voxel] the state of the voxel's far cones (0 none, 1 wanted, 2 traced)
// and [level][voxel][cone] their radiance, kept on the device: the pixels mark the voxels they
// read and list the newly marked ones (flags.z = 2), one invocation turns the list's length into
// the group counts of the next two dispatches (5), which trace the listed voxels' far cones (3)
// and commit them (4), all before the pixels' cones read them, in one submission: the far cones
// never cross the bus, and only the listed voxels are visited.
layout(std430, binding = 6) buffer FarSlotBuffer { uint farSlots[]; };
layout(std430, binding = 7) buffer FarConeBuffer { vec4 farCones[]; };
layout(std430, binding = 8) buffer FarListBuffer {
    uint farCount;        // voxels listed
    uint traceGroups[3];  // dispatchIndirect arguments of the trace (z: the 16 cones)
    uint commitGroups[3]; // and of the commit
    uint farPad;
    uint farList[];       // [level * R^3 + voxel]
};
// The cones' sky (pc.sky.x == 1): per level voxel face, [(level * R^3 + voxel) * 6 + face], the
// emitted radiance premultiplied by the occupancy (rgb) and the occupancy (a), for the emitters
// and the optical depths the sky's march reads; the far cones' sky and emitters, laid out as
// farCones; and the pixels' cones' sky, [pixel][cone].
layout(std430, binding = 9) readonly buffer FaceBuffer { vec4 faces[]; };
layout(std430, binding = 10) buffer FarSkyBuffer { vec4 farSky[]; };
layout(std430, binding = 11) writeonly buffer SkyOutputBuffer { vec4 coneSky[]; };

layout(push_constant) uniform Constants {
    ivec4 size;  // width, height, levels, resolution
    vec4 march;  // level-0 voxel size, tan(half-angle), start offset (voxels), step scale
    ivec4 flags; // y: max steps, z: 0 pixels, 1 far cones of uploaded voxel centres, 2 mark,
                 // 5 count, 3 trace and 4 commit the resident far cones; w: 1 = resident far cones
    ivec4 anchorCell; // xyz: the anchor in level-0 voxels
    vec4 noise;       // x: level noise (of a level's radius), y: far start (level voxels; 0: off)
    vec4 sky;         // x: 1 = trace the sky, y: sky start (voxels of the cone's start level),
                      // z: 1 = optical depth, w: a bit per level that emits (as a float)
} pc;

float selectLevel(vec3 p, float diameter)
{
    return selectLevel(p, diameter, pc.size.z, pc.march.x, pc.noise.x, pc.anchorCell.xyz);
}

vec4 sampleLevel(int level, vec3 p, int cone)
{
    const int R = pc.size.w;
    ivec3 i0;
    vec3 t;
    getTrilinear(level, p, R, i0, t);
    // Each level's buffer is cone-major ([cone][voxel], CascadeVolume::Level::combined).
    const uint levelVoxels = uint(R) * uint(R) * uint(R);
    const uint base = (uint(level) * 16u + uint(cone)) * levelVoxels;
    vec4 acc = vec4(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        ivec3 d;
        const float w = getCornerWeight(corner, t, d);
        if (w == 0.0)
            continue;
        const ivec3 v = i0 + d;
        acc += w * combined[base + uint(v.x + R * (v.y + R * v.z))];
    }
    return acc;
}

// The far cones' radiance at p for cone `cone`, trilinear over level `level`'s voxel centres
// (the lattice and clamping of sampleLevel).
vec3 sampleFar(int level, vec3 p, int cone, bool sky)
{
    const int R = pc.size.w;
    ivec3 i0;
    vec3 t;
    getTrilinear(level, p, R, i0, t);
    const uint base = uint(level) * uint(R) * uint(R) * uint(R);
    vec3 acc = vec3(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        ivec3 d;
        const float w = getCornerWeight(corner, t, d);
        if (w == 0.0)
            continue;
        const ivec3 v = i0 + d;
        const uint voxel = base + uint(v.x + R * (v.y + R * v.z));
        uint entry = 0xffffffffu;
        if (pc.flags.w == 1)
            entry = farSlots[voxel] == 2u ? voxel : 0xffffffffu;
        else
            entry = farSlots[voxel];
        if (entry != 0xffffffffu)
            acc += w * (sky ? farSky[entry * 16u + uint(cone)].rgb : farCones[entry * 16u + uint(cone)].rgb);
    }
    return acc;
}

// Resident far cones: marks the voxels of level `level` whose far cones sampleFar reads at p.
void markFar(int level, vec3 p)
{
    const int R = pc.size.w;
    ivec3 i0;
    vec3 t;
    getTrilinear(level, p, R, i0, t);
    const uint base = uint(level) * uint(R) * uint(R) * uint(R);
    for (int corner = 0; corner < 8; ++corner) {
        ivec3 d;
        if (getCornerWeight(corner, t, d) == 0.0)
            continue;
        const ivec3 v = i0 + d;
        const uint voxel = base + uint(v.x + R * (v.y + R * v.z));
        if (atomicCompSwap(farSlots[voxel], 0u, 1u) == 0u)
            farList[atomicAdd(farCount, 1u)] = voxel;
    }
}

float opticalDepthOf(float a)
{
    return -log(1.0 - clamp(a, 0.0, 0.9999));
}

// The faces seen along `dir` of level `level`'s trilinear neighbourhood of p: their emission and
// optical depths, weighted as the pre-combined buffers blend them (CascadeVolume::sampleLevel).
void sampleFaces(int level, vec3 p, vec3 dir, float weight, bool wantsDepth, bool wantsEmission,
                 inout vec3 emission, inout float depth)
{
    const int R = pc.size.w;
    ivec3 i0;
    vec3 t;
    getTrilinear(level, p, R, i0, t);
    const uint base = uint(level) * uint(R) * uint(R) * uint(R);
    const ivec3 faceSeen = ivec3(0, 2, 4) + ivec3(greaterThan(dir, vec3(0.0)));
    const vec3 axisWeight = dir * dir;
    for (int corner = 0; corner < 8; ++corner) {
        ivec3 d;
        const float w = weight * getCornerWeight(corner, t, d);
        if (w == 0.0)
            continue;
        const ivec3 v = i0 + d;
        const uint at = (base + uint(v.x + R * (v.y + R * v.z))) * 6u;
        const vec4 fx = faces[at + uint(faceSeen.x)], fy = faces[at + uint(faceSeen.y)],
                   fz = faces[at + uint(faceSeen.z)];
        if (wantsDepth)
            depth += w * (axisWeight.x * opticalDepthOf(fx.a) + axisWeight.y * opticalDepthOf(fy.a) +
                          axisWeight.z * opticalDepthOf(fz.a));
        if (wantsEmission)
            emission += w * (axisWeight.x * fx.rgb + axisWeight.y * fy.rgb + axisWeight.z * fz.rgb);
    }
}

// The sample of cone_march.glsl: the level the footprint selects, blended with the next
// coarser one, from the pre-combined buffers of cone `cone`.
bool sampleCone(vec3 q, float diameter, vec3 dir, int cone, bool wantsDepth, bool wantsEmission, out vec4 s,
                out vec3 emission, out float depth, out float voxelSize)
{
    emission = vec3(0.0);
    depth = 0.0;
    const float l = selectLevel(q, diameter);
    if (l < 0.0)
        return false; // left the cascade: no light from beyond
    const int l0 = int(floor(l));
    const float frac = l - float(l0);
    const bool next = frac > 0.0 && l0 + 1 < pc.size.z;
    s = (1.0 - frac) * sampleLevel(l0, q, cone);
    if (next)
        s += frac * sampleLevel(l0 + 1, q, cone);
    // A level's faces are bound where they are read: in optical depth every level's, else
    // those of the levels that emit (CascadeVolume::sampleLevel reads a level's emission only
    // where it emits).
    const uint emitting = uint(pc.sky.w);
    const bool emits0 = wantsEmission && ((emitting >> uint(l0)) & 1u) != 0u;
    const bool emits1 = wantsEmission && next && ((emitting >> uint(l0 + 1)) & 1u) != 0u;
    if (wantsDepth || emits0)
        sampleFaces(l0, q, dir, 1.0 - frac, wantsDepth, emits0, emission, depth);
    if (next && (wantsDepth || emits1))
        sampleFaces(l0 + 1, q, dir, frac, wantsDepth, emits1, emission, depth);
    voxelSize = pc.march.x * exp2(l);
    return true;
}

#include <cone_march.glsl>

// A cone's march from t0 until tMax, with the sky when traced: from skyStart on, the part of
// each sample below the surface of normal n the cone leaves (planeHeight below its origin) left
// out (none where n is 0).
ConeMarch makeMarch(float t0, float tMax, float skyStart, vec3 n, float planeHeight)
{
    ConeMarch m;
    m.t0 = t0;
    m.tMax = tMax;
    m.tanHalfAngle = pc.march.y;
    m.stepScale = pc.march.w;
    m.maxSteps = pc.flags.y;
    m.sky = pc.sky.x == 1.0;
    m.opticalDepth = pc.sky.z == 1.0;
    m.skyStart = skyStart;
    m.planeNormal = n;
    m.planeHeight = planeHeight;
    return m;
}

void main()
{
    // One cone per invocation (z: the cone), so that a warp holds neighbouring pixels' cones of
    // one direction: 16 times the parallelism of a pixel per invocation, and coherent steps.
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    const int k = int(gl_GlobalInvocationID.z);
    if (pc.flags.z == 5) {
        // The group counts for the listed voxels, 64 invocations (one 8 x 8 group) each.
        if (gl_GlobalInvocationID == uvec3(0)) {
            const uint groups = (farCount + 63u) / 64u;
            traceGroups[0] = groups;
            traceGroups[1] = 1u;
            traceGroups[2] = 16u;
            commitGroups[0] = groups;
            commitGroups[1] = 1u;
            commitGroups[2] = 1u;
        }
        return;
    }
    if (pc.flags.z == 3 || pc.flags.z == 4) {
        // Resident far cones of the listed voxels: invocation (list entry, cone).
        const uint entry = gl_WorkGroupID.x * 64u + gl_LocalInvocationIndex;
        if (entry >= farCount)
            return;
        const uint voxel = farList[entry];
        if (pc.flags.z == 4) {
            farSlots[voxel] = 2u;
            return;
        }
        const int R = pc.size.w;
        const int levelVoxels = R * R * R;
        const int level = int(voxel) / levelVoxels;
        if (levels[level].centre.w <= 0.0)
            return;
        const int local = int(voxel) - level * levelVoxels;
        const vec3 cell = vec3(local % R, (local / R) % R, local / (R * R)) + 0.5;
        const float voxelSize = levels[level].origin.w;
        const ConeTrace r = marchCone(levels[level].origin.xyz + cell * voxelSize, cones[k].xyz, k,
                                      makeMarch(pc.noise.y * voxelSize, 1e30, pc.sky.y * voxelSize, vec3(0.0), 0.0));
        farCones[voxel * 16u + uint(k)] = vec4(max(r.light, vec3(0.0)), 1.0);
        if (pc.sky.x == 1.0)
            farSky[voxel * 16u + uint(k)] = vec4(getConeSkyRadiance(r, cones[16 + k].rgb), 1.0);
        return;
    }

    if (pixel.x >= pc.size.x || pixel.y >= pc.size.y || k >= 16)
        return;
    const int index = pixel.y * pc.size.x + pixel.x;
    if (pc.flags.z != 2)
        coneRadiance[index * 16 + k] = vec4(0.0);
    const bool sky = pc.sky.x == 1.0;
    if (sky && pc.flags.z != 2)
        coneSky[index * 16 + k] = vec4(0.0);
    if (pc.flags.z == 1) {
        // Far cones ("Split Cone Trace"): the 16 cones from a voxel centre, from far start voxels
        // of its level on (CascadeVolume::prepareFarCones).
        const vec4 centre = positions[index];
        if (centre.w == 0.0)
            return;
        const float voxelSize = normals[index].w;
        const ConeTrace r = marchCone(centre.xyz, cones[k].xyz, k,
                                      makeMarch(pc.noise.y * voxelSize, 1e30, pc.sky.y * voxelSize, vec3(0.0), 0.0));
        coneRadiance[index * 16 + k] = vec4(max(r.light, vec3(0.0)), 1.0);
        if (sky)
            coneSky[index * 16 + k] = vec4(getConeSkyRadiance(r, cones[16 + k].rgb), 1.0);
        return;
    }
    const vec4 position = positions[index];
    const vec3 n = normals[index].xyz;
    if (position.w == 0.0 || dot(n, n) < 0.5)
        return;
    const vec3 p = position.xyz;
    const float start = selectLevel(p, 0.0);
    if (start < 0.0)
        return;
    const float v = pc.march.x * exp2(floor(start));
    const vec3 origin = p + n * (0.5 * pc.march.z * v);
    const float startDistance = pc.march.z * v;

    // The radiance of each cone above the surface; the pixel's irradiance weights, the
    // occlusion family's visibilities and the capsules are applied in the combine step
    // (families/voxel_gi/upsample.h), at full resolution.
    // Split near/far cones: the start levels l0 and l1 = l0 + 1 when the start blends toward a
    // voxelized l1 (CascadeVolume::getStartLevels and gatherConesSplit).
    const float farStart = pc.noise.y;
    const int l0 = int(floor(start));
    const float frac = start - float(l0);
    const bool two = frac > 0.0 && l0 + 1 < pc.size.z && levels[l0 + 1].centre.w > 0.0;
    const float split0 = farStart * levels[l0].origin.w;
    if (pc.flags.z == 2) {
        // Resident far cones: mark the voxels whose far cones this pixel's cones will read.
        if (k == 0 && farStart > 0.0) {
            markFar(l0, origin);
            if (two)
                markFar(l0 + 1, origin);
        }
        return;
    }
    if (dot(cones[k].xyz, n) <= 0.0)
        return;
    const vec3 dir = cones[k].xyz;
    const vec3 skyOfCone = cones[16 + k].rgb;
    const ConeMarch near =
        makeMarch(startDistance, farStart > 0.0 ? split0 : 1e30, pc.sky.y * v, n, 0.5 * pc.march.z * v);
    const ConeTrace a = marchCone(origin, dir, k, near);
    vec3 light = a.light, skyLight = getConeSkyRadiance(a, skyOfCone);
    if (farStart > 0.0) {
        // The near part, then the far cones seen through it (CascadeVolume::gatherConesSplit);
        // the sky the same way: the near part's emitters, then the sky where it left the
        // cascade, else the far cones' sky and emitters, through the near part's sky
        // transmittance.
        vec3 la = a.light;
        if (!a.escaped)
            la += a.transmittance * sampleFar(l0, origin, k, false);
        vec3 sa = vec3(0.0);
        if (sky)
            sa = a.emission + a.skyTransmittance * (a.skyEscaped ? skyOfCone : sampleFar(l0, origin, k, true));
        light = la;
        skyLight = sa;
        if (two) {
            vec3 lb = a.light, sb = a.emission;
            ConeTrace b;
            b.light = b.emission = vec3(0.0);
            b.transmittance = b.skyTransmittance = 1.0;
            b.escaped = b.skyEscaped = false;
            if (!a.escaped) {
                ConeMarch second = near;
                second.t0 = split0;
                second.tMax = 2.0 * split0;
                b = marchCone(origin, dir, k, second);
                lb += a.transmittance * b.light;
                if (!b.escaped)
                    lb += a.transmittance * b.transmittance * sampleFar(l0 + 1, origin, k, false);
            }
            if (sky) {
                if (a.skyEscaped)
                    sb += a.skyTransmittance * skyOfCone;
                else // then a.escaped is false too: b was marched
                    sb += a.transmittance * b.emission +
                          a.skyTransmittance * b.skyTransmittance *
                              (b.skyEscaped ? skyOfCone : sampleFar(l0 + 1, origin, k, true));
            }
            light = la + frac * (lb - la);
            skyLight = sa + frac * (sb - sa);
        }
    }
    coneRadiance[index * 16 + k] = vec4(max(light, vec3(0.0)), 1.0);
    if (sky)
        coneSky[index * 16 + k] = vec4(max(skyLight, vec3(0.0)), 1.0);
}
