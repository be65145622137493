#version 450
// The reduced G-buffer of a cone-traced gather made on the device from the G-buffer's GPU images
// (families/voxel_gi/cone_gather_gpu.h PixelConeDispatch::preparePixels): per block of
// factor x factor pixels one representative, the block's centre pixel when it has a surface,
// else its first surface pixel in row order, else none, exactly as voxelgi::reduceGBuffer
// (upsample.cpp) picks it; its position relative to the structure's anchor (w = 1 for a surface)
// and its normal, as PixelConeDispatch::uploadPixels lays them out, and its index for the combine.
// The Tomorrow Children traced its pixel cones at a quarter of each dimension
// (shared/seeds/000_3da000e866ebc485.txt, "Trace at a lower resolution").
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D gPositionDepth; // xyz world, w linear depth (inf: none)
layout(binding = 1, rgba32f) uniform readonly image2D gNormal;        // world normal
layout(std430, binding = 2) writeonly buffer PositionBuffer { vec4 positions[]; };
layout(std430, binding = 3) writeonly buffer NormalBuffer { vec4 normals[]; };
layout(std430, binding = 4) writeonly buffer RepresentativeBuffer { int representative[]; }; // full pixel, -1: none

layout(push_constant) uniform Constants {
    ivec4 size;       // full width, height; reduced width, height
    ivec4 factor;     // x: block size
    vec4 anchorHigh;  // the anchor as float, and what it left (anchor = high + low to double precision)
    vec4 anchorLow;
} pc;

bool hasSurface(ivec2 p)
{
    const float d = imageLoad(gPositionDepth, p).w;
    return !isinf(d) && !isnan(d);
}

void main()
{
    const ivec2 b = ivec2(gl_GlobalInvocationID.xy);
    if (b.x >= pc.size.z || b.y >= pc.size.w)
        return;
    const int f = pc.factor.x, w = pc.size.x, h = pc.size.y;
    const ivec2 c = min(b * f + f / 2, ivec2(w - 1, h - 1));
    int chosen = hasSurface(c) ? c.y * w + c.x : -1;
    for (int y = b.y * f; chosen < 0 && y < min(h, (b.y + 1) * f); ++y)
        for (int x = b.x * f; chosen < 0 && x < min(w, (b.x + 1) * f); ++x)
            if (hasSurface(ivec2(x, y)))
                chosen = y * w + x;
    const int s = b.y * pc.size.z + b.x;
    representative[s] = chosen;
    vec4 position = vec4(0.0), normal = vec4(0.0);
    if (chosen >= 0) {
        const ivec2 q = ivec2(chosen % w, chosen / w);
        const vec3 p = imageLoad(gPositionDepth, q).xyz;
        normal = vec4(imageLoad(gNormal, q).xyz, 0.0);
        // Relative to the anchor in two steps: p - high is exact near the anchor (Sterbenz), so
        // the result is the double difference rounded once, as the upload computes it. `precise`
        // keeps the compiler from reassociating the two subtractions into p - (high + low),
        // which loses the low part (Mesa's NIR does so otherwise).
        precise vec3 near = p - pc.anchorHigh.xyz;
        precise vec3 relative = near - pc.anchorLow.xyz;
        if (!any(isinf(p)) && !any(isnan(p)))
            position = vec4(relative, 1.0);
    }
    positions[s] = position;
    normals[s] = normal;
}
