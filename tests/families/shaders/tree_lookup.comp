#version 450
// voxel_structure_benchmark's GPU lookups of the adaptive voxel tree: one query per invocation,
// the element found by the tree's own Vulkan lookup (tree_find.glsl, the one the cone gather
// uses) and its payload read; 0 for an absent element.

layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer TopologyBuffer { uint topology[]; };
layout(std430, binding = 1) readonly buffer PayloadBuffer { float payload[]; };
layout(std430, binding = 2) readonly buffer QueryBuffer { ivec4 queries[]; };
layout(std430, binding = 3) writeonly buffer OutputBuffer { float results[]; };

layout(push_constant) uniform Constants {
    ivec4 roots; // xyz: root cells per axis, w: the first node record's uint in topology[]
    ivec4 masks; // x: shared masks' record bits (0: inline), y: first base's uint, z: table's
    ivec4 query; // x: count, y: the level looked up
} pc;

#include "tree_find.glsl"

void main()
{
    const uint i = gl_GlobalInvocationID.x;
    if (i >= uint(pc.query.x))
        return;
    const int e = findTreeElement(pc.query.y, queries[i].xyz, pc.roots, pc.masks);
    results[i] = e >= 0 ? payload[e] : 0.0;
}
