#include "scene/sdf_mesher.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rtlab::scene {

namespace {

constexpr std::uint32_t kNoVertex = std::numeric_limits<std::uint32_t>::max();

struct Grid {
    glm::ivec3 samples;  // sample count per axis
    glm::dvec3 origin;
    double spacing;
    std::vector<double> values;

    std::size_t index(int x, int y, int z) const
    {
        return (std::size_t(z) * samples.y + y) * samples.x + x;
    }
    glm::dvec3 position(int x, int y, int z) const { return origin + spacing * glm::dvec3(x, y, z); }
};

} // namespace

SdfMesh meshSdfModel(const SdfModel& model, const SdfMeshOptions& options)
{
    if (options.resolution < 4 || options.resolution > 2048)
        throw std::invalid_argument("SDF mesh resolution must be in [4, 2048]");
    const glm::dvec3 extent = model.boundsMax - model.boundsMin;
    const double longest = std::max({extent.x, extent.y, extent.z});
    if (!(longest > 0.0) || !std::isfinite(longest))
        throw std::invalid_argument("SDF model '" + model.name + "' has empty or non-finite bounds");

    Grid g;
    g.spacing = longest / options.resolution;
    const glm::ivec3 cells = glm::ivec3(glm::ceil(extent / g.spacing)) + 2;  // one padding cell per side
    g.samples = cells + 1;
    g.origin = model.boundsMin - glm::dvec3(g.spacing);
    g.values.resize(std::size_t(g.samples.x) * g.samples.y * g.samples.z);
    tbb::parallel_for(0, g.samples.z, [&](int z) {
        for (int y = 0; y < g.samples.y; ++y)
            for (int x = 0; x < g.samples.x; ++x) {
                double v = model.evaluate(g.position(x, y, z), options.frame);
                // The padding shell is outside by construction: closed surfaces stay closed even
                // when the model touches its bounds.
                if (x == 0 || y == 0 || z == 0 || x == g.samples.x - 1 || y == g.samples.y - 1 ||
                    z == g.samples.z - 1)
                    v = std::max(v, g.spacing * 0.5);
                g.values[g.index(x, y, z)] = v;
            }
    });

    // One vertex per crossed cell, at the mean of its edge crossings, then Newton-projected.
    auto cellIndex = [&](int x, int y, int z) { return (std::size_t(z) * cells.y + y) * cells.x + x; };
    std::vector<std::uint32_t> cellVertex(std::size_t(cells.x) * cells.y * cells.z, kNoVertex);
    SdfMesh out;
    auto& positions = out.mesh.positions;
    static const int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0},
                                      {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
    static const int kEdge[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                     {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    for (int z = 0; z < cells.z; ++z)
        for (int y = 0; y < cells.y; ++y)
            for (int x = 0; x < cells.x; ++x) {
                double v[8];
                int inside = 0;
                for (int c = 0; c < 8; ++c) {
                    v[c] = g.values[g.index(x + kCorner[c][0], y + kCorner[c][1], z + kCorner[c][2])];
                    inside += v[c] < 0.0;
                }
                if (inside == 0 || inside == 8)
                    continue;
                glm::dvec3 sum(0.0);
                int crossings = 0;
                for (const auto& e : kEdge) {
                    const double a = v[e[0]], b = v[e[1]];
                    if ((a < 0.0) == (b < 0.0))
                        continue;
                    const double t = a / (a - b);
                    const glm::dvec3 pa(kCorner[e[0]][0], kCorner[e[0]][1], kCorner[e[0]][2]);
                    const glm::dvec3 pb(kCorner[e[1]][0], kCorner[e[1]][1], kCorner[e[1]][2]);
                    sum += pa + t * (pb - pa);
                    ++crossings;
                }
                const glm::dvec3 cellMin = g.position(x, y, z);
                glm::dvec3 p = cellMin + g.spacing * (sum / double(crossings));
                // Newton steps on the field, kept within half a cell of the cell so that sharp
                // features cannot pull vertices across their neighbours (which would fold the
                // mesh); the surface may leave the cell's own box between two crossings.
                const glm::dvec3 lo = cellMin - glm::dvec3(0.5 * g.spacing);
                const glm::dvec3 hi = cellMin + glm::dvec3(1.5 * g.spacing);
                for (int s = 0; s < options.projectionSteps; ++s) {
                    const double f = model.evaluate(p, options.frame);
                    if (!std::isfinite(f))
                        break;
                    p = glm::clamp(p - f * model.evaluateGradient(p, options.frame), lo, hi);
                }
                cellVertex[cellIndex(x, y, z)] = std::uint32_t(positions.size());
                positions.emplace_back(p);
            }

    // One quad per crossed grid edge, between the four cells around it, wound counter-clockwise
    // seen from outside: for an edge along axis a with u = a+1, v = a+2 (cyclic), the cells in
    // the order (u-,v-), (u+,v-), (u+,v+), (u-,v+) are counter-clockwise seen from +a.
    auto& indices = out.mesh.indices;
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;
        for (int z = 0; z < g.samples.z; ++z)
            for (int y = 0; y < g.samples.y; ++y)
                for (int x = 0; x < g.samples.x; ++x) {
                    glm::ivec3 p0(x, y, z), p1 = p0;
                    p1[axis] += 1;
                    if (p1[axis] >= g.samples[axis] || p0[u] == 0 || p0[w] == 0 ||
                        p0[u] >= cells[u] || p0[w] >= cells[w])
                        continue;
                    const bool in0 = g.values[g.index(p0.x, p0.y, p0.z)] < 0.0;
                    const bool in1 = g.values[g.index(p1.x, p1.y, p1.z)] < 0.0;
                    if (in0 == in1)
                        continue;
                    std::uint32_t q[4];
                    const int du[4] = {-1, 0, 0, -1}, dw[4] = {-1, -1, 0, 0};
                    bool complete = true;
                    for (int k = 0; k < 4; ++k) {
                        glm::ivec3 c = p0;
                        c[u] += du[k];
                        c[w] += dw[k];
                        q[k] = cellVertex[cellIndex(c.x, c.y, c.z)];
                        complete = complete && q[k] != kNoVertex;
                    }
                    if (!complete)
                        continue;
                    if (!in0)  // the surface faces -axis: reverse the winding
                        std::swap(q[1], q[3]);
                    // Split along the shorter diagonal: fewer slivers.
                    const float d02 = glm::distance(positions[q[0]], positions[q[2]]);
                    const float d13 = glm::distance(positions[q[1]], positions[q[3]]);
                    if (d02 <= d13)
                        indices.insert(indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
                    else
                        indices.insert(indices.end(), {q[0], q[1], q[3], q[1], q[2], q[3]});
                }
    }

    out.mesh.normals.resize(positions.size());
    tbb::parallel_for(std::size_t(0), positions.size(), [&](std::size_t i) {
        out.mesh.normals[i] = glm::vec3(model.evaluateGradient(glm::dvec3(positions[i]), options.frame));
    });
    out.triangleMaterial.resize(indices.size() / 3);
    tbb::parallel_for(std::size_t(0), out.triangleMaterial.size(), [&](std::size_t t) {
        const glm::dvec3 c = (glm::dvec3(positions[indices[3 * t]]) + glm::dvec3(positions[indices[3 * t + 1]]) +
                              glm::dvec3(positions[indices[3 * t + 2]])) / 3.0;
        out.triangleMaterial[t] = model.evaluateMaterial(c, options.frame);
    });
    return out;
}

} // namespace rtlab::scene
