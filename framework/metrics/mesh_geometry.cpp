#include "metrics/mesh_metrics_detail.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>

namespace rtlab::metrics::detail {

namespace {

std::uint64_t mixSplit(std::uint64_t z)
{
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

std::uint32_t floatBits(float value)
{
    value += 0.0f;  // -0 becomes +0
    std::uint32_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    return bits;
}

struct PositionKey {
    std::uint32_t x, y, z;
    bool operator==(const PositionKey&) const = default;
};

struct PositionKeyHash {
    std::size_t operator()(const PositionKey& k) const
    {
        return std::size_t(mixSplit((std::uint64_t(k.x) << 32 | k.y) ^ mixSplit(k.z)));
    }
};

} // namespace

double hashToUnit(std::uint64_t seed, std::uint64_t index, std::uint64_t stream)
{
    const std::uint64_t h = mixSplit(mixSplit(mixSplit(seed) ^ index) ^ stream);
    return double(h >> 11) * 0x1.0p-53;  // 53 random bits
}

glm::dvec3 findClosestPointOnSegment(const glm::dvec3& p, const glm::dvec3& a,
                                     const glm::dvec3& b)
{
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    if (len2 == 0.0)
        return a;
    const double t = std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0);
    return a + t * ab;
}

glm::dvec3 findClosestPointOnTriangle(const glm::dvec3& p, const glm::dvec3& a,
                                      const glm::dvec3& b, const glm::dvec3& c)
{
    const glm::dvec3 ab = b - a, ac = c - a;
    const glm::dvec3 n = glm::cross(ab, ac);
    const double scale = glm::dot(ab, ab) * glm::dot(ac, ac);
    if (!(glm::dot(n, n) > 1e-24 * scale)) {  // no area (or NaN): nearest of the three edges
        glm::dvec3 best = findClosestPointOnSegment(p, a, b);
        for (const glm::dvec3& q :
             {findClosestPointOnSegment(p, b, c), findClosestPointOnSegment(p, c, a)})
            if (glm::dot(q - p, q - p) < glm::dot(best - p, best - p))
                best = q;
        return best;
    }
    // Voronoi regions of the vertices, then of the edges, else the face.
    const glm::dvec3 ap = p - a;
    const double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0)
        return a;
    const glm::dvec3 bp = p - b;
    const double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3)
        return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0)
        return a + (d1 / (d1 - d3)) * ab;
    const glm::dvec3 cp = p - c;
    const double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6)
        return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0)
        return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

void checkMesh(const TriangleMesh& mesh, const char* what)
{
    if (mesh.indices.size() % 3 != 0)
        throw Error(std::string("metrics: ") + what + ": the mesh has " +
                    std::to_string(mesh.indices.size()) + " indices, not a multiple of 3");
    for (std::size_t i = 0; i < mesh.indices.size(); ++i)
        if (mesh.indices[i] >= mesh.positions.size())
            throw Error(std::string("metrics: ") + what + ": index " + std::to_string(i) +
                        " is " + std::to_string(mesh.indices[i]) + " but there are only " +
                        std::to_string(mesh.positions.size()) + " positions");
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::vec3& p = mesh.positions[i];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw Error(std::string("metrics: ") + what + ": position " + std::to_string(i) +
                        " is not finite");
    }
}

std::vector<std::uint32_t> mergeVerticesByPosition(const TriangleMesh& mesh)
{
    std::vector<std::uint32_t> canonical(mesh.positions.size());
    std::unordered_map<PositionKey, std::uint32_t, PositionKeyHash> first;
    first.reserve(mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const glm::vec3& p = mesh.positions[i];
        const PositionKey key{floatBits(p.x), floatBits(p.y), floatBits(p.z)};
        canonical[i] = first.try_emplace(key, std::uint32_t(i)).first->second;
    }
    return canonical;
}

bool testTrianglesIntersect(const glm::dvec3 p[3], const glm::dvec3 q[3])
{
    // Work relative to p[0] so that the projections do not lose digits to a far origin.
    const glm::dvec3 origin = p[0];
    glm::dvec3 a[3], b[3], ea[3], eb[3];
    for (int i = 0; i < 3; ++i) {
        a[i] = p[i] - origin;
        b[i] = q[i] - origin;
    }
    for (int i = 0; i < 3; ++i) {
        ea[i] = a[(i + 1) % 3] - a[i];
        eb[i] = b[(i + 1) % 3] - b[i];
    }
    auto separates = [&](const glm::dvec3& axis) {
        double loA = glm::dot(axis, a[0]), hiA = loA, loB = glm::dot(axis, b[0]), hiB = loB;
        for (int i = 1; i < 3; ++i) {
            const double sa = glm::dot(axis, a[i]), sb = glm::dot(axis, b[i]);
            loA = std::min(loA, sa);
            hiA = std::max(hiA, sa);
            loB = std::min(loB, sb);
            hiB = std::max(hiB, sb);
        }
        return hiA < loB || hiB < loA;  // a zero axis never separates
    };
    const glm::dvec3 na = glm::cross(ea[0], ea[1]), nb = glm::cross(eb[0], eb[1]);
    if (separates(na) || separates(nb))
        return false;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (separates(glm::cross(ea[i], eb[j])))
                return false;
    // In-plane edge normals: decisive when the triangles are coplanar.
    for (int i = 0; i < 3; ++i)
        if (separates(glm::cross(na, ea[i])) || separates(glm::cross(nb, eb[i])))
            return false;
    return true;
}

} // namespace rtlab::metrics::detail
