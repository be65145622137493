#version 450
// The pixel gather of the sparse voxel octree on Vulkan: per G-buffer pixel, the 16 fixed cones
// above the surface marched front to back through the octree's gathered light, each sample
// quadrilinear (trilinear at the two levels around the cone footprint, every corner found by a
// descent from the root through the child pointers, or with corner bricks one descent per level
// and the node's brick); the same algorithm as
// SparseVoxelOctree::gatherCones (sparse_voxel_octree.cpp, cone_tracing.h marchCone), in float.
// Crassin et al., "Interactive Indirect Illumination Using Voxel Cone Tracing", Pacific Graphics
// 2011, section 4. Positions are relative to the cube's centre (precision far from the origin).

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(std430, binding = 0) readonly buffer ChildBuffer { uint children[]; }; // [node]: first child, 0 = none
// [node * 6 + face]: rgb = gathered light premultiplied by the occupancy, a = occupancy; with
// corner bricks (pc.mode.x == 1) [(node * 6 + face) * 8 + corner], corner = x | y << 1 | z << 2:
// the same at the node's corners (sparse_voxel_octree.h).
layout(std430, binding = 1) readonly buffer GatheredBuffer { vec4 gathered[]; };
layout(std430, binding = 2) readonly buffer PositionBuffer { vec4 positions[]; }; // w: 1 = surface
layout(std430, binding = 3) readonly buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = 4) writeonly buffer OutputBuffer { vec4 coneRadiance[]; }; // [pixel][cone]
layout(std430, binding = 5) readonly buffer ConeBuffer { vec4 cones[16]; };

layout(push_constant) uniform Constants {
    ivec4 size;  // width, height, depth (levels below the root), max steps
    vec4 march;  // leaf size, tan(half-angle), start offset (leaves), step scale
    vec4 cube;   // xyz: min corner relative to the centre, w: side
    ivec4 mode;  // x: 1 = corner bricks
} pc;

#include "svo_find.glsl"

vec4 sampleLevel(int level, vec3 p, vec3 dir)
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
        acc += w * (axisWeight.x * gathered[base + uint(faceSeen.x)] +
                    axisWeight.y * gathered[base + uint(faceSeen.y)] +
                    axisWeight.z * gathered[base + uint(faceSeen.z)]);
    }
    return acc;
}

// Corner bricks: one descent to the node of `level` holding p, its brick blended trilinearly.
vec4 sampleBrickLevel(int level, vec3 p, vec3 dir)
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
        acc += w * (axisWeight.x * gathered[base + 8u * uint(faceSeen.x)] +
                    axisWeight.y * gathered[base + 8u * uint(faceSeen.y)] +
                    axisWeight.z * gathered[base + 8u * uint(faceSeen.z)]);
    }
    return acc;
}

vec4 sampleAt(int level, vec3 p, vec3 dir)
{
    return pc.mode.x == 1 ? sampleBrickLevel(level, p, dir) : sampleLevel(level, p, dir);
}

bool insideCube(vec3 p)
{
    const vec3 rel = (p - pc.cube.xyz) / pc.cube.w;
    return all(greaterThanEqual(rel, vec3(0.0))) && all(lessThanEqual(rel, vec3(1.0)));
}

void main()
{
    // One cone per invocation (z: the cone), so that a warp holds neighbouring pixels' cones of
    // one direction: 16 times the parallelism of a pixel per invocation, and coherent steps.
    const ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    const int k = int(gl_GlobalInvocationID.z);
    if (pixel.x >= pc.size.x || pixel.y >= pc.size.y || k >= 16)
        return;
    const int index = pixel.y * pc.size.x + pixel.x;
    coneRadiance[index * 16 + k] = vec4(0.0);
    const vec4 position = positions[index];
    const vec3 n = normals[index].xyz;
    if (position.w == 0.0 || dot(n, n) < 0.5 || !insideCube(position.xyz))
        return;
    const float leaf = pc.march.x;
    const int depth = pc.size.z;
    const vec3 origin = position.xyz + n * (0.5 * pc.march.z * leaf);
    const float startDistance = pc.march.z * leaf;
    if (dot(cones[k].xyz, n) <= 0.0)
        return;
    const vec3 dir = cones[k].xyz;
    float occupied = 0.0;
    vec3 light = vec3(0.0);
    float t = startDistance;
    for (int step = 0; step < pc.size.w; ++step) {
        const vec3 q = origin + t * dir;
        if (!insideCube(q))
            break; // left the cube: no indirect light from beyond
        const float diameter = 2.0 * t * pc.march.y;
        const float m = min(float(depth), diameter > leaf ? log2(diameter / leaf) : 0.0);
        const int m0 = int(floor(m));
        const float frac = m - float(m0);
        vec4 s = (1.0 - frac) * sampleAt(depth - m0, q, dir);
        if (frac > 0.0 && m0 < depth)
            s += frac * sampleAt(depth - m0 - 1, q, dir);
        const float voxelSize = leaf * exp2(m);
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
    coneRadiance[index * 16 + k] = vec4(max(light, vec3(0.0)), 1.0);
}
