#version 450
// Voxelization on Vulkan, step 1 of 2: one invocation per voxel column and axis, which casts one
// of the column's S x S axis-aligned rays (the push constant `ray`; one dispatch per ray, in the
// C++ path's order, so the sums are accumulated in the same order and one invocation's loops stay
// short: lavapipe stops an invocation after 65,535 loop iterations in all) through the triangles
// binned to the column, sorts the ray's fragments by (depth, triangle), and accumulates what the
// ray sees into the column's voxels (which no other invocation of this axis touches): rays
// covered inside, rays meeting a surface,
// the albedo and emission of the first and last surface met per voxel, the normals, and the
// middle ray's votes for voxel centres inside closed spans. The same algorithm as
// voxelgi::voxelizeTriangles (framework/families/voxel_gi/voxelize.cpp), in float from positions
// relative to the region's min corner. The Tomorrow Children, GDC 2015 (seed
// shared/seeds/000_3da000e866ebc485.txt, "Object Voxelization", "Post Processing: ensure a solid
// voxelization").

layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;

// Positions relative to the region's min corner; normal.w: the material index's bits.
struct Triangle {
    vec4 p0;
    vec4 p1;
    vec4 p2;
    vec4 normal;
};

layout(std430, binding = 0) readonly buffer TriangleBuffer { Triangle tris[]; };
layout(std430, binding = 1) readonly buffer MaterialBuffer { vec4 materials[]; }; // [m][albedo, emission]
// Per axis and column (axis * R * R + cu + R * cv): the range [start, next start) of binTris.
layout(std430, binding = 2) readonly buffer BinStartBuffer { uint binStart[]; };
layout(std430, binding = 3) readonly buffer BinBuffer { uint binTris[]; };
// [(voxel * 3 + axis) * 3 + i]: i = 0 rays covering the voxel, 1 of those meeting a surface in
// it, 2 the middle ray's vote (the centre lies inside a closed span).
layout(std430, binding = 4) buffer CountBuffer { uint counts[]; };
// [(voxel * 6 + face) * 2 + i]: i = 0 albedo sum, 1 emission sum.
layout(std430, binding = 5) buffer FaceBuffer { vec4 faceSums[]; };
layout(std430, binding = 6) buffer NormalBuffer { vec4 normalSums[]; }; // [voxel * 3 + axis]
layout(std430, binding = 7) buffer StatBuffer { uint stats[]; }; // 0: fragments, 1: rays over the limit

layout(push_constant) uniform Constants {
    ivec4 size;     // resolution R, supersampling S, solid (1/0)
    ivec4 boxBegin; // voxels voxelized: [boxBegin, boxEnd)
    ivec4 boxEnd;
    vec4 scale;     // voxel size, ray spacing (voxel size / S)
    ivec4 ray;      // x: the ray within the column (jr * S + ir)
} pc;

const int kMaxFragments = 64; // per ray; more is reported (stats[1]) and the host falls back
const int kMaxResolution = 128;

float cross2(vec2 a, vec2 b)
{
    return a.x * b.y - a.y * b.x;
}

// Edge function of edge a->b at q from the lexicographically ordered endpoints, so that the two
// triangles sharing an edge get exactly opposite values (voxelize.cpp computeEdge).
float computeEdge(vec2 a, vec2 b, vec2 q)
{
    const bool ordered = a.x < b.x || (a.x == b.x && a.y <= b.y);
    const vec2 p0 = ordered ? a : b;
    const vec2 p1 = ordered ? b : a;
    const float w = cross2(p1 - p0, q - p0);
    return ordered ? w : -w;
}

// Top-left fill rule: exactly one of two triangles sharing an edge owns a sample on it.
bool isTopLeft(vec2 e)
{
    return e.y < 0.0 || (e.y == 0.0 && e.x > 0.0);
}

vec3 getPoint(Triangle t, int k)
{
    return k == 0 ? t.p0.xyz : (k == 1 ? t.p1.xyz : t.p2.xyz);
}

uint getVoxel(ivec3 c)
{
    const int R = pc.size.x;
    return uint(c.x + R * (c.y + R * c.z));
}

void addFace(uint voxel, int face, uint tri)
{
    const uint m = floatBitsToUint(tris[tri].normal.w);
    const uint f = (voxel * 6u + uint(face)) * 2u;
    faceSums[f] += vec4(materials[2u * m].rgb, 0.0);
    faceSums[f + 1u] += vec4(materials[2u * m + 1u].rgb, 0.0);
}

void main()
{
    const int R = pc.size.x, S = pc.size.y;
    const uint id = gl_GlobalInvocationID.x;
    const int a = int(id / uint(R * R));
    if (a >= 3)
        return;
    const int column = int(id % uint(R * R));
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    const int cu = column % R, cv = column / R;
    if (cu < pc.boxBegin[u] || cu >= pc.boxEnd[u] || cv < pc.boxBegin[v] || cv >= pc.boxEnd[v])
        return;
    const uint binFirst = binStart[uint(a * R * R + column)];
    const uint binEnd = binStart[uint(a * R * R + column) + 1u];
    if (binFirst == binEnd)
        return;
    const float h = pc.scale.y, voxelSize = pc.scale.x;
    ivec3 coord = ivec3(0);
    coord[u] = cu;
    coord[v] = cv;
    float depths[kMaxFragments];
    uint fragTris[kMaxFragments];
    const int jr = pc.ray.x / S, ir = pc.ray.x % S;
    const vec2 s = vec2((float(cu * S + ir) + 0.5) * h, (float(cv * S + jr) + 0.5) * h);
    // The ray's fragments, sorted by (depth, triangle) as they come.
    int count = 0;
    for (uint b = binFirst; b < binEnd; ++b) {
        const uint t = binTris[b];
        const Triangle tri = tris[t];
        vec2 q[3];
        float depth3[3];
        for (int k = 0; k < 3; ++k) {
            const vec3 p = getPoint(tri, k);
            q[k] = vec2(p[u], p[v]);
            depth3[k] = p[a];
        }
        float area = cross2(q[1] - q[0], q[2] - q[0]);
        if (area == 0.0)
            continue; // edge-on along this axis: the other axes see it
        int o1 = 1, o2 = 2;
        if (area < 0.0) {
            o1 = 2;
            o2 = 1;
        }
        const vec2 A = q[0], B = q[o1], C = q[o2];
        const float w0 = computeEdge(B, C, s);
        const float w1 = computeEdge(C, A, s);
        const float w2 = computeEdge(A, B, s);
        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0)
            continue;
        if ((w0 == 0.0 && !isTopLeft(C - B)) || (w1 == 0.0 && !isTopLeft(A - C)) ||
            (w2 == 0.0 && !isTopLeft(B - A)))
            continue;
        // A triangle perpendicular to the axis lies at its corners' depth exactly
        // (coplanar faces then tie and are ordered by index).
        const bool planar = depth3[0] == depth3[1] && depth3[1] == depth3[2];
        const float depth = planar ? depth3[0]
                                 : (w0 * depth3[0] + w1 * depth3[o1] + w2 * depth3[o2]) / (w0 + w1 + w2);
        if (count == kMaxFragments) {
            atomicAdd(stats[1], 1u);
            break;
        }
        int at = count++;
        while (at > 0 && (depths[at - 1] > depth || (depths[at - 1] == depth && fragTris[at - 1] > t))) {
            depths[at] = depths[at - 1];
            fragTris[at] = fragTris[at - 1];
            --at;
        }
        depths[at] = depth;
        fragTris[at] = t;
    }
    if (count == 0)
        return;
    atomicAdd(stats[0], uint(count));
    // Voxels of the column this ray covers (a surface inside, or inside a closed span).
    uint covered[kMaxResolution / 32];
    for (int w = 0; w < kMaxResolution / 32; ++w)
        covered[w] = 0u;
    // Surface: per voxel the first and the last fragment inside it.
    int f = 0;
    while (f < count) {
        const float k = floor(depths[f] / voxelSize);
        int g = f;
        while (g + 1 < count && floor(depths[g + 1] / voxelSize) == k)
            ++g;
        if (k >= float(pc.boxBegin[a]) && k < float(pc.boxEnd[a])) {
            coord[a] = int(k);
            const uint voxel = getVoxel(coord);
            counts[(voxel * 3u + uint(a)) * 3u + 1u] += 1u;
            covered[int(k) / 32] |= 1u << uint(int(k) % 32);
            addFace(voxel, 2 * a + 1, fragTris[f]); // met first: seen from -a
            addFace(voxel, 2 * a, fragTris[g]);     // met last: seen from +a
            vec3 n = vec3(0.0);
            for (int x = f; x <= g; ++x)
                n += tris[fragTris[x]].normal.xyz;
            normalSums[voxel * 3u + uint(a)] += vec4(n, 0.0);
        }
        f = g + 1;
    }
    // Closed solid spans (entry through a front face to exit through a back face).
    if (pc.size.z != 0) {
        const bool middle = jr == S / 2 && ir == S / 2;
        int depthCount = 0;
        float spanStart = 0.0;
        for (int x = 0; x < count; ++x) {
            const bool entering = tris[fragTris[x]].normal[a] < 0.0;
            if (entering) {
                if (depthCount++ == 0)
                    spanStart = depths[x];
                continue;
            }
            if (depthCount == 0 || --depthCount != 0)
                continue;
            const float s0 = spanStart / voxelSize, s1 = depths[x] / voxelSize;
            const int k0 = max(pc.boxBegin[a], int(floor(s0)));
            const int k1 = min(pc.boxEnd[a] - 1, int(floor(s1)));
            for (int k = k0; k <= k1; ++k)
                covered[k / 32] |= 1u << uint(k % 32);
            if (middle) {
                const int m0 = max(pc.boxBegin[a], int(ceil(s0 - 0.5)));
                const int m1 = min(pc.boxEnd[a] - 1, int(floor(s1 - 0.5)));
                for (int k = m0; k <= m1; ++k) {
                    coord[a] = k;
                    counts[(getVoxel(coord) * 3u + uint(a)) * 3u + 2u] += 1u;
                }
            }
        }
    }
    for (int k = 0; k < R; ++k)
        if ((covered[k / 32] & (1u << uint(k % 32))) != 0u) {
            coord[a] = k;
            counts[(getVoxel(coord) * 3u + uint(a)) * 3u] += 1u;
        }
}
