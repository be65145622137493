// Pass 1 "lsao.sweep" of Line-Sweep Ambient Obscurance [Timonen 2013: sweeps]: one invocation
// per line of a direction (x: line, y: direction of the batch). It walks its line across the whole
// depth buffer in step strata and keeps the earlier samples that can still be a horizon as an
// upper convex hull in (t, 1/depth) on a stack of LSAO_HULL_CAPACITY entries (a ring: a push onto
// a full stack forgets the farthest vertex). Per stratum it stores the stratum index of the
// sample's dominant occluder, or LSAO_NO_OCCLUDER. Samples lie on their line at the depth of
// their pixel's tangent plane (lsaoSampleHeight). The twin of lsao::runSweepCpu.
#version 450

layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

#include "lsao_common.glsl"

layout(std430, set = 0, binding = 2) writeonly buffer Sweep { uint sweep[]; };

#define LSAO_HULL_MASK (LSAO_HULL_CAPACITY - 1)

void main()
{
    uint k = pc.dirBegin + gl_GlobalInvocationID.y;
    uint line = gl_GlobalInvocationID.x;
    if (k >= pc.dirEnd)
        return;
    Direction d = directions[k];
    if (line >= d.lineCount)
        return;
    float c = lsaoLineOffset(d, line);
    uint row = d.base + line * d.stepCount;
    uint lineHash = lsaoLineHash(k, line);

    float hullT[LSAO_HULL_CAPACITY];
    vec2 hullHeight[LSAO_HULL_CAPACITY];
    uint hullId[LSAO_HULL_CAPACITY];
    int top = -1;
    int size = 0;
    for (uint m = 0u; m < d.stepCount; ++m) {
        LineSample s = lsaoLocateSample(d, lineHash, c, int(m));
        float z = s.exists ? lsaoLoadDepth(s.pixel) : 0.0;
        uint result = LSAO_NO_OCCLUDER;
        if (z != 0.0) {
            precise float qx = s.t * d.dir.x + c * d.perp.x;
            precise float qy = s.t * d.dir.y + c * d.perp.y;
            vec2 h = lsaoSampleHeight(vec2(qx, qy), s.pixel, z,
                                      imageLoad(normalImage, s.pixel).xyz).xy;
            // Pop the vertices that the new sample sees past; the top is then its horizon.
            while (size >= 2) {
                int b = top & LSAO_HULL_MASK;
                int a = (top - 1) & LSAO_HULL_MASK;
                if (!lsaoIsOnOrBelowChord(hullT[a], hullHeight[a], hullT[b], hullHeight[b], s.t, h))
                    break;
                --top;
                --size;
            }
            if (size > 0)
                result = hullId[top & LSAO_HULL_MASK];
            ++top;
            hullT[top & LSAO_HULL_MASK] = s.t;
            hullHeight[top & LSAO_HULL_MASK] = h;
            hullId[top & LSAO_HULL_MASK] = m;
            size = min(size + 1, LSAO_HULL_CAPACITY);
        }
        sweep[row + m] = result;
    }
}
