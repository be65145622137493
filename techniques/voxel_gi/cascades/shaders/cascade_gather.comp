#version 450
// The pixel gather of the voxel texture cascades on Vulkan: per G-buffer pixel, the 16 fixed cones
// above the surface marched front to back through the pre-combined direction buffers of the
// levels, with step-corrected opacity; the same algorithm as CascadeVolume::gather and
// voxelgi::marchCone (cascade_volume.cpp, framework/families/voxel_gi/cone_tracing.h), in float.
// Positions are relative to an anchor (the coarsest level's centre), so that coordinates far from
// the origin keep their precision. The Tomorrow Children, GDC 2015 (seed
// shared/seeds/000_3da000e866ebc485.txt, "Need to light pixels", "Cascade selection",
// "Pre-Combine Anisotropic Voxels").

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

#include "cascade_common.glsl"

layout(std430, binding = 1) readonly buffer CombinedBuffer { vec4 combined[]; };
layout(std430, binding = 2) readonly buffer PositionBuffer { vec4 positions[]; }; // w: 1 = surface
// The pixels' normals; for far cones (flags.z = 1) w is the voxel size of the centre's level.
layout(std430, binding = 3) readonly buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = 4) writeonly buffer OutputBuffer { vec4 coneRadiance[]; }; // [pixel][cone]
layout(std430, binding = 5) readonly buffer ConeBuffer { vec4 cones[16]; };
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

layout(push_constant) uniform Constants {
    ivec4 size;  // width, height, levels, resolution
    vec4 march;  // level-0 voxel size, tan(half-angle), start offset (voxels), step scale
    ivec4 flags; // y: max steps, z: 0 pixels, 1 far cones of uploaded voxel centres, 2 mark,
                 // 5 count, 3 trace and 4 commit the resident far cones; w: 1 = resident far cones
    ivec4 anchorCell; // xyz: the anchor in level-0 voxels
    vec4 noise;       // x: level noise (of a level's radius), y: far start (level voxels; 0: off)
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
vec3 sampleFar(int level, vec3 p, int cone)
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
        if (pc.flags.w == 1) {
            if (farSlots[voxel] == 2u)
                acc += w * farCones[voxel * 16u + uint(cone)].rgb;
            continue;
        }
        const uint slot = farSlots[voxel];
        if (slot != 0xffffffffu)
            acc += w * farCones[slot * 16u + uint(cone)].rgb;
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

// One cone marched front to back from t0 until tMax: rgb the radiance, a the transmittance;
// `escaped` when it left the cascade (voxelgi::marchCone).
vec4 marchCone(vec3 origin, vec3 dir, int k, float t0, float tMax, out bool escaped)
{
    float occupied = 0.0;
    vec3 light = vec3(0.0);
    float t = t0;
    escaped = false;
    for (int step = 0; step < pc.flags.y; ++step) {
        if (t >= tMax)
            break;
        const float diameter = 2.0 * t * pc.march.y;
        const vec3 q = origin + t * dir;
        const float l = selectLevel(q, diameter);
        if (l < 0.0) {
            escaped = true; // left the cascade: no indirect light from beyond
            break;
        }
        const int l0 = int(floor(l));
        const float frac = l - float(l0);
        vec4 s = (1.0 - frac) * sampleLevel(l0, q, k);
        if (frac > 0.0 && l0 + 1 < pc.size.z)
            s += frac * sampleLevel(l0 + 1, q, k);
        const float voxelSize = pc.march.x * exp2(l);
        const float dt = pc.march.w * voxelSize;
        const float a = clamp(s.a, 0.0, 1.0);
        if (a > 0.0) {
            const float corrected = 1.0 - pow(1.0 - min(a, 0.999999), dt / voxelSize);
            light += ((1.0 - occupied) * corrected / a) * s.rgb;
            occupied += (1.0 - occupied) * corrected;
            if (occupied >= 0.99)
                break;
        }
        t += dt;
    }
    return vec4(light, 1.0 - occupied);
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
        bool escaped;
        const vec3 light = marchCone(levels[level].origin.xyz + cell * voxelSize, cones[k].xyz, k,
                                     pc.noise.y * voxelSize, 1e30, escaped).rgb;
        farCones[voxel * 16u + uint(k)] = vec4(max(light, vec3(0.0)), 1.0);
        return;
    }

    if (pixel.x >= pc.size.x || pixel.y >= pc.size.y || k >= 16)
        return;
    const int index = pixel.y * pc.size.x + pixel.x;
    if (pc.flags.z != 2)
        coneRadiance[index * 16 + k] = vec4(0.0);
    if (pc.flags.z == 1) {
        // Far cones ("Split Cone Trace"): the 16 cones from a voxel centre, from far start voxels
        // of its level on (CascadeVolume::prepareFarCones).
        const vec4 centre = positions[index];
        if (centre.w == 0.0)
            return;
        const float t0 = pc.noise.y * normals[index].w;
        bool escaped;
        const vec3 light = marchCone(centre.xyz, cones[k].xyz, k, t0, 1e30, escaped).rgb;
        coneRadiance[index * 16 + k] = vec4(max(light, vec3(0.0)), 1.0);
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
    bool escaped;
    vec3 light;
    if (farStart <= 0.0) {
        light = marchCone(origin, dir, k, startDistance, 1e30, escaped).rgb;
    } else {
        const vec4 a = marchCone(origin, dir, k, startDistance, split0, escaped);
        vec3 la = a.rgb;
        if (!escaped)
            la += a.a * sampleFar(l0, origin, k);
        light = la;
        if (two) {
            vec3 lb = a.rgb;
            if (!escaped) {
                bool escapedB;
                const vec4 b = marchCone(origin, dir, k, split0, 2.0 * split0, escapedB);
                lb += a.a * b.rgb;
                if (!escapedB)
                    lb += a.a * b.a * sampleFar(l0 + 1, origin, k);
            }
            light = la + frac * (lb - la);
        }
    }
    coneRadiance[index * 16 + k] = vec4(max(light, vec3(0.0)), 1.0);
}
