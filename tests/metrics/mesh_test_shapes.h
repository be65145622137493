#pragma once
// Meshes and exact signed distance fields for the mesh metric tests.

#include "core/mesh.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace rtlab::metrics::testing {

//! Exact signed distance of the box |x_i| <= h_i.
inline double evaluateBoxSdf(const glm::dvec3& p, const glm::dvec3& h)
{
    const glm::dvec3 q = glm::abs(p) - h;
    return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

//! Gradient of evaluateBoxSdf (unit length except on the box's medial axis).
inline glm::dvec3 evaluateBoxGradient(const glm::dvec3& p, const glm::dvec3& h)
{
    const glm::dvec3 q = glm::abs(p) - h;
    const glm::dvec3 s(p.x < 0 ? -1 : 1, p.y < 0 ? -1 : 1, p.z < 0 ? -1 : 1);
    if (q.x > 0 || q.y > 0 || q.z > 0)
        return s * glm::normalize(glm::max(q, 0.0));
    const int axis = q.x >= q.y && q.x >= q.z ? 0 : (q.y >= q.z ? 1 : 2);
    glm::dvec3 g(0.0);
    g[axis] = s[axis];
    return g;
}

inline double evaluateSphereSdf(const glm::dvec3& p, double r) { return glm::length(p) - r; }

//! The cube [-h, h]^3 with each face an n x n grid of quads split into two triangles, outward
//! counter-clockwise. `shared` welds the grid vertices along the cube's edges; otherwise every
//! face has its own vertices (and flat per-face normals).
inline TriangleMesh makeCubeMesh(float h, int n, bool shared = true)
{
    TriangleMesh mesh;
    std::map<std::array<int, 3>, std::uint32_t> ids;
    auto vertex = [&](const glm::ivec3& g, const glm::vec3& normal) {
        const std::array<int, 3> key{g.x, g.y, g.z};
        if (shared) {
            if (auto it = ids.find(key); it != ids.end())
                return it->second;
        }
        const auto id = std::uint32_t(mesh.positions.size());
        mesh.positions.push_back(h * (glm::vec3(g) * (2.0f / float(n)) - 1.0f));
        mesh.normals.push_back(normal);
        if (shared)
            ids[key] = id;
        return id;
    };
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            glm::vec3 normal(0.0f);
            normal[axis] = side ? 1.0f : -1.0f;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    std::uint32_t c[4];
                    const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
                    for (int k = 0; k < 4; ++k) {
                        glm::ivec3 g(0);
                        g[axis] = side ? n : 0;
                        g[u] = i + du[k];
                        g[v] = j + dv[k];
                        c[k] = vertex(g, normal);
                    }
                    // (u, v, axis) is right-handed: counter-clockwise in (u, v) faces +axis.
                    if (side)
                        mesh.indices.insert(mesh.indices.end(),
                                            {c[0], c[1], c[2], c[0], c[2], c[3]});
                    else
                        mesh.indices.insert(mesh.indices.end(),
                                            {c[0], c[2], c[1], c[0], c[3], c[2]});
                }
        }
    return mesh;
}

//! Icosphere of radius r: the icosahedron with each triangle split into 4, `level` times, and
//! every vertex pushed onto the sphere. Outward counter-clockwise.
inline TriangleMesh makeIcosphere(double r, int level)
{
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<glm::dvec3> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                 {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                 {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<std::uint32_t> f = {0, 11, 5, 0, 5,  1,  0,  1, 7, 0, 7,  10, 0, 10, 11,
                                    1, 5,  9, 5, 11, 4,  11, 10, 2, 10, 7, 6,  7, 1,  8,
                                    3, 9,  4, 3, 4,  2,  3,  2, 6, 3, 6,  8,  3, 8,  9,
                                    4, 9,  5, 2, 4,  11, 6,  2, 10, 8, 6, 7,  9, 8,  1};
    for (auto& v : p)
        v = glm::normalize(v);
    for (int l = 0; l < level; ++l) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
        auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            if (auto it = mid.find(key); it != mid.end())
                return it->second;
            p.push_back(glm::normalize(p[a] + p[b]));
            return mid[key] = std::uint32_t(p.size() - 1);
        };
        std::vector<std::uint32_t> next;
        for (std::size_t i = 0; i < f.size(); i += 3) {
            const std::uint32_t a = f[i], b = f[i + 1], c = f[i + 2];
            const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        f = std::move(next);
    }
    TriangleMesh mesh;
    for (const auto& v : p) {
        mesh.positions.push_back(glm::vec3(r * v));
        mesh.normals.push_back(glm::vec3(v));
    }
    mesh.indices = f;
    return mesh;
}

//! Largest circumradius over the triangles (from the stored float positions).
inline double findMaxCircumradius(const TriangleMesh& mesh)
{
    double best = 0;
    for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
        const glm::dvec3 a(mesh.positions[mesh.indices[i]]), b(mesh.positions[mesh.indices[i + 1]]),
            c(mesh.positions[mesh.indices[i + 2]]);
        const double area2 = glm::length(glm::cross(b - a, c - a));
        best = std::max(best, glm::length(b - a) * glm::length(c - b) * glm::length(a - c) /
                                  (2.0 * area2));
    }
    return best;
}

//! Convex polyhedron whose faces are the planes n.x = max over the points, for each of the given
//! normals: each face is the polygon of the points on its plane, sorted around its centre and
//! fanned into triangles (outward counter-clockwise). Points are shared between faces.
inline TriangleMesh makeConvexPolyhedron(const std::vector<glm::dvec3>& points,
                                         const std::vector<glm::dvec3>& normals)
{
    TriangleMesh mesh;
    for (const auto& q : points)
        mesh.positions.push_back(glm::vec3(q));
    for (const glm::dvec3& n : normals) {
        double top = -1e300;
        for (const auto& q : points)
            top = std::max(top, glm::dot(n, q));
        std::vector<std::uint32_t> face;
        glm::dvec3 centre(0.0);
        for (std::size_t i = 0; i < points.size(); ++i)
            if (glm::dot(n, points[i]) > top - 1e-9) {
                face.push_back(std::uint32_t(i));
                centre += points[i];
            }
        centre /= double(face.size());
        const glm::dvec3 e0 = glm::normalize(points[face[0]] - centre);
        const glm::dvec3 e1 = glm::cross(glm::normalize(n), e0);
        auto angle = [&](std::uint32_t i) {
            const glm::dvec3 d = points[i] - centre;
            return std::atan2(glm::dot(d, e1), glm::dot(d, e0));
        };
        std::sort(face.begin(), face.end(),
                  [&](std::uint32_t a, std::uint32_t b) { return angle(a) < angle(b); });
        for (std::size_t k = 1; k + 1 < face.size(); ++k)
            mesh.indices.insert(mesh.indices.end(), {face[0], face[k], face[k + 1]});
    }
    return mesh;
}

//! The cube [-1, 1]^3 with its 12 edges cut by 45-degree bevels of width w on each face and its
//! corners cut by triangles: 6 squares, 12 rectangles, 8 triangles, 24 vertices.
inline TriangleMesh makeChamferedCube(double w)
{
    std::vector<glm::dvec3> points;
    for (int axis = 0; axis < 3; ++axis)
        for (int s0 : {-1, 1})
            for (int s1 : {-1, 1})
                for (int s2 : {-1, 1}) {
                    glm::dvec3 q(s1 * (1 - w), s2 * (1 - w), 0.0);
                    glm::dvec3 p(0.0);
                    p[axis] = s0;
                    p[(axis + 1) % 3] = q.x;
                    p[(axis + 2) % 3] = q.y;
                    points.push_back(p);
                }
    std::vector<glm::dvec3> normals;
    for (int axis = 0; axis < 3; ++axis)
        for (int s : {-1, 1}) {
            glm::dvec3 n(0.0);
            n[axis] = s;
            normals.push_back(n);
            for (int s1 : {-1, 1}) {
                glm::dvec3 m = n;
                m[(axis + 1) % 3] = s1;
                normals.push_back(m);  // each bevel once: (axis, axis + 1) pairs
            }
        }
    for (int sx : {-1, 1})
        for (int sy : {-1, 1})
            for (int sz : {-1, 1})
                normals.push_back({sx, sy, sz});
    return makeConvexPolyhedron(points, normals);
}

//! Regular octahedron with vertices at +-1 on the axes: 8 equilateral faces.
inline TriangleMesh makeOctahedron()
{
    std::vector<glm::dvec3> points = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0},
                                      {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    std::vector<glm::dvec3> normals;
    for (int sx : {-1, 1})
        for (int sy : {-1, 1})
            for (int sz : {-1, 1})
                normals.push_back({sx, sy, sz});
    return makeConvexPolyhedron(points, normals);
}

//! Appends `part` to `mesh`, offsetting its indices and translating it.
inline void appendMesh(TriangleMesh& mesh, const TriangleMesh& part,
                       const glm::vec3& offset = glm::vec3(0.0f))
{
    const auto base = std::uint32_t(mesh.positions.size());
    for (const auto& p : part.positions)
        mesh.positions.push_back(p + offset);
    for (const auto i : part.indices)
        mesh.indices.push_back(base + i);
    mesh.normals.clear();
}

} // namespace rtlab::metrics::testing
