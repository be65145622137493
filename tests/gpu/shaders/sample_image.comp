// results[i] = texture(image, coords[i].xyz): samples a 2D or 3D texture at given normalised
// coordinates. Defines: SAMPLER (sampler2D|sampler3D), DIM (2|3).
#version 450

layout(local_size_x = 32) in;

layout(set = 0, binding = 0) uniform SAMPLER image;
layout(set = 0, binding = 1) readonly buffer Coords { vec4 coords[]; };
layout(set = 0, binding = 2) writeonly buffer Results { vec4 results[]; };

layout(push_constant) uniform Params { uint count; } params;

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.count)
        return;
#if DIM == 2
    results[i] = textureLod(image, coords[i].xy, 0.0);
#else
    results[i] = textureLod(image, coords[i].xyz, 0.0);
#endif
}
