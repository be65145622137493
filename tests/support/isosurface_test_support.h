#pragma once
// Helpers shared by the isosurface technique tests and the isosurface family suite: sampling
// analytic SDFs onto grids, running a technique, and checking the topology, volume and finiteness
// of the meshes it writes. Header-only; link rtlab_isosurface_test_support.

#include "config/param.h"
#include "core/mesh.h"
#include "families/isosurface/isosurface.h"

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <numeric>
#include <string>
#include <unordered_map>
#include <vector>

namespace rtlab::test {

//! A scalar field in world units, negative inside.
using SdfFunction = std::function<double(const glm::dvec3&)>;
//! Parameter values replacing a technique's defaults, by name.
using ParamOverrides = std::map<std::string, config::ParamValue>;

// ---------------------------------------------------------------------------------------------
// Shapes

inline double computeSphereSdf(const glm::dvec3& p, double radius)
{
    return glm::length(p) - radius;
}

inline double computeSphereSdf(const glm::dvec3& p, const glm::dvec3& center, double radius)
{
    return glm::length(p - center) - radius;
}

//! Torus around the y axis through `center`.
inline double computeTorusSdf(const glm::dvec3& p, const glm::dvec3& center, double major,
                              double minor)
{
    const glm::dvec3 q = p - center;
    return glm::length(glm::dvec2(glm::length(glm::dvec2(q.x, q.z)) - major, q.y)) - minor;
}

inline double computeBoxSdf(const glm::dvec3& p, const glm::dvec3& center,
                            const glm::dvec3& halfExtent)
{
    const glm::dvec3 q = glm::abs(p - center) - halfExtent;
    return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

// ---------------------------------------------------------------------------------------------
// Sampling and extraction

inline plugin::SampledField sampleField(glm::ivec3 samples, glm::dvec3 origin, double spacing,
                                        const SdfFunction& sdf)
{
    plugin::SampledField field;
    field.samples = samples;
    field.origin = origin;
    field.spacing = spacing;
    field.values.resize(std::size_t(samples.x) * samples.y * samples.z);
    for (int z = 0; z < samples.z; ++z)
        for (int y = 0; y < samples.y; ++y)
            for (int x = 0; x < samples.x; ++x)
                field.values[field.index(x, y, z)] = float(sdf(field.position(x, y, z)));
    return field;
}

//! n^3 samples spanning [-1, 1]^3 (spacing 2 / (n - 1)).
inline plugin::SampledField sampleUnitCube(int n, const SdfFunction& sdf)
{
    return sampleField(glm::ivec3(n), glm::dvec3(-1.0), 2.0 / (n - 1), sdf);
}

//! The technique's default parameters with `overrides` applied.
template <class Technique> config::ParamSet makeParams(const ParamOverrides& overrides = {})
{
    config::ParamSet params = config::ParamSet::defaultsOf(Technique::declareParams());
    for (const auto& [name, value] : overrides)
        params.set(name, value);
    return params;
}

//! Runs `technique` on `field` at `isoValue`.
inline TriangleMesh extractMeshWith(plugin::IsosurfaceTechnique& technique,
                                    const plugin::SampledField& field, double isoValue = 0.0)
{
    plugin::IsosurfaceInput input;
    input.field = &field;
    input.isoValue = isoValue;
    TriangleMesh mesh;
    technique.extract(input, mesh);
    return mesh;
}

// ---------------------------------------------------------------------------------------------
// Mesh checks

struct Topology {
    std::size_t vertices = 0; //!< referenced by some triangle
    std::size_t edges = 0;    //!< undirected
    std::size_t faces = 0;
    std::size_t unreferencedVertices = 0;
    std::size_t badIndices = 0;            //!< out of range or repeated within a triangle
    std::size_t boundaryEdges = 0;         //!< undirected edges used by one triangle
    std::size_t overusedEdges = 0;         //!< undirected edges used by three or more triangles
    std::size_t nonManifoldEdges = 0;      //!< undirected edges not used by exactly two triangles
    std::size_t unbalancedEdges = 0;       //!< a->b used a different number of times than b->a
    std::size_t repeatedDirectedEdges = 0; //!< directed edges used twice: inconsistent winding
    std::size_t components = 0;            //!< connected by shared vertices

    long euler() const { return long(vertices) - long(edges) + long(faces); }
};

inline std::size_t findRoot(std::vector<std::size_t>& parent, std::size_t i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

inline Topology analyzeTopology(const TriangleMesh& mesh)
{
    Topology t;
    t.faces = mesh.triangleCount();
    const std::size_t n = mesh.vertexCount();
    std::unordered_map<std::uint64_t, int> directed;
    std::vector<bool> used(n, false);
    std::vector<std::size_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    for (std::size_t f = 0; f < t.faces; ++f) {
        const std::uint32_t v[3] = {mesh.indices[3 * f], mesh.indices[3 * f + 1],
                                    mesh.indices[3 * f + 2]};
        if (v[0] >= n || v[1] >= n || v[2] >= n || v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
            ++t.badIndices;
            continue;
        }
        for (int k = 0; k < 3; ++k) {
            used[v[k]] = true;
            ++directed[(std::uint64_t(v[k]) << 32) | v[(k + 1) % 3]];
            parent[findRoot(parent, v[k])] = findRoot(parent, v[(k + 1) % 3]);
        }
    }
    for (const auto& [key, count] : directed) {
        if (count > 1)
            ++t.repeatedDirectedEdges;
        const std::uint64_t a = key >> 32;
        const std::uint64_t b = key & 0xffffffffu;
        const auto reverse = directed.find((b << 32) | a);
        const int reverseCount = reverse == directed.end() ? 0 : reverse->second;
        if (reverseCount != 0 && a > b)
            continue; // counted from the other direction
        ++t.edges;
        const int total = count + reverseCount;
        if (total == 1)
            ++t.boundaryEdges;
        if (total > 2)
            ++t.overusedEdges;
        if (total != 2)
            ++t.nonManifoldEdges;
        if (count != reverseCount)
            ++t.unbalancedEdges;
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (!used[i])
            ++t.unreferencedVertices;
        else
            ++t.vertices;
        if (used[i] && findRoot(parent, i) == i)
            ++t.components;
    }
    return t;
}

//! Every undirected edge shared by exactly two triangles, each directed edge used once, every
//! vertex used, no bad index.
inline void expectClosedOriented(const Topology& t)
{
    EXPECT_GT(t.faces, 0u);
    EXPECT_EQ(t.badIndices, 0u);
    EXPECT_EQ(t.boundaryEdges, 0u) << "holes";
    EXPECT_EQ(t.overusedEdges, 0u) << "edges shared by more than two triangles";
    EXPECT_EQ(t.repeatedDirectedEdges, 0u) << "inconsistent orientation";
    EXPECT_EQ(t.unreferencedVertices, 0u);
    EXPECT_EQ(2 * t.edges, 3 * t.faces);
}

//! Enclosed volume by the divergence theorem; positive when triangles face outward.
inline double computeSignedVolume(const TriangleMesh& mesh)
{
    double volume = 0.0;
    for (std::size_t f = 0; f < mesh.triangleCount(); ++f) {
        const glm::dvec3 a = mesh.positions[mesh.indices[3 * f]];
        const glm::dvec3 b = mesh.positions[mesh.indices[3 * f + 1]];
        const glm::dvec3 c = mesh.positions[mesh.indices[3 * f + 2]];
        volume += glm::dot(a, glm::cross(b, c)) / 6.0;
    }
    return volume;
}

//! Positions and normals finite.
inline bool isMeshFinite(const TriangleMesh& mesh)
{
    const auto finite = [](const glm::vec3& v) {
        return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    };
    return std::all_of(mesh.positions.begin(), mesh.positions.end(), finite) &&
           std::all_of(mesh.normals.begin(), mesh.normals.end(), finite);
}

//! Grid edges whose ends are on opposite sides (f < iso inside), counted independently of the
//! mesher.
inline std::size_t countCrossedEdges(const plugin::SampledField& field, double isoValue = 0.0)
{
    std::size_t count = 0;
    const glm::ivec3 n = field.samples;
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const bool in = field.at(x, y, z) < isoValue;
                count += x + 1 < n.x && in != (field.at(x + 1, y, z) < isoValue);
                count += y + 1 < n.y && in != (field.at(x, y + 1, z) < isoValue);
                count += z + 1 < n.z && in != (field.at(x, y, z + 1) < isoValue);
            }
    return count;
}

} // namespace rtlab::test
