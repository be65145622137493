// Pass 3 "lsao.resolve" of Line-Sweep Ambient Obscurance: one invocation per pixel. Averages the
// per-direction sums of the gather over the interleave x interleave window around the pixel
// (one pixel of every direction class, [Quantum Break seed: "We cycle through the 36 directions
// on 9 pixel neighborhoods"]), each neighbour's sums scaled from its share of the directions to
// all of them, over the neighbours on the pixel's surface (lsaoIsSameSurface), then turns them
// into the outputs: outA = (bent normal, aperture), outB = ambient. The twin of the resolve in
// lsao::computeOnCpu.
#version 450

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

#include "lsao_common.glsl"

layout(set = 0, binding = 4, rgba32f) uniform readonly image2D accumA; // moment.xyz, obscurance
layout(set = 0, binding = 5, r32f) uniform readonly image2D accumB;    // visibility
layout(set = 0, binding = 6, rgba32f) uniform writeonly image2D outA;  // bent normal, aperture
layout(set = 0, binding = 7, r32f) uniform writeonly image2D outB;     // ambient

// The group's 8x8 pixels and the window's reach around them (at most 1 before and 2 after for
// interleave <= 4) are loaded once into shared memory: 121 texels instead of 64 x 9 loads.
#define LSAO_TILE 11
shared float tileDepth[LSAO_TILE * LSAO_TILE];
shared vec3 tileNormal[LSAO_TILE * LSAO_TILE];
shared vec4 tileSumA[LSAO_TILE * LSAO_TILE]; // share * (moment.xyz, obscurance); w < 0: none
shared float tileSumB[LSAO_TILE * LSAO_TILE]; // share * visibility

void main()
{
    ivec2 origin = ivec2(gl_WorkGroupID.xy) * 8 - 1;
    int n = int(pc.interleave);
    for (uint i = gl_LocalInvocationIndex; i < LSAO_TILE * LSAO_TILE; i += 64u) {
        ivec2 q = origin + ivec2(int(i % LSAO_TILE), int(i / LSAO_TILE));
        float zq = 0.0;
        vec3 nq = vec3(0.0);
        vec4 a = vec4(0.0, 0.0, 0.0, -1.0);
        float b = 0.0;
        if (q.x >= 0 && q.y >= 0 && q.x < pc.width && q.y < pc.height) {
            zq = imageLoad(depthImage, q).r;
            nq = imageLoad(normalImage, q).xyz;
            if (lsaoHasSurface(zq, nq)) {
                float share = float(pc.dirCount) /
                              float(lsaoClassDirections(lsaoPixelClass(q, n), pc.dirCount, n));
                vec4 sums = imageLoad(accumA, q);
                a = vec4(share * sums.xyz, share * sums.w);
                b = share * imageLoad(accumB, q).r;
            }
        }
        tileDepth[i] = zq;
        tileNormal[i] = nq;
        tileSumA[i] = a;
        tileSumB[i] = b;
    }
    barrier();

    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= pc.width || pixel.y >= pc.height)
        return;
    ivec2 local = pixel - origin;
    int centre = local.x + LSAO_TILE * local.y;
    if (tileSumA[centre].w < 0.0) {
        imageStore(outA, pixel, vec4(0.0));
        imageStore(outB, pixel, vec4(1.0));
        return;
    }
    float z = tileDepth[centre];
    vec3 nRaw = tileNormal[centre];
    vec2 pi = vec2(pixel) + 0.5;
    int begin = -((n - 1) / 2);
    float obscurance = 0.0;
    float visibility = 0.0;
    float count = 0.0;
    vec3 moment = vec3(0.0);
    for (int dy = begin; dy < begin + n; ++dy) {
        for (int dx = begin; dx < begin + n; ++dx) {
            int j = centre + dx + LSAO_TILE * dy;
            vec4 a = tileSumA[j];
            if (a.w < 0.0)
                continue; // outside the image or no surface
            if ((dx != 0 || dy != 0) &&
                !lsaoIsSameSurface(pi, z, nRaw, vec2(pixel + ivec2(dx, dy)) + 0.5, tileDepth[j],
                                   tileNormal[j]))
                continue;
            obscurance += a.w;
            visibility += tileSumB[j];
            moment += a.xyz;
            count += 1.0;
        }
    }
    float inv = 1.0 / count;
    PixelResult r = lsaoResolvePixel(normalize(nRaw), inv * obscurance, inv * visibility, inv * moment);
    imageStore(outA, pixel, vec4(r.bentNormal, r.aperture));
    imageStore(outB, pixel, vec4(r.ambient));
}
