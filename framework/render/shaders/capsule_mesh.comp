#version 450
// The characters' capsules meshed on the device (render/capsule_mesh_gpu.h): per capsule vertex
// the position and normal scene.cpp's appendCapsule computes, from the unit sphere's template
// (scene::getCapsuleTemplate) and the capsule's ends, radius and frame, written where the vertex
// lies in a vertex buffer. `precise`: no fused multiply-add, so that the float operations are the
// C++ ones (which has none on x86-64 without -mfma) and the vertices match it bit for bit.
layout(local_size_x = 64) in;

layout(std430, binding = 0) readonly buffer TemplateBuffer { vec4 unit[]; }; // cos lat, cos lon, sin lon, sin lat
struct Capsule {
    vec4 a;  // xyz: the lower end, w: radius
    vec4 b;  // xyz: the upper end, w: the first vertex (uint bits)
    vec4 t0; // the capsule's frame: two tangents and its axis
    vec4 t1;
    vec4 up;
};
layout(std430, binding = 1) readonly buffer CapsuleBuffer { Capsule capsules[]; };
layout(std430, binding = 2) buffer VertexBuffer { float vertices[]; };

layout(push_constant) uniform Constants {
    uvec4 counts; // x: capsules, y: vertices per capsule, z: floats per vertex, w: 1 = normals at float 3
} pc;

void main()
{
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.counts.x * pc.counts.y)
        return;
    const uint c = id / pc.counts.y, i = id % pc.counts.y;
    const Capsule k = capsules[c];
    const vec4 e = unit[i];
    // The lower half of the rows sits on a, the upper half on b.
    const vec3 centre = i < pc.counts.y / 2u ? k.a.xyz : k.b.xyz;
    precise const vec3 n = e.x * (e.y * k.t0.xyz + e.z * k.t1.xyz) + e.w * k.up.xyz;
    precise const vec3 p = centre + k.a.w * n;
    const uint at = (floatBitsToUint(k.b.w) + i) * pc.counts.z;
    vertices[at + 0u] = p.x;
    vertices[at + 1u] = p.y;
    vertices[at + 2u] = p.z;
    if (pc.counts.w == 1u) {
        vertices[at + 3u] = n.x;
        vertices[at + 4u] = n.y;
        vertices[at + 5u] = n.z;
    }
}
