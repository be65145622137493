// Writes (x, y, x * y + 0.5, -x) to every texel of an rgba32f image.
#version 450

layout(local_size_x = 8, local_size_y = 8) in;
layout(set = 0, binding = 0, rgba32f) uniform writeonly image2D target;

void main()
{
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(target))))
        return;
    vec2 f = vec2(p);
    imageStore(target, p, vec4(f.x, f.y, f.x * f.y + 0.5, -f.x));
}
