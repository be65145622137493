#version 450
// voxel_structure_benchmark's GPU lookups of the sparse voxel octree: one query per invocation,
// the node found by the octree's own Vulkan lookup (svo_find.glsl, the one the cone gather uses)
// and its payload read; 0 for an absent node.

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer ChildBuffer { uint children[]; };
layout(std430, binding = 1) readonly buffer PayloadBuffer { float payload[]; };
layout(std430, binding = 2) readonly buffer QueryBuffer { ivec4 queries[]; };
layout(std430, binding = 3) writeonly buffer OutputBuffer { float results[]; };

layout(push_constant) uniform Constants {
    ivec4 query; // x: count, y: the level looked up
} pc;

#include "svo_find.glsl"

void main()
{
    const uint i = gl_GlobalInvocationID.x;
    if (i >= uint(pc.query.x))
        return;
    const int n = findNode(pc.query.y, queries[i].xyz);
    results[i] = n >= 0 ? payload[n] : 0.0;
}
