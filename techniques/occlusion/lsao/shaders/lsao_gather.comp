// Pass 2 "lsao.gather" of Line-Sweep Ambient Obscurance [Timonen 2013: gathering]: one invocation
// per pixel. For each direction of the batch it takes the occluders of the sweep sample nearest to
// the pixel on the nearest line (LSAO_GATHER_NEAREST, [Quantum Break seed]) or interpolates
// bilinearly between the samples of the two lines that bracket the pixel and the two samples that
// bracket it along each line; each sample's dominant occluder is seen from the pixel itself with
// its normal, with one near-field sample [Quantum Break seed], and the half-slice contributions
// are added to the accumulators. Each pixel takes the directions of its class (k mod
// interleave^2, [Quantum Break seed]); lsao_resolve.comp turns the sums into the outputs. The twin
// of lsao::runGatherCpu.
#version 450

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

#include "lsao_common.glsl"

layout(std430, set = 0, binding = 2) readonly buffer Sweep { uint sweep[]; };
layout(set = 0, binding = 4, rgba32f) uniform image2D accumA;  // moment.xyz, obscurance
layout(set = 0, binding = 5, r32f) uniform image2D accumB;     // visibility

// lsao::runGatherCpu's findWall: the wall below occluder o where its foot on the receiver's
// tangent plane is the visible surface.
void lsaoFindWall(Slice sl, vec3 x, vec3 n, vec3 p, inout Occluder o)
{
#if LSAO_WALLS
    WallFoot f = lsaoFindWallFoot(sl, x, n, p, o);
    if (!f.worth)
        return;
    vec2 q = viewToScreen(f.foot, pc.projScale, pc.projOffset, pc.size);
    if (!(q.x >= 0.0 && q.y >= 0.0 && q.x < float(pc.width) && q.y < float(pc.height)))
        return;
    ivec2 pixel = ivec2(int(floor(q.x)), int(floor(q.y)));
    float z = lsaoLoadDepth(pixel);
    if (z == 0.0)
        return;
    vec3 h = lsaoSampleHeight(q, pixel, z, imageLoad(normalImage, pixel).xyz);
    float surface = h.z != 0.0 ? h.y / h.x : z;
    float support = lsaoFootSupport(-f.foot.z, surface, f.height);
    if (support > 0.0)
        o.wall = f.wall / support;
#endif
}

Occluder lsaoLoadOccluder(ivec2 pixel, Slice sl, vec3 x, vec3 n, float minDistance)
{
    float z = lsaoLoadDepth(pixel);
    if (z == 0.0)
        return lsaoNoOccluder();
    vec3 p = screenToView(vec2(pixel) + 0.5, z, pc.projScale, pc.projOffset, pc.size);
    Occluder o = lsaoProjectOccluder(sl, x, p, minDistance);
    lsaoFindWall(sl, x, n, p, o);
    return o;
}

// The point of a line sample: on its line at its tangent-plane depth, else its pixel centre.
Occluder lsaoLoadLineSample(Direction d, float c, LineSample ls, Slice sl, vec3 x, vec3 n,
                            float minDistance)
{
    float z = ls.exists ? lsaoLoadDepth(ls.pixel) : 0.0;
    if (z == 0.0)
        return lsaoNoOccluder();
    precise float qx = ls.t * d.dir.x + c * d.perp.x;
    precise float qy = ls.t * d.dir.y + c * d.perp.y;
    vec2 q = vec2(qx, qy);
    vec3 h = lsaoSampleHeight(q, ls.pixel, z, imageLoad(normalImage, ls.pixel).xyz);
    vec3 p = h.z != 0.0 ? screenToView(q, h.y / h.x, pc.projScale, pc.projOffset, pc.size)
                        : screenToView(vec2(ls.pixel) + 0.5, z, pc.projScale, pc.projOffset,
                                       pc.size);
    Occluder o = lsaoProjectOccluder(sl, x, p, minDistance);
    lsaoFindWall(sl, x, n, p, o);
    return o;
}

Occluder lsaoLoadDominant(Direction d, uint lineHash, float c, uint row, LineSample ls,
                          Slice sl, vec3 x, vec3 n, float minDistance)
{
    uint id = sweep[row + uint(ls.stratum)];
    if (id == LSAO_NO_OCCLUDER)
        return lsaoNoOccluder();
    LineSample s = lsaoLocateSample(d, lineHash, c, int(id));
    return lsaoLoadLineSample(d, c, s, sl, x, n, minDistance);
}

void lsaoAddScaled(inout Contribution total, float weight, Contribution c)
{
    total.obscurance += weight * c.obscurance;
    total.visibility += weight * c.visibility;
    total.moment += weight * c.moment;
}

// lsao::runGatherCpu's locateReceiver: where the receiver lies among the lines of direction d.
struct ReceiverOnLines {
    float t;
    int lowerLine;
    float lineWeight;
    int stratum;
};

ReceiverOnLines lsaoLocateReceiver(Direction d, vec2 p)
{
    precise float cX = p.x * d.perp.x + p.y * d.perp.y;
    precise float tX = p.x * d.dir.x + p.y * d.dir.y;
    precise float fl = (cX - d.cMin) * pc.invSpacing;
    int i0 = clamp(int(floor(fl)), 0, int(d.lineCount) - 2);
    precise float fs = (tX - d.tMin) * pc.invStep;
    return ReceiverOnLines(tX, i0, clamp(fl - float(i0), 0.0, 1.0), int(floor(fs)));
}

#if LSAO_GATHER_NEAREST
// lsao::runGatherCpu's gatherNearest: one occluder set per direction, that of the sample nearest
// to the receiver on the nearest line [Quantum Break seed: "average distance to the nearest step
// is less than 3 px"].
Contribution lsaoGatherDirection(uint k, vec2 p, vec3 x, vec3 n)
{
    Direction d = directions[k];
    Slice sl = lsaoMakeSlice(x, n, d.axis.xyz);
    if (!sl.hasHemisphere)
        return Contribution(0.0, 0.0, vec3(0.0));
    float minDistance = 1e-4 * length(x);

    ReceiverOnLines at = lsaoLocateReceiver(d, p);
    precise float tX = at.t;
    int i0 = at.lowerLine;
    float f = at.lineWeight;
    int mX = at.stratum;
    uint line = uint(f < 0.5 ? i0 : i0 + 1);
    uint lineHash = lsaoLineHash(k, line);
    float c = lsaoLineOffset(d, line);
    LineSample atX = lsaoLocateSample(d, lineHash, c, mX);
    bool atXIsLower = atX.t <= tX;
    LineSample other = lsaoLocateSample(d, lineHash, c, atXIsLower ? mX + 1 : mX - 1);
    LineSample lower = atXIsLower ? atX : other;
    LineSample upper = atXIsLower ? other : atX;
    precise float lowerGap = tX - lower.t;
    precise float upperGap = upper.t - tX;
    bool useLower = lower.exists && (!upper.exists || lowerGap <= upperGap);
    LineSample s = useLower ? lower : upper;

    Occluder nearSample = lsaoNoOccluder();
    if ((pc.flags & LSAO_FLAG_NEAR_FIELD) != 0u) {
        // [Quantum Break seed] one sample roughly half-way to the nearest upstream sample.
        precise float gap = lower.exists ? lowerGap : pc.step;
        precise float delta = max(0.5 * gap, 1.0);
        precise float qx = p.x - delta * d.dir.x;
        precise float qy = p.y - delta * d.dir.y;
        nearSample =
            lsaoLoadOccluder(ivec2(int(floor(qx)), int(floor(qy))), sl, x, n, minDistance);
    }
    uint row = d.base + line * d.stepCount;
    Occluder dominant = s.exists ? lsaoLoadDominant(d, lineHash, c, row, s, sl, x, n, minDistance)
                                 : lsaoNoOccluder();
    Occluder self = useLower ? lsaoLoadLineSample(d, c, lower, sl, x, n, minDistance)
                             : lsaoNoOccluder();
    return lsaoEvaluateOccluders(sl, dominant, self, nearSample);
}
#else
Contribution lsaoGatherDirection(uint k, vec2 p, vec3 x, vec3 n)
{
    Direction d = directions[k];
    Contribution total = Contribution(0.0, 0.0, vec3(0.0));
    Slice sl = lsaoMakeSlice(x, n, d.axis.xyz);
    if (!sl.hasHemisphere)
        return total;
    float minDistance = 1e-4 * length(x);

    ReceiverOnLines at = lsaoLocateReceiver(d, p);
    precise float tX = at.t;
    int i0 = at.lowerLine;
    float f = at.lineWeight;
    int mX = at.stratum;

    LineSample lower[2];
    LineSample upper[2];
    precise float gap = 0.0;
    for (int j = 0; j < 2; ++j) {
        uint line = uint(i0 + j);
        uint lineHash = lsaoLineHash(k, line);
        float c = lsaoLineOffset(d, line);
        LineSample atX = lsaoLocateSample(d, lineHash, c, mX);
        if (atX.t <= tX) {
            lower[j] = atX;
            upper[j] = lsaoLocateSample(d, lineHash, c, mX + 1);
        } else {
            lower[j] = lsaoLocateSample(d, lineHash, c, mX - 1);
            upper[j] = atX;
        }
        precise float lineGap = lower[j].exists ? tX - lower[j].t : pc.step;
        gap += (j == 0 ? 1.0 - f : f) * lineGap;
    }

    Occluder nearSample = lsaoNoOccluder();
    if ((pc.flags & LSAO_FLAG_NEAR_FIELD) != 0u) {
        // [Quantum Break seed] one sample roughly half-way to the nearest upstream sample.
        precise float delta = max(0.5 * gap, 1.0);
        precise float qx = p.x - delta * d.dir.x;
        precise float qy = p.y - delta * d.dir.y;
        nearSample =
            lsaoLoadOccluder(ivec2(int(floor(qx)), int(floor(qy))), sl, x, n, minDistance);
    }

    for (int j = 0; j < 2; ++j) {
        uint line = uint(i0 + j);
        uint lineHash = lsaoLineHash(k, line);
        float c = lsaoLineOffset(d, line);
        float lineWeight = j == 0 ? 1.0 - f : f;
        uint row = d.base + line * d.stepCount;
        float wLower = 0.0;
        float wUpper = 0.0;
        float wNear = 0.0;
        if (lower[j].exists && upper[j].exists) {
            wUpper = clamp((tX - lower[j].t) / (upper[j].t - lower[j].t), 0.0, 1.0);
            wLower = 1.0 - wUpper;
        } else if (lower[j].exists) {
            wLower = 1.0;
        } else if (upper[j].exists) {
            wUpper = 1.0;
        } else {
            wNear = 1.0;
        }
        // Occluders are loaded once per stratum (see lsao::runGatherCpu's gatherDirection).
        uint lowerId = wLower > 0.0 ? sweep[row + uint(lower[j].stratum)] : LSAO_NO_OCCLUDER;
        Occluder none = lsaoNoOccluder();
        Occluder lowerDominant = none;
        Occluder self = none;
        Occluder dominant = none;
        if (wLower > 0.0) {
            lowerDominant = lsaoLoadDominant(d, lineHash, c, row, lower[j], sl, x, n, minDistance);
            self = lsaoLoadLineSample(d, c, lower[j], sl, x, n, minDistance);
        }
        if (wUpper > 0.0) {
            uint id = sweep[row + uint(upper[j].stratum)];
            if (wLower > 0.0 && id == uint(lower[j].stratum))
                dominant = self;
            else if (wLower > 0.0 && id == lowerId)
                dominant = lowerDominant;
            else
                dominant = lsaoLoadDominant(d, lineHash, c, row, upper[j], sl, x, n, minDistance);
        }
        // The upstream sample's occluders (or, where the line has no sample around the pixel,
        // the near-field sample alone: wNear > 0 only where wLower = wUpper = 0), then the
        // downstream sample's, in the order of the C++ path. One call site in a loop of two keeps
        // the shader small: lavapipe runs every branch for every lane.
        for (int e = 0; e < 2; ++e) {
            bool first = e == 0;
            float w = first ? wLower + wNear : wUpper;
            if (!(w > 0.0))
                continue;
            bool alone = wNear > 0.0;
            Occluder o0 = first ? (alone ? nearSample : lowerDominant) : dominant;
            Occluder o1 = first ? (alone ? none : self) : nearSample;
            Occluder o2 = first && !alone ? nearSample : none;
            lsaoAddScaled(total, lineWeight * w, lsaoEvaluateOccluders(sl, o0, o1, o2));
        }
    }
    return total;
}
#endif

void main()
{
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (pixel.x >= pc.width || pixel.y >= pc.height)
        return;
    float z = imageLoad(depthImage, pixel).r;
    vec3 nRaw = imageLoad(normalImage, pixel).xyz;
    bool first = (pc.flags & LSAO_FLAG_FIRST_BATCH) != 0u;
    vec4 sumA = first ? vec4(0.0) : imageLoad(accumA, pixel);
    float sumB = first ? 0.0 : imageLoad(accumB, pixel).r;
    if (lsaoHasSurface(z, nRaw)) {
        vec3 n = normalize(nRaw);
        vec2 p = vec2(pixel) + 0.5;
        vec3 x = screenToView(p, z, pc.projScale, pc.projOffset, pc.size);
        // [Quantum Break seed] this pixel's share of the directions: k = class mod n^2.
        int il = int(pc.interleave);
        uint classes = uint(il * il);
        uint pixelClass = lsaoPixelClass(pixel, il);
        uint firstK = pc.dirBegin + (pixelClass + classes - pc.dirBegin % classes) % classes;
        for (uint k = firstK; k < pc.dirEnd; k += classes) {
            Contribution c = lsaoGatherDirection(k, p, x, n);
            sumA.w += c.obscurance;
            sumB += c.visibility;
            sumA.xyz += c.moment;
        }
    }
    imageStore(accumA, pixel, sumA);
    imageStore(accumB, pixel, vec4(sumB));
}
