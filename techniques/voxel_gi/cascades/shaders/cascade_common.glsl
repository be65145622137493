// What the cascades' Vulkan passes share (cascade_gather.comp, cascade_inject.comp): the level
// descriptors at binding 0, the level selection and the trilinear lattice of the voxel centres,
// the same algorithm as CascadeVolume::selectLevel and getTrilinear (cascade_volume.cpp), in
// float, from positions relative to an anchor (the coarsest level's centre).

struct Level {
    vec4 origin; // xyz: min corner relative to the anchor, w: voxel size
    vec4 centre; // xyz: centre relative to the anchor, w: radius of the sphere that selects it (< 0: empty)
};

layout(std430, binding = 0) readonly buffer LevelBuffer { Level levels[]; };

// pcg3d (Jarzynski and Olano, "Hash Functions for GPU Rendering", JCGT 2020) to 24 bits, and
// the value noise on the level-0 voxel lattice (voxel size v0, the anchor's cell anchorCell):
// CascadeVolume's computeValueNoise.
float hashToUnit(uvec3 v)
{
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return float(v.x >> 8u) * (1.0 / 16777216.0);
}

float valueNoise(vec3 p, float v0, ivec3 anchorCell)
{
    const vec3 u = p / v0;
    const vec3 c = floor(u);
    const vec3 f = u - c;
    const ivec3 cell = anchorCell + ivec3(c);
    float n = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const ivec3 d = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
        const float w = (d.x == 1 ? f.x : 1.0 - f.x) * (d.y == 1 ? f.y : 1.0 - f.y) *
                        (d.z == 1 ? f.z : 1.0 - f.z);
        n += w * hashToUnit(uvec3(cell + d));
    }
    return n;
}

// The level to sample at p for footprint `diameter`, continuous; < 0 outside every level. The
// levels' count n, the level-0 voxel size v0; `noise` > 0 offsets the blend between levels (the
// talk's "3D noise offset"; the containment test stays exact).
float selectLevel(vec3 p, float diameter, int n, float v0, float noise, ivec3 anchorCell)
{
    float containing = -1.0;
    for (int i = 0; i < n; ++i) {
        const float radius = levels[i].centre.w;
        if (radius <= 0.0)
            continue;
        const float r = length(p - levels[i].centre.xyz) / radius;
        if (r <= 1.0) {
            // From half the radius on, blend toward the next level ("Cascade selection").
            const float blend = noise > 0.0 ? r + noise * (2.0 * valueNoise(p, v0, anchorCell) - 1.0) : r;
            containing = float(i) + (i + 1 < n ? clamp((blend - 0.5) / 0.5, 0.0, 1.0) : 0.0);
            break;
        }
    }
    if (containing < 0.0)
        return -1.0;
    const float footprint = diameter > v0 ? log2(diameter / v0) : 0.0;
    return min(float(n - 1), max(containing, footprint));
}

// The trilinear neighbourhood of p among level `level`'s voxel centres (R per axis), clamped to
// the level: its min corner i0 and the weights' fractions t.
void getTrilinear(int level, vec3 p, int R, out ivec3 i0, out vec3 t)
{
    vec3 c = (p - levels[level].origin.xyz) / levels[level].origin.w - 0.5;
    c = clamp(c, vec3(0.0), vec3(float(R - 1)));
    i0 = min(ivec3(floor(c)), ivec3(R - 2));
    t = c - vec3(i0);
}

// The weight of corner `corner` (bit 0: +x, 1: +y, 2: +z) and its voxel within the level.
float getCornerWeight(int corner, vec3 t, out ivec3 d)
{
    d = ivec3(corner & 1, (corner >> 1) & 1, (corner >> 2) & 1);
    const vec3 w3 = mix(vec3(1.0) - t, t, vec3(d));
    return w3.x * w3.y * w3.z;
}
