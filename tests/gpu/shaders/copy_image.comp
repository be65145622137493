// Copies one storage image to another texel by texel with imageLoad/imageStore.
// Defines: FORMAT (layout qualifier, e.g. rgba32f), IMAGE (e.g. image2D, uimage3D), DIM (2|3).
#version 450

layout(local_size_x = 4, local_size_y = 4, local_size_z = 1) in;

layout(set = 0, binding = 0, FORMAT) uniform readonly IMAGE source;
layout(set = 0, binding = 1, FORMAT) uniform writeonly IMAGE destination;

void main()
{
#if DIM == 2
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
#else
    ivec3 p = ivec3(gl_GlobalInvocationID.xyz);
#endif
    if (any(greaterThanEqual(p, imageSize(source))))
        return;
    imageStore(destination, p, imageLoad(source, p));
}
