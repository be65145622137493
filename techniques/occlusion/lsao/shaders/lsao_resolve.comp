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

// The window is read straight from the images: a shared-memory tile of the group's pixels and
// their reach took the same time on lavapipe (73 against 69 ms at 1280x720); not compared on a GPU.
void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= pc.width || pixel.y >= pc.height)
        return;
    // LSAO_INTERLEAVE: Layout::interleave, a constant so that the window's loops unroll.
    const int n = LSAO_INTERLEAVE;
    float z = imageLoad(depthImage, pixel).r;
    vec3 nRaw = imageLoad(normalImage, pixel).xyz;
    if (!lsaoHasSurface(z, nRaw)) {
        imageStore(outA, pixel, vec4(0.0));
        imageStore(outB, pixel, vec4(1.0));
        return;
    }
    SurfaceReceiver receiver = lsaoMakeSurfaceReceiver(vec2(pixel) + 0.5, z, nRaw);
    int begin = -((n - 1) / 2);
    // The classes of the window's pixels, from this pixel's, without a division per tap.
    uint classes = uint(n * n);
    uint extra = pc.dirCount % classes;
    // A class holds dirCount / classes directions, one more below `extra`.
    float shareFewer = float(pc.dirCount) / float(pc.dirCount / classes);
    float shareMore = float(pc.dirCount) / float(pc.dirCount / classes + 1u);
    int cx0 = (pixel.x + begin + n) % n; // pixel.x + begin >= -1
    int cy0 = (pixel.y + begin + n) % n;
    float obscurance = 0.0;
    float visibility = 0.0;
    float count = 0.0;
    vec3 moment = vec3(0.0);
    int cy = cy0;
    for (int dy = begin; dy < begin + n; ++dy, cy = cy + 1 == n ? 0 : cy + 1) {
        int cx = cx0;
        for (int dx = begin; dx < begin + n; ++dx, cx = cx + 1 == n ? 0 : cx + 1) {
            ivec2 q = pixel + ivec2(dx, dy);
            if (!(q.x >= 0 && q.y >= 0 && q.x < pc.width && q.y < pc.height))
                continue;
            float zq = imageLoad(depthImage, q).r;
            vec3 nq = imageLoad(normalImage, q).xyz;
            if (!lsaoHasSurface(zq, nq))
                continue;
            if ((dx != 0 || dy != 0) && !lsaoIsSameSurface(receiver, vec2(q) + 0.5, zq, nq))
                continue;
            uint pixelClass = uint(cx + n * cy);
            float share = pixelClass < extra ? shareMore : shareFewer;
            vec4 sums = imageLoad(accumA, q);
            obscurance += share * sums.w;
            visibility += share * imageLoad(accumB, q).r;
            moment += share * sums.xyz;
            count += 1.0;
        }
    }
    float inv = 1.0 / count;
    PixelResult r = lsaoResolvePixel(normalize(nRaw), inv * obscurance, inv * visibility, inv * moment);
    imageStore(outA, pixel, vec4(r.bentNormal, r.aperture));
    imageStore(outB, pixel, vec4(r.ambient));
}
