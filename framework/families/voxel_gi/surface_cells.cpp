#include "families/voxel_gi/voxelize.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace rtlab::voxelgi {

namespace {

// Separating-axis test of a triangle (vertices relative to the box centre) against the box
// [-h, h]^3: the 3 box normals (done by the caller's cell range), the triangle's normal and the
// 9 cross products of the box axes and the triangle's edges (Akenine-Moeller 2001). Touching
// counts as meeting.
bool meetsBox(const glm::dvec3& v0, const glm::dvec3& v1, const glm::dvec3& v2, double h,
              const glm::dvec3& normal)
{
    const glm::dvec3 e[3] = {v1 - v0, v2 - v1, v0 - v2};
    const glm::dvec3 v[3] = {v0, v1, v2};
    for (int i = 0; i < 3; ++i)
        for (int a = 0; a < 3; ++a) {
            // axis = unit_a x e_i
            glm::dvec3 axis(0.0);
            axis[(a + 1) % 3] = -e[i][(a + 2) % 3];
            axis[(a + 2) % 3] = e[i][(a + 1) % 3];
            const double p0 = glm::dot(axis, v[0]), p1 = glm::dot(axis, v[1]),
                         p2 = glm::dot(axis, v[2]);
            const double r = h * (std::abs(axis.x) + std::abs(axis.y) + std::abs(axis.z));
            if (std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r)
                return false;
        }
    const double d = glm::dot(normal, v0);
    const double r = h * (std::abs(normal.x) + std::abs(normal.y) + std::abs(normal.z));
    return std::abs(d) <= r;
}

} // namespace

std::vector<glm::ivec3> listCellsMeetingTriangles(const scene::RenderScene& scene,
                                                  const glm::dvec3& origin, double cellSize,
                                                  const glm::ivec3& cells)
{
    if (!(cellSize > 0.0) || !std::isfinite(cellSize) || cells.x < 1 || cells.y < 1 || cells.z < 1)
        throw Error("listCellsMeetingTriangles: cell size " + std::to_string(cellSize) +
                    " and cell counts must be positive");
    const std::size_t triangles = scene.indices.size() / 3;
    tbb::enumerable_thread_specific<std::vector<glm::ivec3>> found;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangles, 256), [&](const auto& range) {
        auto& out = found.local();
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
            // Cell units relative to the lattice origin: cell c spans [c, c + 1].
            glm::dvec3 v[3];
            bool finite = true;
            for (int k = 0; k < 3; ++k) {
                v[k] = (glm::dvec3(scene.positions[scene.indices[3 * t + std::size_t(k)]]) - origin) /
                       cellSize;
                finite = finite && std::isfinite(v[k].x) && std::isfinite(v[k].y) &&
                         std::isfinite(v[k].z);
            }
            if (!finite)
                continue;
            const glm::dvec3 normal = glm::cross(v[1] - v[0], v[2] - v[0]);
            if (!(glm::dot(normal, normal) > 0.0))
                continue;
            const glm::dvec3 lo = glm::min(v[0], glm::min(v[1], v[2]));
            const glm::dvec3 hi = glm::max(v[0], glm::max(v[1], v[2]));
            glm::ivec3 begin, end; // cells [begin, end] whose closed box meets the bounds
            bool empty = false;
            for (int a = 0; a < 3; ++a) {
                const double n = double(cells[a]);
                begin[a] = int(std::clamp(std::ceil(lo[a]) - 1.0, 0.0, n));
                end[a] = int(std::clamp(std::floor(hi[a]), -1.0, n - 1.0));
                empty = empty || lo[a] > n || hi[a] < 0.0 || begin[a] > end[a];
            }
            if (empty)
                continue;
            // Walk the two axes across the dominant axis of the normal; along it only the cells
            // the plane passes through over that column.
            const glm::dvec3 an = glm::abs(normal);
            const int c = an.x >= an.y && an.x >= an.z ? 0 : (an.y >= an.z ? 1 : 2);
            const int a = (c + 1) % 3, b = (c + 2) % 3;
            const double d = glm::dot(normal, v[0]);
            for (int i = begin[a]; i <= end[a]; ++i)
                for (int j = begin[b]; j <= end[b]; ++j) {
                    // Plane coordinate along c over the column's rectangle [i, i+1] x [j, j+1].
                    double cmin = 1e300, cmax = -1e300;
                    for (int corner = 0; corner < 4; ++corner) {
                        const double x = i + (corner & 1), y = j + (corner >> 1);
                        const double z = (d - normal[a] * x - normal[b] * y) / normal[c];
                        cmin = std::min(cmin, z);
                        cmax = std::max(cmax, z);
                    }
                    const double n = double(cells[c]);
                    const int k0 = std::max(begin[c], int(std::clamp(std::ceil(cmin) - 1.0, -1.0, n)));
                    const int k1 = std::min(end[c], int(std::clamp(std::floor(cmax), -1.0, n)));
                    for (int k = k0; k <= k1; ++k) {
                        glm::ivec3 cell;
                        cell[a] = i;
                        cell[b] = j;
                        cell[c] = k;
                        const glm::dvec3 centre = glm::dvec3(cell) + 0.5;
                        if (meetsBox(v[0] - centre, v[1] - centre, v[2] - centre, 0.5, normal))
                            out.push_back(cell);
                    }
                }
        }
    });
    std::vector<glm::ivec3> all;
    for (auto& part : found)
        all.insert(all.end(), part.begin(), part.end());
    const auto order = [](const glm::ivec3& p, const glm::ivec3& q) {
        return p.z != q.z ? p.z < q.z : (p.y != q.y ? p.y < q.y : p.x < q.x);
    };
    std::sort(all.begin(), all.end(), order);
    all.erase(std::unique(all.begin(), all.end()), all.end());
    return all;
}

} // namespace rtlab::voxelgi
