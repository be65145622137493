#version 450
// The view-space inputs of screen-space techniques, from the G-buffer on the GPU
// (render/view_inputs_pass.h): linear depth, and the world normal turned into view space
// (zero where there is no surface), as the CPU path of pipeline/frame_start.cpp computes them.
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D gPositionDepth; // xyz world, w linear depth
layout(binding = 1, rgba32f) uniform readonly image2D gNormal;        // world normal
layout(binding = 2, r32f) uniform writeonly image2D outDepth;
layout(binding = 3, rgba32f) uniform writeonly image2D outNormal;

layout(push_constant) uniform Push {
    mat4 view;  // world -> view
    uvec4 size; // width, height
} pc;

void main()
{
    const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.size.x) || p.y >= int(pc.size.y))
        return;
    const float depth = imageLoad(gPositionDepth, p).w;
    const vec3 n = imageLoad(gNormal, p).xyz;
    const bool surface = !isinf(depth) && !isnan(depth) && dot(n, n) > 0.0;
    imageStore(outDepth, p, vec4(depth, 0.0, 0.0, 0.0));
    imageStore(outNormal, p, vec4(surface ? normalize(mat3(pc.view) * n) : vec3(0.0), 0.0));
}
