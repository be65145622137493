#version 450
// The pixel gather of the sparse voxel octree on Vulkan: per G-buffer pixel, the 16 fixed cones
// above the surface marched front to back through the octree's gathered light, each sample
// quadrilinear (trilinear at the two levels around the cone footprint, every corner found by a
// descent from the root through the child pointers, or with corner bricks one descent per level
// and the node's brick); the same algorithm as
// SparseVoxelOctree::gatherCones (sparse_voxel_octree.cpp, cone_tracing.h marchCone), in float.
// Crassin et al., "Interactive Indirect Illumination Using Voxel Cone Tracing", Pacific Graphics
// 2011, section 4. Positions are relative to the cube's centre (precision far from the origin).
// Asked for the cones' sky (pc.sky.x), the same march (<cone_march.glsl>) also gives each cone's
// sky and emitters past the voxels, the Tomorrow Children's "Sky Light".

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = 0) readonly buffer ChildBuffer { uint children[]; }; // [node]: first child, 0 = none
// [node * 6 + face]: rgb = gathered light premultiplied by the occupancy, a = occupancy; with
// corner bricks (pc.mode.x == 1) [(node * 6 + face) * 8 + corner], corner = x | y << 1 | z << 2:
// the same at the node's corners (sparse_voxel_octree.h).
layout(std430, binding = 1) readonly buffer GatheredBuffer { vec4 gathered[]; };
layout(std430, binding = 2) readonly buffer PositionBuffer { vec4 positions[]; }; // w: 1 = surface
layout(std430, binding = 3) readonly buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = 4) writeonly buffer OutputBuffer { vec4 coneRadiance[]; }; // [pixel][cone]
// [k]: cone k's direction; [16 + k]: the mean sky radiance over its solid angle (pc.sky.x == 1).
layout(std430, binding = 5) readonly buffer ConeBuffer { vec4 cones[32]; };
// [node * 6 + face]: the emitted radiance premultiplied by the occupancy (pc.sky.w == 1).
layout(std430, binding = 6) readonly buffer EmissionBuffer { vec4 emitted[]; };
// [pixel][cone]: the sky and emitters the cone sees past the voxels (pc.sky.x == 1).
layout(std430, binding = 7) writeonly buffer SkyOutputBuffer { vec4 coneSky[]; };

layout(push_constant) uniform Constants {
    ivec4 size;  // width, height, depth (levels below the root), max steps
    vec4 march;  // leaf size, tan(half-angle), start offset (leaves), step scale
    vec4 cube;   // xyz: min corner relative to the centre, w: side
    ivec4 mode;  // x: 1 = corner bricks
    vec4 sky;    // x: 1 = trace the sky, y: sky start (world units), z: 1 = optical depth, w: 1 = emission
} pc;

#include "svo_find.glsl"

float opticalDepthOf(float a)
{
    return -log(1.0 - clamp(a, 0.0, 0.9999));
}

// The optical depth of the three faces seen, with the axes' weights (cone_tracing.h
// ConeSample::depth).
float faceDepth(vec3 axisWeight, vec4 x, vec4 y, vec4 z)
{
    return axisWeight.x * opticalDepthOf(x.a) + axisWeight.y * opticalDepthOf(y.a) + axisWeight.z * opticalDepthOf(z.a);
}

vec4 sampleLevel(int level, vec3 p, vec3 dir, bool wantsDepth, bool wantsEmission, inout vec3 emission,
                 inout float depth)
{
    const float size = pc.cube.w / float(1 << level);
    const vec3 c = (p - pc.cube.xyz) / size - 0.5;
    const vec3 f = floor(c);
    const ivec3 i0 = ivec3(f);
    const vec3 t = c - f;
    // The face a cone travelling along +axis sees is the voxel's -axis face.
    const ivec3 faceSeen = ivec3(0, 2, 4) + ivec3(greaterThan(dir, vec3(0.0)));
    const vec3 axisWeight = dir * dir;
    vec4 acc = vec4(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        const ivec3 d = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const vec3 w3 = mix(vec3(1.0) - t, t, vec3(d));
        const float w = w3.x * w3.y * w3.z;
        if (w == 0.0)
            continue;
        const int node = findNode(level, i0 + d);
        if (node < 0)
            continue;
        const uint base = uint(node) * 6u;
        const vec4 gx = gathered[base + uint(faceSeen.x)], gy = gathered[base + uint(faceSeen.y)],
                   gz = gathered[base + uint(faceSeen.z)];
        acc += w * (axisWeight.x * gx + axisWeight.y * gy + axisWeight.z * gz);
        if (wantsDepth)
            depth += w * faceDepth(axisWeight, gx, gy, gz);
        if (wantsEmission)
            emission += w * (axisWeight.x * emitted[base + uint(faceSeen.x)].rgb +
                             axisWeight.y * emitted[base + uint(faceSeen.y)].rgb +
                             axisWeight.z * emitted[base + uint(faceSeen.z)].rgb);
    }
    return acc;
}

// Corner bricks: one descent to the node of `level` holding p, its brick blended trilinearly.
// Emitters are not bricked (SparseVoxelOctree::sampleBrickLevel reads none either).
vec4 sampleBrickLevel(int level, vec3 p, vec3 dir, bool wantsDepth, inout float depth)
{
    const int cells = 1 << level;
    const vec3 q = (p - pc.cube.xyz) / pc.cube.w * float(cells);
    const ivec3 cell = clamp(ivec3(floor(q)), ivec3(0), ivec3(cells - 1));
    const vec3 t = clamp(q - vec3(cell), vec3(0.0), vec3(1.0));
    const int node = findNode(level, cell);
    if (node < 0)
        return vec4(0.0);
    const ivec3 faceSeen = ivec3(0, 2, 4) + ivec3(greaterThan(dir, vec3(0.0)));
    const vec3 axisWeight = dir * dir;
    vec4 acc = vec4(0.0);
    for (int corner = 0; corner < 8; ++corner) {
        const ivec3 d = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const vec3 w3 = mix(vec3(1.0) - t, t, vec3(d));
        const float w = w3.x * w3.y * w3.z;
        const uint base = uint(node) * 48u + uint(corner);
        const vec4 gx = gathered[base + 8u * uint(faceSeen.x)], gy = gathered[base + 8u * uint(faceSeen.y)],
                   gz = gathered[base + 8u * uint(faceSeen.z)];
        acc += w * (axisWeight.x * gx + axisWeight.y * gy + axisWeight.z * gz);
        if (wantsDepth)
            depth += w * faceDepth(axisWeight, gx, gy, gz);
    }
    return acc;
}

vec4 sampleAt(int level, vec3 p, vec3 dir, bool wantsDepth, bool wantsEmission, inout vec3 emission,
              inout float depth)
{
    return pc.mode.x == 1 ? sampleBrickLevel(level, p, dir, wantsDepth, depth)
                          : sampleLevel(level, p, dir, wantsDepth, wantsEmission, emission, depth);
}

bool insideCube(vec3 p)
{
    const vec3 rel = (p - pc.cube.xyz) / pc.cube.w;
    return all(greaterThanEqual(rel, vec3(0.0))) && all(lessThanEqual(rel, vec3(1.0)));
}

// The quadrilinear sample of cone_march.glsl: the level whose voxels are as wide as the
// footprint and the next coarser one, blended linearly.
bool sampleCone(vec3 q, float diameter, vec3 dir, int cone, bool wantsDepth, bool wantsEmission, out vec4 s,
                out vec3 emission, out float depth, out float voxelSize)
{
    emission = vec3(0.0);
    depth = 0.0;
    if (!insideCube(q))
        return false; // left the cube: no light from beyond
    const float leaf = pc.march.x;
    const int levels = pc.size.z;
    const float m = min(float(levels), diameter > leaf ? log2(diameter / leaf) : 0.0);
    const int m0 = int(floor(m));
    const float frac = m - float(m0);
    wantsEmission = wantsEmission && pc.sky.w == 1.0;
    vec3 e0 = vec3(0.0), e1 = vec3(0.0);
    float d0 = 0.0, d1 = 0.0;
    s = (1.0 - frac) * sampleAt(levels - m0, q, dir, wantsDepth, wantsEmission, e0, d0);
    if (frac > 0.0 && m0 < levels)
        s += frac * sampleAt(levels - m0 - 1, q, dir, wantsDepth, wantsEmission, e1, d1);
    emission = (1.0 - frac) * e0 + frac * e1;
    depth = (1.0 - frac) * d0 + frac * d1;
    voxelSize = leaf * exp2(m);
    return true;
}

#include <cone_march.glsl>

void main()
{
    // One cone per invocation (z: the cone), so that a warp holds neighbouring pixels' cones of
    // one direction: 16 times the parallelism of a pixel per invocation, and coherent steps.
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    const int k = int(gl_GlobalInvocationID.z);
    if (pixel.x >= pc.size.x || pixel.y >= pc.size.y || k >= 16)
        return;
    const int index = pixel.y * pc.size.x + pixel.x;
    const bool sky = pc.sky.x == 1.0;
    coneRadiance[index * 16 + k] = vec4(0.0);
    if (sky)
        coneSky[index * 16 + k] = vec4(0.0);
    const vec4 position = positions[index];
    const vec3 n = normals[index].xyz;
    if (position.w == 0.0 || dot(n, n) < 0.5 || !insideCube(position.xyz))
        return;
    const float leaf = pc.march.x;
    if (dot(cones[k].xyz, n) <= 0.0)
        return;
    // Start a leaf out, along the normal and along the cone (SparseVoxelOctree::preparePixel).
    ConeMarch m;
    m.t0 = pc.march.z * leaf;
    m.tMax = 1e30;
    m.tanHalfAngle = pc.march.y;
    m.stepScale = pc.march.w;
    m.maxSteps = pc.size.w;
    m.sky = sky;
    m.opticalDepth = pc.sky.z == 1.0;
    m.skyStart = pc.sky.y;
    m.planeNormal = n;
    m.planeHeight = 0.5 * pc.march.z * leaf;
    const ConeTrace r = marchCone(position.xyz + n * (0.5 * pc.march.z * leaf), cones[k].xyz, k, m);
    coneRadiance[index * 16 + k] = vec4(max(r.light, vec3(0.0)), 1.0);
    if (sky)
        coneSky[index * 16 + k] = vec4(getConeSkyRadiance(r, cones[16 + k].rgb), 1.0);
}
