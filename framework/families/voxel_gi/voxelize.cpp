#include "families/voxel_gi/voxelize.h"

#include "core/error.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace rtlab::voxelgi {

glm::vec3 getFaceNormal(int face)
{
    glm::vec3 n(0.0f);
    n[face / 2] = (face % 2 == 0) ? 1.0f : -1.0f;
    return n;
}

namespace {

// One ray-triangle hit of an axis-aligned ray.
struct Fragment {
    double depth = 0.0;      //!< coordinate along the ray's axis, world units
    std::uint32_t tri = 0;   //!< triangle index
    bool entering = false;   //!< the triangle's front faces the ray (an entry into a closed object)
    bool operator<(const Fragment& o) const
    {
        return depth < o.depth || (depth == o.depth && tri < o.tri);
    }
};

struct Triangle2 {
    glm::dvec3 p[3];
    glm::dvec3 normal; //!< unit geometric normal (CCW front)
    bool valid = false;
};

double cross2(double ax, double ay, double bx, double by)
{
    return ax * by - ay * bx;
}

// Edge function of edge a->b at q in the projection (u, v), computed from the lexicographically
// ordered endpoints so that the two triangles sharing an edge get exactly opposite values.
double computeEdge(glm::dvec2 a, glm::dvec2 b, glm::dvec2 q)
{
    const bool ordered = a.x < b.x || (a.x == b.x && a.y <= b.y);
    const glm::dvec2 p0 = ordered ? a : b, p1 = ordered ? b : a;
    const double w = cross2(p1.x - p0.x, p1.y - p0.y, q.x - p0.x, q.y - p0.y);
    return ordered ? w : -w;
}

// Top-left fill rule (of an edge of a triangle with positive area): exactly one of the two
// triangles that share an edge owns a sample lying on it.
bool isTopLeft(glm::dvec2 e)
{
    return e.y < 0.0 || (e.y == 0.0 && e.x > 0.0);
}

// Per-voxel accumulators of the three axis passes.
struct Accumulators {
    std::vector<std::uint32_t> hits;    // [voxel * 3 + axis]: rays of that axis covered inside
    std::vector<std::uint32_t> surfaceRays; // [voxel * 3 + axis]: of those, rays meeting a surface
    std::vector<glm::dvec3> albedo;     // [voxel * 6 + face]
    std::vector<glm::dvec3> emission;   // [voxel * 6 + face]
    std::vector<glm::dvec3> normal;     // [voxel]
    std::vector<std::uint8_t> votes;    // [voxel]: axes on which the centre is inside a span
};

} // namespace

void checkVoxelizeArguments(const VoxelRegion& region, const VoxelizeOptions& options, int maxResolution)
{
    if (region.resolution < 1 || region.resolution > maxResolution)
        throw Error("voxelize: resolution must be in [1, " + std::to_string(maxResolution) + "], found " +
                    std::to_string(region.resolution));
    if (!(region.voxelSize > 0.0) || !std::isfinite(region.voxelSize))
        throw Error("voxelize: voxel size must be positive and finite, found " +
                    std::to_string(region.voxelSize));
    if (!std::isfinite(region.origin.x) || !std::isfinite(region.origin.y) ||
        !std::isfinite(region.origin.z))
        throw Error("voxelize: the region's origin is not finite");
    if (options.supersampling < 1 || options.supersampling > 16)
        throw Error("voxelize: supersampling must be in [1, 16], found " +
                    std::to_string(options.supersampling));
}

void getVoxelizeBox(const VoxelRegion& region, const VoxelizeOptions& options, glm::ivec3& begin,
                    glm::ivec3& end)
{
    const int R = region.resolution;
    begin = glm::clamp(options.boxBegin, glm::ivec3(0), glm::ivec3(R));
    end = options.boxEnd;
    for (int a = 0; a < 3; ++a)
        end[a] = std::clamp(end[a] < 0 ? R : end[a], begin[a], R);
}

VoxelGrid voxelizeTriangles(const scene::RenderScene& scene, const VoxelRegion& region,
                            const VoxelizeOptions& options, VoxelizeStats* stats)
{
    checkVoxelizeArguments(region, options);
    const int R = region.resolution;
    const int S = options.supersampling;
    glm::ivec3 boxBegin, boxEnd;
    getVoxelizeBox(region, options, boxBegin, boxEnd);
    const int N = R * S;
    const double h = region.voxelSize / S;
    const std::size_t voxelCount = region.getVoxelCount();
    VoxelizeStats local;

    // Triangles with their geometric normals; degenerate ones are dropped.
    const std::size_t triCount = scene.triangleCount();
    std::vector<Triangle2> tris(triCount);
    const glm::dvec3 lo = region.origin, hi = region.getMaxCorner();
    for (std::size_t t = 0; t < triCount; ++t) {
        Triangle2& tri = tris[t];
        for (int k = 0; k < 3; ++k)
            tri.p[k] = glm::dvec3(scene.positions[scene.indices[3 * t + std::size_t(k)]]);
        const glm::dvec3 n = glm::cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
        const double len = glm::length(n);
        tri.valid = len > 0.0 && std::isfinite(len);
        tri.normal = tri.valid ? n / len : glm::dvec3(0.0);
        if (tri.valid) {
            const glm::dvec3 tmin = glm::min(tri.p[0], glm::min(tri.p[1], tri.p[2]));
            const glm::dvec3 tmax = glm::max(tri.p[0], glm::max(tri.p[1], tri.p[2]));
            // Meets the region's columns along at least one axis (needed for solid spans).
            int overlapping = 0;
            for (int a = 0; a < 3; ++a)
                overlapping += (tmax[a] >= lo[a] && tmin[a] <= hi[a]) ? 1 : 0;
            if (overlapping >= 2)
                ++local.trianglesConsidered;
        }
    }

    Accumulators acc;
    acc.hits.assign(voxelCount * 3, 0);
    acc.surfaceRays.assign(voxelCount * 3, 0);
    acc.albedo.assign(voxelCount * kFaceCount, glm::dvec3(0.0));
    acc.emission.assign(voxelCount * kFaceCount, glm::dvec3(0.0));
    acc.normal.assign(voxelCount, glm::dvec3(0.0));
    acc.votes.assign(voxelCount, 0);
    std::vector<std::size_t> fragmentsPerRow(std::size_t(R), 0);

    for (int a = 0; a < 3; ++a) {
        const int u = (a + 1) % 3, v = (a + 2) % 3;
        // Triangles by voxel row (v) of the projection onto (u, v).
        std::vector<std::vector<std::uint32_t>> buckets(static_cast<std::size_t>(R));
        for (std::size_t t = 0; t < triCount; ++t) {
            const Triangle2& tri = tris[t];
            if (!tri.valid)
                continue;
            double minU = tri.p[0][u], maxU = minU, minV = tri.p[0][v], maxV = minV;
            for (int k = 1; k < 3; ++k) {
                minU = std::min(minU, tri.p[k][u]);
                maxU = std::max(maxU, tri.p[k][u]);
                minV = std::min(minV, tri.p[k][v]);
                maxV = std::max(maxV, tri.p[k][v]);
            }
            if (maxU < lo[u] || minU > hi[u] || maxV < lo[v] || minV > hi[v])
                continue;
            const int j0 =
                std::max(boxBegin[v], int(std::floor((minV - lo[v]) / region.voxelSize)));
            const int j1 =
                std::min(boxEnd[v] - 1, int(std::floor((maxV - lo[v]) / region.voxelSize)));
            for (int j = j0; j <= j1; ++j)
                buckets[std::size_t(j)].push_back(std::uint32_t(t));
        }

        tbb::parallel_for(boxBegin[v], boxEnd[v], [&](int row) {
            // The S rays-rows of voxel row `row`, N rays each.
            std::vector<std::vector<Fragment>> rays(std::size_t(N) * std::size_t(S));
            std::size_t fragments = 0;
            for (const std::uint32_t t : buckets[std::size_t(row)]) {
                const Triangle2& tri = tris[t];
                glm::dvec2 q[3];
                for (int k = 0; k < 3; ++k)
                    q[k] = {tri.p[k][u] - lo[u], tri.p[k][v] - lo[v]};
                double area = cross2(q[1].x - q[0].x, q[1].y - q[0].y, q[2].x - q[0].x,
                                     q[2].y - q[0].y);
                if (area == 0.0 || !std::isfinite(area))
                    continue; // edge-on along this axis: the other axes see it
                int order[3] = {0, 1, 2};
                if (area < 0.0) {
                    std::swap(order[1], order[2]);
                    area = -area;
                }
                const glm::dvec2 A = q[order[0]], B = q[order[1]], C = q[order[2]];
                const double minU = std::min({A.x, B.x, C.x}), maxU = std::max({A.x, B.x, C.x});
                const double minV = std::min({A.y, B.y, C.y}), maxV = std::max({A.y, B.y, C.y});
                const int i0 = std::max(boxBegin[u] * S, int(std::ceil(minU / h - 0.5)));
                const int i1 = std::min(boxEnd[u] * S - 1, int(std::floor(maxU / h - 0.5)));
                const int jr0 = std::max(row * S, int(std::ceil(minV / h - 0.5)));
                const int jr1 = std::min(row * S + S - 1, int(std::floor(maxV / h - 0.5)));
                const bool entering = tri.normal[a] < 0.0; // a ray along +a meets its front
                const bool flat = tri.p[0][a] == tri.p[1][a] && tri.p[1][a] == tri.p[2][a];
                const bool tlA = isTopLeft(C - B), tlB = isTopLeft(A - C), tlC = isTopLeft(B - A);
                for (int j = jr0; j <= jr1; ++j)
                    for (int i = i0; i <= i1; ++i) {
                        const glm::dvec2 s{(i + 0.5) * h, (j + 0.5) * h};
                        const double w0 = computeEdge(B, C, s);
                        const double w1 = computeEdge(C, A, s);
                        const double w2 = computeEdge(A, B, s);
                        if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0)
                            continue;
                        if ((w0 == 0.0 && !tlA) || (w1 == 0.0 && !tlB) || (w2 == 0.0 && !tlC))
                            continue;
                        // A triangle perpendicular to the axis lies at its corners' depth
                        // exactly (coplanar faces then tie and are ordered by index).
                        const double sum = w0 + w1 + w2;
                        const double depth =
                            flat ? tri.p[0][a]
                                 : (w0 * tri.p[order[0]][a] + w1 * tri.p[order[1]][a] +
                                    w2 * tri.p[order[2]][a]) /
                                       sum;
                        rays[std::size_t(j - row * S) * std::size_t(N) + std::size_t(i)]
                            .push_back({depth, t, entering});
                        ++fragments;
                    }
            }
            fragmentsPerRow[std::size_t(row)] += fragments;

            glm::ivec3 coord(0);
            coord[v] = row;
            // Voxels along the current ray that it covers: 1 = meets a surface inside, 2 = runs
            // inside a closed solid span (a wall's voxel is covered on every axis, not only along
            // its normal).
            std::vector<std::uint8_t> covered(std::size_t(R), 0);
            std::vector<int> touched;
            for (int jr = 0; jr < S; ++jr)
                for (int i = 0; i < N; ++i) {
                    std::vector<Fragment>& frags = rays[std::size_t(jr) * std::size_t(N) + std::size_t(i)];
                    if (frags.empty())
                        continue;
                    std::sort(frags.begin(), frags.end());
                    coord[u] = i / S;
                    // Surface: per voxel the first and the last fragment inside it.
                    std::size_t f = 0;
                    while (f < frags.size()) {
                        const double k = std::floor((frags[f].depth - lo[a]) / region.voxelSize);
                        std::size_t g = f;
                        while (g + 1 < frags.size() &&
                               std::floor((frags[g + 1].depth - lo[a]) / region.voxelSize) == k)
                            ++g;
                        if (k >= boxBegin[a] && k < boxEnd[a]) {
                            coord[a] = int(k);
                            const std::size_t vox = region.index(coord.x, coord.y, coord.z);
                            ++acc.surfaceRays[vox * 3 + std::size_t(a)];
                            if (!covered[std::size_t(k)])
                                touched.push_back(int(k));
                            covered[std::size_t(k)] |= 1;
                            const auto addFace = [&](int face, std::uint32_t t) {
                                const scene::Material& m =
                                    scene.materials[scene.triangleMaterial[t]];
                                acc.albedo[vox * kFaceCount + std::size_t(face)] +=
                                    glm::dvec3(m.albedo);
                                acc.emission[vox * kFaceCount + std::size_t(face)] +=
                                    glm::dvec3(m.emission);
                            };
                            addFace(2 * a + 1, frags[f].tri); // met first: seen from -a
                            addFace(2 * a, frags[g].tri);     // met last: seen from +a
                            for (std::size_t x = f; x <= g; ++x)
                                acc.normal[vox] += tris[frags[x].tri].normal;
                        }
                        f = g + 1;
                    }
                    // Closed solid spans (entry through a front face to exit through a back
                    // face): every ray covers the voxels it runs through inside a span; the
                    // column's middle ray votes for the voxel centres inside one.
                    if (options.solid) {
                        const bool middle = jr == S / 2 && i % S == S / 2;
                        int depthCount = 0;
                        double spanStart = 0.0;
                        for (const Fragment& fr : frags) {
                            if (fr.entering) {
                                if (depthCount++ == 0)
                                    spanStart = fr.depth;
                                continue;
                            }
                            if (depthCount == 0 || --depthCount != 0)
                                continue;
                            const double s0 = (spanStart - lo[a]) / region.voxelSize;
                            const double s1 = (fr.depth - lo[a]) / region.voxelSize;
                            for (int k = std::max(boxBegin[a], int(std::floor(s0)));
                                 k <= std::min(boxEnd[a] - 1, int(std::floor(s1))); ++k) {
                                if (!covered[std::size_t(k)])
                                    touched.push_back(k);
                                covered[std::size_t(k)] |= 2;
                            }
                            if (middle)
                                for (int k = std::max(boxBegin[a], int(std::ceil(s0 - 0.5)));
                                     k <= std::min(boxEnd[a] - 1, int(std::floor(s1 - 0.5))); ++k) {
                                    coord[a] = k;
                                    ++acc.votes[region.index(coord.x, coord.y, coord.z)];
                                }
                        }
                    }
                    for (const int k : touched) {
                        coord[a] = k;
                        ++acc.hits[region.index(coord.x, coord.y, coord.z) * 3 + std::size_t(a)];
                        covered[std::size_t(k)] = 0;
                    }
                    touched.clear();
                }
        });
    }
    for (const std::size_t n : fragmentsPerRow)
        local.fragments += n;

    VoxelGrid grid;
    grid.region = region;
    grid.faces.assign(voxelCount * kFaceCount, glm::vec4(0.0f));
    grid.emission.assign(voxelCount * kFaceCount, glm::vec3(0.0f));
    grid.normal.assign(voxelCount, glm::vec3(0.0f));
    grid.flags.assign(voxelCount, 0);
    const double raysPerColumn = double(S) * double(S);
    for (std::size_t vox = 0; vox < voxelCount; ++vox) {
        bool surface = false;
        glm::dvec3 meanAlbedo(0.0), meanEmission(0.0);
        double meanCount = 0.0;
        for (int a = 0; a < 3; ++a)
            if (const std::uint32_t n = acc.surfaceRays[vox * 3 + std::size_t(a)]; n > 0) {
                surface = true;
                for (int face = 2 * a; face <= 2 * a + 1; ++face) {
                    meanAlbedo += acc.albedo[vox * kFaceCount + std::size_t(face)];
                    meanEmission += acc.emission[vox * kFaceCount + std::size_t(face)];
                    meanCount += n;
                }
            }
        for (int a = 0; a < 3; ++a) {
            const std::uint32_t n = acc.hits[vox * 3 + std::size_t(a)];
            if (n == 0 || !surface)
                continue;
            const std::uint32_t m = acc.surfaceRays[vox * 3 + std::size_t(a)];
            const float occupancy = float(std::min(1.0, n / raysPerColumn));
            for (int face = 2 * a; face <= 2 * a + 1; ++face) {
                const std::size_t i = vox * kFaceCount + std::size_t(face);
                // Rays that only run through the solid part see the voxel's mean surface.
                const glm::dvec3 albedo = m > 0 ? acc.albedo[i] / double(m) : meanAlbedo / meanCount;
                const glm::dvec3 emission =
                    m > 0 ? acc.emission[i] / double(m) : meanEmission / meanCount;
                grid.faces[i] = glm::vec4(glm::vec3(albedo), occupancy);
                grid.emission[i] = glm::vec3(emission);
            }
        }
        if (surface) {
            grid.flags[vox] = kVoxelSurface;
            const double len = glm::length(acc.normal[vox]);
            if (len > 1e-9)
                grid.normal[vox] = glm::vec3(acc.normal[vox] / len);
        } else if (acc.votes[vox] >= 2) {
            grid.flags[vox] = kVoxelSolid;
        }
    }
    local.solidVoxels = finalizeVoxelGrid(grid);
    local.surfaceVoxels = grid.surfaceVoxels.size();
    if (stats)
        *stats = local;
    return grid;
}

std::size_t finalizeVoxelGrid(VoxelGrid& grid)
{
    const VoxelRegion& region = grid.region;
    const int R = region.resolution;
    grid.surfaceVoxels.clear();
    for (std::size_t vox = 0; vox < grid.flags.size(); ++vox)
        if (grid.flags[vox] & kVoxelSurface)
            grid.surfaceVoxels.push_back(std::uint32_t(vox));
    std::size_t solidVoxels = 0;
    // Solid voxels: opaque on every face, the neighbouring surface's attributes one layer in.
    for (int z = 0; z < R; ++z)
        for (int y = 0; y < R; ++y)
            for (int x = 0; x < R; ++x) {
                const std::size_t vox = region.index(x, y, z);
                if (!(grid.flags[vox] & kVoxelSolid))
                    continue;
                ++solidVoxels;
                glm::vec3 mean(0.0f);
                int meanCount = 0;
                glm::vec3 sideAlbedo[kFaceCount];
                bool hasSide[kFaceCount] = {};
                for (int face = 0; face < kFaceCount; ++face) {
                    glm::ivec3 c(x, y, z);
                    c[face / 2] += (face % 2 == 0) ? 1 : -1;
                    if (c[face / 2] < 0 || c[face / 2] >= R)
                        continue;
                    const std::size_t n = region.index(c.x, c.y, c.z);
                    if (!(grid.flags[n] & kVoxelSurface))
                        continue;
                    const glm::vec4& seen = grid.face(n, face);
                    if (seen.a > 0.0f) {
                        sideAlbedo[face] = glm::vec3(seen);
                        hasSide[face] = true;
                        mean += glm::vec3(seen);
                        ++meanCount;
                    }
                }
                if (meanCount > 0)
                    mean /= float(meanCount);
                for (int face = 0; face < kFaceCount; ++face)
                    grid.faces[vox * kFaceCount + std::size_t(face)] =
                        glm::vec4(hasSide[face] ? sideAlbedo[face] : mean, 1.0f);
            }
    return solidVoxels;
}

namespace {

// Every attribute of voxel `from` of `source` into voxel `to` of `target`.
void copyVoxel(const VoxelGrid& source, std::size_t from, VoxelGrid& target, std::size_t to)
{
    for (int f = 0; f < kFaceCount; ++f) {
        target.faces[to * kFaceCount + std::size_t(f)] = source.faces[from * kFaceCount + std::size_t(f)];
        target.emission[to * kFaceCount + std::size_t(f)] =
            source.emission[from * kFaceCount + std::size_t(f)];
    }
    target.normal[to] = source.normal[from];
    target.flags[to] = source.flags[from];
}

} // namespace

// The voxels of `old` that lie in `region` (old shifted by `shift` voxels), the rest empty.
VoxelGrid shiftVoxelGrid(const VoxelGrid& old, const VoxelRegion& region, const glm::ivec3& shift)
{
    VoxelGrid grid;
    grid.region = region;
    const std::size_t voxels = region.getVoxelCount();
    grid.faces.assign(voxels * kFaceCount, glm::vec4(0.0f));
    grid.emission.assign(voxels * kFaceCount, glm::vec3(0.0f));
    grid.normal.assign(voxels, glm::vec3(0.0f));
    grid.flags.assign(voxels, 0);
    const int R = region.resolution;
    for (int z = 0; z < R; ++z)
        for (int y = 0; y < R; ++y)
            for (int x = 0; x < R; ++x) {
                const glm::ivec3 o = glm::ivec3(x, y, z) + shift;
                if (o.x < 0 || o.y < 0 || o.z < 0 || o.x >= R || o.y >= R || o.z >= R)
                    continue;
                copyVoxel(old, old.region.index(o.x, o.y, o.z), grid, region.index(x, y, z));
            }
    return grid;
}

// (voxelize.h)
void pasteVoxelBox(const VoxelGrid& part, const glm::ivec3& begin, const glm::ivec3& endIn,
                   VoxelGrid& grid)
{
    const int R = grid.region.resolution;
    glm::ivec3 end = endIn;
    for (int a = 0; a < 3; ++a)
        end[a] = end[a] < 0 ? R : end[a];
    for (int z = begin.z; z < end.z; ++z)
        for (int y = begin.y; y < end.y; ++y)
            for (int x = begin.x; x < end.x; ++x) {
                const std::size_t v = grid.region.index(x, y, z);
                copyVoxel(part, v, grid, v);
            }
}


} // namespace rtlab::voxelgi
