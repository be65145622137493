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

struct Level {
    vec4 origin; // xyz: min corner relative to the anchor, w: voxel size
    vec4 centre; // xyz: centre relative to the anchor, w: radius of the sphere that selects it (< 0: empty)
};

layout(std430, binding = 0) readonly buffer LevelBuffer { Level levels[]; };
// [level][voxel][cone]: rgb = light premultiplied by the occupancy, a = occupancy.
layout(std430, binding = 1) readonly buffer CombinedBuffer { vec4 combined[]; };
layout(std430, binding = 2) readonly buffer PositionBuffer { vec4 positions[]; }; // w: 1 = surface
layout(std430, binding = 3) readonly buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = 4) writeonly buffer OutputBuffer { vec4 coneRadiance[]; }; // [pixel][cone]
layout(std430, binding = 5) readonly buffer ConeBuffer { vec4 cones[16]; };
// Split near/far cones (noise.y > 0): [level][voxel] the slot of the voxel centre's far cones
// (~0u: not traced), and [slot][cone] their radiance (CascadeVolume::prepareFarCones).
layout(std430, binding = 6) readonly buffer FarSlotBuffer { uint farSlots[]; };
layout(std430, binding = 7) readonly buffer FarConeBuffer { vec4 farCones[]; };

layout(push_constant) uniform Constants {
    ivec4 size;  // width, height, levels, resolution
    vec4 march;  // level-0 voxel size, tan(half-angle), start offset (voxels), step scale
    ivec4 flags; // y: max steps
    ivec4 anchorCell; // xyz: the anchor in level-0 voxels
    vec4 noise;       // x: level noise (of a level's radius), y: far start (level voxels; 0: off)
} pc;

// pcg3d (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 2020) to 24 bits, and
// the value noise on the level-0 voxel lattice: CascadeVolume's computeValueNoise.
float hashToUnit(uvec3 v)
{
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return float(v.x >> 8u) * (1.0 / 16777216.0);
}

float valueNoise(vec3 p)
{
    const vec3 u = p / pc.march.x;
    const vec3 c = floor(u);
    const vec3 f = u - c;
    const ivec3 cell = pc.anchorCell.xyz + ivec3(c);
    float n = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const ivec3 d = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const float w = (d.x == 1 ? f.x : 1.0 - f.x) * (d.y == 1 ? f.y : 1.0 - f.y) *
                        (d.z == 1 ? f.z : 1.0 - f.z);
        n += w * hashToUnit(uvec3(cell + d));
    }
    return n;
}

float selectLevel(vec3 p, float diameter)
{
    const int n = pc.size.z;
    float containing = -1.0;
    for (int i = 0; i < n; ++i) {
        const float radius = levels[i].centre.w;
        if (radius <= 0.0)
            continue;
        const float r = length(p - levels[i].centre.xyz) / radius;
        if (r <= 1.0) {
            // The talk's "3D noise offset" on the blend; the containment test stays exact.
            const float blend = pc.noise.x > 0.0 ? r + pc.noise.x * (2.0 * valueNoise(p) - 1.0) : r;
            containing = float(i) + (i + 1 < n ? clamp((blend - 0.5) / 0.5, 0.0, 1.0) : 0.0);
            break;
        }
    }
    if (containing < 0.0)
        return -1.0;
    const float footprint = diameter > pc.march.x ? log2(diameter / pc.march.x) : 0.0;
    return min(float(n - 1), max(containing, footprint));
}

vec4 sampleLevel(int level, vec3 p, int cone)
{
    const int R = pc.size.w;
    vec3 c = (p - levels[level].origin.xyz) / levels[level].origin.w - 0.5;
    c = clamp(c, vec3(0.0), vec3(float(R - 1)));
    const ivec3 i0 = min(ivec3(floor(c)), ivec3(R - 2));
    const vec3 t = c - vec3(i0);
    const uint base = uint(level) * uint(R) * uint(R) * uint(R);
    vec4 acc = vec4(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        const ivec3 d = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const vec3 w3 = mix(vec3(1.0) - t, t, vec3(d));
        const float w = w3.x * w3.y * w3.z;
        if (w == 0.0)
            continue;
        const ivec3 v = i0 + d;
        const uint voxel = base + uint(v.x + R * (v.y + R * v.z));
        acc += w * combined[voxel * 16u + uint(cone)];
    }
    return acc;
}

// The far cones' radiance at p for cone `cone`, trilinear over level `level`'s voxel centres
// (the lattice and clamping of sampleLevel).
vec3 sampleFar(int level, vec3 p, int cone)
{
    const int R = pc.size.w;
    vec3 c = (p - levels[level].origin.xyz) / levels[level].origin.w - 0.5;
    c = clamp(c, vec3(0.0), vec3(float(R - 1)));
    const ivec3 i0 = min(ivec3(floor(c)), ivec3(R - 2));
    const vec3 t = c - vec3(i0);
    const uint base = uint(level) * uint(R) * uint(R) * uint(R);
    vec3 acc = vec3(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        const ivec3 d = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const vec3 w3 = mix(vec3(1.0) - t, t, vec3(d));
        const float w = w3.x * w3.y * w3.z;
        if (w == 0.0)
            continue;
        const ivec3 v = i0 + d;
        const uint slot = farSlots[base + uint(v.x + R * (v.y + R * v.z))];
        if (slot != 0xffffffffu)
            acc += w * farCones[slot * 16u + uint(cone)].rgb;
    }
    return acc;
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
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= pc.size.x || pixel.y >= pc.size.y)
        return;
    const int index = pixel.y * pc.size.x + pixel.x;
    for (int k = 0; k < 16; ++k)
        coneRadiance[index * 16 + k] = vec4(0.0);
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
    for (int k = 0; k < 16; ++k) {
        if (dot(cones[k].xyz, n) <= 0.0)
            continue;
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
}
