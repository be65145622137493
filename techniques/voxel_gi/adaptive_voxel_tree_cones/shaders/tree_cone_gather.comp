#version 450
// The pixel gather of the adaptive voxel tree on Vulkan: per G-buffer pixel, the 16 fixed cones
// above the surface marched front to back through the tree's gathered light, each sample
// trilinear at the two levels around the cone footprint (4x apart) and linear between them; every
// corner found by a descent from its dense root cell (whose node record is the cell's); below the
// roots an element's node record found by rank (voxel_tree.h: base of its 64-element word + the
// set bits below it). The child index is Quantum Break's offset +
// popcount of the mask bits below the child's (Silvennoinen & Timonen, SIGGRAPH 2015, "Adaptive
// Voxel Tree"), the 64-bit popcount as two 32-bit bitCounts. The same algorithm as
// VoxelTreeCones::gatherCones (voxel_tree_cones.cpp, cone_tracing.h marchCone), in float.
// Positions are relative to the lattice's centre (precision far from the origin). Asked for the
// cones' sky (pc.sky.x), the same march (<cone_march.glsl>) also gives each cone's sky and
// emitters past the voxels, the Tomorrow Children's "Sky Light".

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

// [word * 3 + 0, 1, 2]: which of 64 upper-level elements have children (low, high 32 bits), and
// how many before the word do; then from pc.roots.w the node records. Inline masks
// (pc.masks.x == 0): [record * 3 + 0, 1, 2] = child mask low and high 32 bits, offset of the
// first child. Shared masks (voxel_tree.h): record r is the bit field of pc.masks.x bits at bit
// r * pc.masks.x, low bits first, = mask table index << 12 | offset from the base of its 64
// records; from pc.masks.y [record / 64] = that base; from pc.masks.z [index * 2 + 0, 1] = the
// mask's low and high 32 bits.
layout(std430, binding = 0) readonly buffer TopologyBuffer { uint topology[]; };
// [element * 6 + face]: rgb = gathered light premultiplied by the occupancy, a = occupancy.
layout(std430, binding = 1) readonly buffer GatheredBuffer { vec4 gathered[]; };
layout(std430, binding = 2) readonly buffer PositionBuffer { vec4 positions[]; }; // w: 1 = surface
layout(std430, binding = 3) readonly buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = 4) writeonly buffer OutputBuffer { vec4 coneRadiance[]; }; // [pixel][cone]
// [k]: cone k's direction; [16 + k]: the mean sky radiance over its solid angle (pc.sky.x == 1).
layout(std430, binding = 5) readonly buffer ConeBuffer { vec4 cones[32]; };
// [element * 6 + face]: the emitted radiance premultiplied by the occupancy (pc.sky.w == 1).
layout(std430, binding = 6) readonly buffer EmissionBuffer { vec4 emitted[]; };
// [pixel][cone]: the sky and emitters the cone sees past the voxels (pc.sky.x == 1).
layout(std430, binding = 7) writeonly buffer SkyOutputBuffer { vec4 coneSky[]; };

layout(push_constant) uniform Constants {
    ivec4 size;  // width, height, depth (levels below the roots), max steps
    vec4 march;  // leaf size, tan(half-angle), start offset (leaves), step scale
    vec4 box;    // xyz: min corner relative to the centre
    ivec4 roots; // xyz: root cells per axis, w: the first node record's uint in topology[]
    ivec4 masks; // x: shared masks' record bits (0: inline), y: first base's uint, z: table's first
    vec4 sky;    // x: 1 = trace the sky, y: sky start (world units), z: 1 = optical depth, w: 1 = emission
} pc;

#include "tree_find.glsl"

int findElement(int level, ivec3 c)
{
    return findTreeElement(level, c, pc.roots, pc.masks);
}

float opticalDepthOf(float a)
{
    return -log(1.0 - clamp(a, 0.0, 0.9999));
}

vec4 sampleLevel(int level, vec3 p, vec3 dir, bool wantsDepth, bool wantsEmission, inout vec3 emission,
                 inout float depth)
{
    const float size = pc.march.x * exp2(float(2 * (pc.size.z - level)));
    const vec3 c = (p - pc.box.xyz) / size - 0.5;
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
        const int e = findElement(level, i0 + d);
        if (e < 0)
            continue;
        const uint base = uint(e) * 6u;
        const vec4 gx = gathered[base + uint(faceSeen.x)], gy = gathered[base + uint(faceSeen.y)],
                   gz = gathered[base + uint(faceSeen.z)];
        acc += w * (axisWeight.x * gx + axisWeight.y * gy + axisWeight.z * gz);
        // The voxels' optical depths with the same weights (cone_tracing.h ConeSample::depth).
        if (wantsDepth)
            depth += w * (axisWeight.x * opticalDepthOf(gx.a) + axisWeight.y * opticalDepthOf(gy.a) +
                          axisWeight.z * opticalDepthOf(gz.a));
        if (wantsEmission)
            emission += w * (axisWeight.x * emitted[base + uint(faceSeen.x)].rgb +
                             axisWeight.y * emitted[base + uint(faceSeen.y)].rgb +
                             axisWeight.z * emitted[base + uint(faceSeen.z)].rgb);
    }
    return acc;
}

bool insideBox(vec3 p)
{
    const vec3 extent = vec3(pc.roots.xyz) * (pc.march.x * exp2(float(2 * pc.size.z)));
    const vec3 rel = (p - pc.box.xyz) / extent;
    return all(greaterThanEqual(rel, vec3(0.0))) && all(lessThanEqual(rel, vec3(1.0)));
}

// The sample of cone_march.glsl: trilinear at the two levels around the footprint (4x apart),
// linear between them.
bool sampleCone(vec3 q, float diameter, vec3 dir, int cone, bool wantsDepth, bool wantsEmission, out vec4 s,
                out vec3 emission, out float depth, out float voxelSize)
{
    emission = vec3(0.0);
    depth = 0.0;
    if (!insideBox(q))
        return false; // left the lattice: no light from beyond
    const float leaf = pc.march.x;
    const int levels = pc.size.z;
    const float m = min(float(levels), diameter > leaf ? 0.5 * log2(diameter / leaf) : 0.0);
    const int m0 = int(floor(m));
    const float frac = m - float(m0);
    wantsEmission = wantsEmission && pc.sky.w == 1.0;
    vec3 e0 = vec3(0.0), e1 = vec3(0.0);
    float d0 = 0.0, d1 = 0.0;
    s = (1.0 - frac) * sampleLevel(levels - m0, q, dir, wantsDepth, wantsEmission, e0, d0);
    if (frac > 0.0 && m0 < levels)
        s += frac * sampleLevel(levels - m0 - 1, q, dir, wantsDepth, wantsEmission, e1, d1);
    emission = (1.0 - frac) * e0 + frac * e1;
    depth = (1.0 - frac) * d0 + frac * d1;
    voxelSize = leaf * exp2(2.0 * m);
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
    if (position.w == 0.0 || dot(n, n) < 0.5 || !insideBox(position.xyz))
        return;
    const float leaf = pc.march.x;
    if (dot(cones[k].xyz, n) <= 0.0)
        return;
    // Start a leaf out, along the normal and along the cone (VoxelTreeCones::preparePixel).
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
