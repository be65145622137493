#version 450
// Light injection of the voxel texture cascades on Vulkan: per surface voxel of the level being
// lit, the 16 fixed cones marched front to back through the levels' light buffers (every face's
// occupancy, emission, direct and first-bounce light, the three faces a direction sees blended
// by its squared components), the sky where a cone leaves the cascade, and a thin shadow cone
// toward each point light; out come the irradiance per face of the three fields a pass writes
// (E_0 from emission, sky and point lights, E_1 from the direct buffer, E_2 from the first
// bounce). The same algorithm as voxelgi::gatherVoxelIrradiance and marchCone
// (framework/families/voxel_gi/cone_tracing.h) over CascadeVolume::sampleFields, in float.
// The Tomorrow Children, GDC 2015 (seed shared/seeds/000_3da000e866ebc485.txt, "Core Lighting
// Update Logic", "Sky Light", "Point Lights", "Bounce Light").

layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

#include "cascade_common.glsl"

// [level][voxel][face][3]: (emission, occupancy), (direct, 0), (first bounce, 0); light
// premultiplied by the occupancy, as CascadeVolume::Level::light.
layout(std430, binding = 1) readonly buffer FieldBuffer { vec4 fields[]; };
// [surface voxel][2]: centre relative to the anchor, mean normal (may be 0).
layout(std430, binding = 2) readonly buffer VoxelBuffer { vec4 voxels[]; };
// [surface voxel][field 0..2][face]: irradiance E_0, E_1, E_2.
layout(std430, binding = 3) writeonly buffer OutputBuffer { vec4 irradiance[]; };
layout(std430, binding = 4) readonly buffer ConeBuffer { vec4 cones[16]; };
layout(std430, binding = 5) readonly buffer SkyBuffer { vec4 skyPerCone[16]; };
// [light][2]: position relative to the anchor, intensity.
layout(std430, binding = 6) readonly buffer LightBuffer { vec4 pointLights[]; };

layout(push_constant) uniform Constants {
    ivec4 size;   // surface voxels, levels, resolution, point lights
    vec4 march;   // level-0 voxel size, tan(half-angle), start offset (voxels), step scale
    vec4 inject;  // voxel size of the lit level, shadow-cone tan, max opacity, 1 = sky
    ivec4 flags;  // x: max steps
} pc;

// The occupancy and the three fields seen along `dir` at p, level `level`, weight `weight`
// (CascadeVolume::sampleLevel with gathered = false).
void sampleFields(int level, vec3 p, vec3 dir, float weight, inout float alpha, inout vec3 emission,
                  inout vec3 direct, inout vec3 bounce)
{
    const int R = pc.size.z;
    ivec3 i0;
    vec3 t;
    getTrilinear(level, p, R, i0, t);
    const uint base = uint(level) * uint(R) * uint(R) * uint(R);
    for (int corner = 0; corner < 8; ++corner) {
        ivec3 d;
        const float w = getCornerWeight(corner, t, d);
        if (w == 0.0)
            continue;
        const ivec3 v = i0 + d;
        const uint voxel = base + uint(v.x + R * (v.y + R * v.z));
        for (int axis = 0; axis < 3; ++axis) {
            const float aw = w * weight * dir[axis] * dir[axis];
            if (aw == 0.0)
                continue;
            // The face a cone travelling along +axis sees is the voxel's -axis face.
            const uint face = uint(2 * axis + (dir[axis] > 0.0 ? 1 : 0));
            const uint f = (voxel * 6u + face) * 3u;
            const vec4 e = fields[f];
            alpha += aw * e.a;
            emission += aw * e.rgb;
            direct += aw * fields[f + 1u].rgb;
            bounce += aw * fields[f + 2u].rgb;
        }
    }
}

// One cone from `origin` along `dir` (voxelgi::marchCone): the three fields' radiance, the
// transmittance, and whether it left the cascade.
void marchCone(vec3 origin, vec3 dir, float tanHalf, float t0, float tMax, out vec3 emission,
               out vec3 direct, out vec3 bounce, out float transmittance, out bool escaped)
{
    float occupied = 0.0;
    emission = vec3(0.0);
    direct = vec3(0.0);
    bounce = vec3(0.0);
    escaped = false;
    float t = t0;
    for (int step = 0; step < pc.flags.x; ++step) {
        if (t >= tMax)
            break;
        const vec3 q = origin + t * dir;
        const float l = selectLevel(q, 2.0 * t * tanHalf, pc.size.y, pc.march.x, 0.0, ivec3(0));
        if (l < 0.0) {
            escaped = true;
            break;
        }
        const int l0 = int(floor(l));
        const float frac = l - float(l0);
        float a = 0.0;
        vec3 se = vec3(0.0), sd = vec3(0.0), sb = vec3(0.0);
        sampleFields(l0, q, dir, 1.0 - frac, a, se, sd, sb);
        if (frac > 0.0 && l0 + 1 < pc.size.y)
            sampleFields(l0 + 1, q, dir, frac, a, se, sd, sb);
        const float voxelSize = pc.march.x * exp2(l);
        const float dt = pc.march.w * voxelSize;
        a = clamp(a, 0.0, 1.0);
        if (a > 0.0) {
            // Step-length-corrected opacity (Engel et al., Real-Time Volume Graphics).
            const float corrected = 1.0 - pow(1.0 - min(a, 0.999999), dt / voxelSize);
            const float w = (1.0 - occupied) * corrected / a;
            emission += w * se;
            direct += w * sd;
            bounce += w * sb;
            occupied += (1.0 - occupied) * corrected;
            if (occupied >= pc.inject.z)
                break;
        }
        t += dt;
    }
    transmittance = 1.0 - occupied;
}

// The face's shading normal: the voxel's normal when it faces that side, else the face's axis.
vec3 getShadingNormal(vec3 n, int face)
{
    vec3 axis = vec3(0.0);
    axis[face / 2] = (face % 2 == 0) ? 1.0 : -1.0;
    return dot(n, axis) > 0.0 ? n : axis;
}

void main()
{
    const int s = int(gl_GlobalInvocationID.x);
    if (s >= pc.size.x)
        return;
    const vec3 centre = voxels[2 * s].xyz;
    const vec3 n = voxels[2 * s + 1].xyz;
    const float v = pc.inject.x;
    const vec3 origin = centre + n * (0.5 * pc.march.z * v);
    const float startDistance = pc.march.z * v;

    // Per face, the cosine weights of the 16 cones normalised to pi (voxelgi's
    // computeIrradianceWeights): their sums first.
    vec3 shading[6];
    float weightSum[6];
    for (int face = 0; face < 6; ++face) {
        shading[face] = getShadingNormal(n, face);
        weightSum[face] = 0.0;
        for (int k = 0; k < 16; ++k)
            weightSum[face] += max(0.0, dot(cones[k].xyz, shading[face]));
    }
    vec3 e0[6], e1[6], e2[6];
    for (int face = 0; face < 6; ++face) {
        e0[face] = vec3(0.0);
        e1[face] = vec3(0.0);
        e2[face] = vec3(0.0);
    }
    for (int k = 0; k < 16; ++k) {
        const vec3 dir = cones[k].xyz;
        vec3 emission, direct, bounce;
        float transmittance;
        bool escaped;
        marchCone(origin, dir, pc.march.y, startDistance, 1e30, emission, direct, bounce,
                  transmittance, escaped);
        // The sky as 16 lobes on the cone directions, seen by the cones that leave the cascade.
        if (escaped && pc.inject.w > 0.0)
            emission += transmittance * skyPerCone[k].rgb;
        for (int face = 0; face < 6; ++face) {
            const float c = max(0.0, dot(dir, shading[face]));
            if (c == 0.0 || weightSum[face] <= 0.0)
                continue;
            const float w = c * 3.14159265358979 / weightSum[face];
            e0[face] += w * emission;
            e1[face] += w * direct;
            e2[face] += w * bounce;
        }
    }
    // Point lights: inverse-square irradiance, shadowed by a thin cone toward the light.
    for (int i = 0; i < pc.size.w; ++i) {
        const vec3 toLight = pointLights[2 * i].xyz - origin;
        const float d2 = dot(toLight, toLight);
        if (!(d2 > 0.0))
            continue;
        const float d = sqrt(d2);
        const vec3 l = toLight / d;
        vec3 emission, direct, bounce;
        float visible;
        bool escaped;
        marchCone(origin, l, pc.inject.y, startDistance, d, emission, direct, bounce, visible, escaped);
        if (visible <= 0.0)
            continue;
        for (int face = 0; face < 6; ++face) {
            const float c = dot(shading[face], l);
            if (c > 0.0)
                e0[face] += pointLights[2 * i + 1].rgb * (c * visible / d2);
        }
    }
    for (int face = 0; face < 6; ++face) {
        irradiance[(s * 3 + 0) * 6 + face] = vec4(e0[face], 0.0);
        irradiance[(s * 3 + 1) * 6 + face] = vec4(e1[face], 0.0);
        irradiance[(s * 3 + 2) * 6 + face] = vec4(e2[face], 0.0);
    }
}
