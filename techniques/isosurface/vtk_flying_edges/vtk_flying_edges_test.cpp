#include "vtk_flying_edges.h"

#include "plugin/technique.h"

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <unordered_map>
#include <vector>

// Defined by RTLAB_REGISTER_TECHNIQUE at the bottom of vtk_flying_edges.cpp.
void rtlabRegisterTechnique_isosurface_vtk_flying_edges(rtlab::plugin::Registry& registry);

namespace rtlab::isosurface {
namespace {

using Sdf = std::function<double(const glm::dvec3&)>;
using Overrides = std::map<std::string, config::ParamValue>;

//! Float rounding of samples and of index-space vertex positions (2^-24 relative, indices <= 64
//! here) mapped to world units (spacing <= 2/31): below 1e-6.
constexpr double kRounding = 1e-6;

plugin::SampledField sampleField(glm::ivec3 samples, glm::dvec3 origin, double spacing,
                                 const Sdf& sdf)
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

//! n^3 samples spanning [-1, 1]^3.
plugin::SampledField sampleUnitCube(int n, const Sdf& sdf)
{
    return sampleField(glm::ivec3(n), glm::dvec3(-1.0), 2.0 / (n - 1), sdf);
}

TriangleMesh extractMesh(const plugin::SampledField& field, const Overrides& overrides = {},
                         VtkFlyingEdges* keep = nullptr)
{
    config::ParamSet params = config::ParamSet::defaultsOf(VtkFlyingEdges::declareParams());
    for (const auto& [name, value] : overrides)
        params.set(name, value);
    VtkFlyingEdges technique(params);
    plugin::IsosurfaceInput input;
    input.field = &field;
    TriangleMesh mesh;
    (keep != nullptr ? *keep : technique).extract(input, mesh);
    return mesh;
}

struct Topology {
    std::size_t vertices = 0;
    std::size_t edges = 0;
    std::size_t faces = 0;
    std::size_t unreferencedVertices = 0;
    std::size_t badIndices = 0;
    std::size_t boundaryEdges = 0;
    std::size_t overusedEdges = 0;
    std::size_t repeatedDirectedEdges = 0;

    long euler() const { return long(vertices) - long(edges) + long(faces); }
};

Topology analyzeTopology(const TriangleMesh& mesh)
{
    Topology t;
    t.faces = mesh.triangleCount();
    const std::size_t n = mesh.vertexCount();
    std::unordered_map<std::uint64_t, int> directed;
    std::vector<bool> used(n, false);
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
            continue;
        ++t.edges;
        if (count + reverseCount == 1)
            ++t.boundaryEdges;
        if (count + reverseCount > 2)
            ++t.overusedEdges;
    }
    for (std::size_t i = 0; i < n; ++i)
        (used[i] ? t.vertices : t.unreferencedVertices) += 1;
    return t;
}

void expectClosedOriented(const Topology& t)
{
    EXPECT_GT(t.faces, 0u);
    EXPECT_EQ(t.badIndices, 0u);
    EXPECT_EQ(t.boundaryEdges, 0u) << "holes";
    EXPECT_EQ(t.overusedEdges, 0u) << "edges shared by more than two triangles";
    EXPECT_EQ(t.repeatedDirectedEdges, 0u) << "inconsistent orientation";
    EXPECT_EQ(t.unreferencedVertices, 0u);
}

//! Enclosed volume by the divergence theorem; positive when triangles face outward.
double computeSignedVolume(const TriangleMesh& mesh)
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

bool isMeshFinite(const TriangleMesh& mesh)
{
    const auto finite = [](const glm::vec3& v) {
        return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
    };
    return std::all_of(mesh.positions.begin(), mesh.positions.end(), finite) &&
           std::all_of(mesh.normals.begin(), mesh.normals.end(), finite);
}

//! Grid edges whose ends are on opposite sides of the iso-value: one vertex each.
std::size_t countCrossedEdges(const plugin::SampledField& field)
{
    std::size_t count = 0;
    const glm::ivec3 n = field.samples;
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const bool in = field.at(x, y, z) < 0.0f;
                count += x + 1 < n.x && in != (field.at(x + 1, y, z) < 0.0f);
                count += y + 1 < n.y && in != (field.at(x, y + 1, z) < 0.0f);
                count += z + 1 < n.z && in != (field.at(x, y, z + 1) < 0.0f);
            }
    return count;
}

double computeBoxSdf(const glm::dvec3& p, const glm::dvec3& center, const glm::dvec3& halfExtent)
{
    const glm::dvec3 q = glm::abs(p - center) - halfExtent;
    return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

class VtkFlyingEdgesSphere : public ::testing::TestWithParam<int> {};

TEST_P(VtkFlyingEdgesSphere, ClosedManifoldOutwardWithBoundedErrors)
{
    const int n = GetParam();
    const double radius = 0.7;
    const double h = 2.0 / (n - 1);
    const Sdf sdf = [&](const glm::dvec3& p) { return glm::length(p) - radius; };
    const plugin::SampledField field = sampleUnitCube(n, sdf);
    const TriangleMesh mesh = extractMesh(field);

    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    EXPECT_TRUE(isMeshFinite(mesh));
    // Flying edges writes one point per crossed grid edge.
    EXPECT_EQ(mesh.vertexCount(), countCrossedEdges(field));

    // Vertices sit on the zero of the linear interpolant along a crossed edge. The sphere SDF is
    // convex along the edge with second derivative <= 1 / (r - h) (the edge is within h of the
    // surface), and a chord of a convex function with f'' <= K lies at most K h^2 / 8 above it: at
    // the chord's zero the SDF is in [-h^2 / (8 (r - h)), 0].
    const double depthBound = h * h / (8.0 * (radius - h));
    double maxAbs = 0.0;
    double maxSigned = -std::numeric_limits<double>::infinity();
    for (const glm::vec3& p : mesh.positions) {
        const double d = sdf(glm::dvec3(p));
        maxAbs = std::max(maxAbs, std::abs(d));
        maxSigned = std::max(maxSigned, d);
    }
    EXPECT_LE(maxAbs, depthBound + kRounding) << "h = " << h;
    EXPECT_LE(maxSigned, kRounding);

    // Volume: triangle points are convex combinations of vertices at most D = sqrt(3) h apart
    // (one cell), so |q|^2 >= (r - depth)^2 - D^2 / 3 and the mesh lies between the ball of radius
    // r_in = sqrt((r - depth)^2 - h^2) and the ball of radius r. Positive: triangles face outward.
    const double innerRadius = std::sqrt(std::pow(radius - depthBound, 2) - h * h);
    const double ballVolume = 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
    const double innerVolume = 4.0 / 3.0 * std::numbers::pi * std::pow(innerRadius, 3);
    const double roundingVolume = 4.0 * std::numbers::pi * radius * radius * kRounding;
    const double volume = computeSignedVolume(mesh);
    EXPECT_GT(volume, 0.0) << "triangles face inward";
    EXPECT_LE(volume, ballVolume + roundingVolume);
    EXPECT_GE(volume, innerVolume - roundingVolume)
        << "relative error " << (ballVolume - volume) / ballVolume;

    // Normals: unit, and outward: within 10 degrees of the radial direction (the gradient of the
    // sampled field at these resolutions; a flip would give 180).
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    double maxAngle = 0.0;
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i) {
        const glm::dvec3 normal = mesh.normals[i];
        EXPECT_NEAR(glm::length(normal), 1.0, 1e-5);
        const double cosine =
            glm::dot(glm::normalize(normal), glm::normalize(glm::dvec3(mesh.positions[i])));
        maxAngle = std::max(maxAngle, std::acos(std::clamp(cosine, -1.0, 1.0)));
    }
    EXPECT_LE(maxAngle, 10.0 * std::numbers::pi / 180.0);
}

INSTANTIATE_TEST_SUITE_P(Resolutions, VtkFlyingEdgesSphere, ::testing::Values(32, 64));

TEST(VtkFlyingEdges, TorusIsClosedWithGenusOne)
{
    const Sdf sdf = [](const glm::dvec3& p) {
        const glm::dvec2 q(glm::length(glm::dvec2(p.x, p.z)) - 0.5, p.y);
        return glm::length(q) - 0.2;
    };
    const TriangleMesh mesh = extractMesh(sampleUnitCube(48, sdf));
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 0);
    // Analytic volume 2 pi^2 R r^2; the sampled surface lies inside it (see the sphere bounds).
    const double analytic = 2.0 * std::numbers::pi * std::numbers::pi * 0.5 * 0.2 * 0.2;
    const double volume = computeSignedVolume(mesh);
    EXPECT_GT(volume, 0.9 * analytic);
    EXPECT_LE(volume, analytic * (1.0 + 1e-6));
}

TEST(VtkFlyingEdges, BoxBetweenSamplePlanesHasExactCounts)
{
    // Samples at integer coordinates 0..9; box [2.5, 5.5]^3: the inside samples are the 3x3x3
    // block 3..5 and every face lies halfway between two sample planes.
    // Vertices: one per grid edge leaving the block, 3x3 per block face: 54.
    // Mixed cells: 6 faces * 4 (four inside corners, a quad: 2 triangles), 12 edges * 2 (two
    // inside corners, a quad: 2 triangles), 8 corners (one inside corner, 1 triangle): 104.
    // Every crossed edge joins SDF -0.5 to +0.5, so the vertex is on the face plane; the quads of
    // the edge cells are planar chamfers, so the volume does not depend on the diagonals chosen:
    // per octant 1 + 3 * 0.5 + 3 * 0.125 + 0.5^3 / 6 = 139/48, in all 139/6.
    const glm::dvec3 center(4.0);
    const glm::dvec3 halfExtent(1.5);
    const Sdf sdf = [&](const glm::dvec3& p) { return computeBoxSdf(p, center, halfExtent); };
    const plugin::SampledField field = sampleField(glm::ivec3(10), glm::dvec3(0.0), 1.0, sdf);
    const TriangleMesh mesh = extractMesh(field);

    EXPECT_EQ(mesh.vertexCount(), 54u);
    EXPECT_EQ(mesh.triangleCount(), 104u);
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    EXPECT_NEAR(computeSignedVolume(mesh), 139.0 / 6.0, 1e-9);
    for (const glm::vec3& p : mesh.positions)
        EXPECT_NEAR(sdf(glm::dvec3(p)), 0.0, 1e-12);
}

TEST(VtkFlyingEdges, WorldMappingUsesOriginAndSpacing)
{
    // The same samples at two placements: vertices map by origin + spacing * index.
    const Sdf sdf = [](const glm::dvec3& p) { return glm::length(p - glm::dvec3(8.0)) - 5.3; };
    plugin::SampledField field = sampleField(glm::ivec3(17), glm::dvec3(0.0), 1.0, sdf);
    const TriangleMesh unit = extractMesh(field);
    field.origin = glm::dvec3(1e3, -2e3, 5.0);
    field.spacing = 0.25;
    const TriangleMesh moved = extractMesh(field);
    ASSERT_EQ(unit.vertexCount(), moved.vertexCount());
    EXPECT_EQ(unit.indices, moved.indices);
    for (std::size_t i = 0; i < unit.vertexCount(); ++i) {
        const glm::dvec3 expected = field.origin + 0.25 * glm::dvec3(unit.positions[i]);
        EXPECT_NEAR(glm::length(glm::dvec3(moved.positions[i]) - expected), 0.0, 1e-3);
    }
}

TEST(VtkFlyingEdges, ThreadCountDoesNotChangeTheMeshAndCountersSplitTheTime)
{
    const Sdf sdf = [](const glm::dvec3& p) { return glm::length(p) - 0.6; };
    const plugin::SampledField field = sampleUnitCube(40, sdf);
    config::ParamSet params = config::ParamSet::defaultsOf(VtkFlyingEdges::declareParams());
    params.set("threads", std::int64_t(1));
    VtkFlyingEdges single(params);
    const TriangleMesh one = extractMesh(field, {}, &single);
    const auto counters = single.counters();
    std::map<std::string, double> byName(counters.begin(), counters.end());
    ASSERT_EQ(byName.size(), 4u);
    EXPECT_EQ(byName.at("smp_threads"), 1.0);
    EXPECT_GE(byName.at("filter_ms"), 0.0);
    EXPECT_GE(byName.at("convert_ms"), 0.0);
    // Debian 12's VTK 9.1 is built with the TBB backend; any known backend is accepted.
    EXPECT_GE(byName.at("smp_backend"), 0.0);

    const TriangleMesh all = extractMesh(field, {{"threads", std::int64_t(0)}});
    EXPECT_EQ(one.positions, all.positions);
    EXPECT_EQ(one.indices, all.indices);
}

TEST(VtkFlyingEdges, NoNormalsWhenAskedAndSameTriangles)
{
    const Sdf sdf = [](const glm::dvec3& p) { return glm::length(p) - 0.6; };
    const plugin::SampledField field = sampleUnitCube(24, sdf);
    const TriangleMesh with = extractMesh(field);
    const TriangleMesh without = extractMesh(field, {{"normals", std::string("none")}});
    EXPECT_TRUE(without.normals.empty());
    EXPECT_EQ(with.indices, without.indices);
    EXPECT_EQ(with.positions, without.positions);
}

TEST(VtkFlyingEdges, EmptyAndDegenerateGrids)
{
    // All outside: no surface.
    plugin::SampledField field = sampleUnitCube(8, [](const glm::dvec3&) { return 1.0; });
    TriangleMesh mesh = extractMesh(field);
    EXPECT_EQ(mesh.vertexCount(), 0u);
    EXPECT_EQ(mesh.triangleCount(), 0u);
    // One sample thick: no cells.
    field = sampleField(glm::ivec3(8, 8, 1), glm::dvec3(0.0), 1.0,
                        [](const glm::dvec3& p) { return p.x - 3.5; });
    mesh.positions.assign(3, glm::vec3(1.0f));
    mesh = extractMesh(field);
    EXPECT_EQ(mesh.vertexCount(), 0u);
    // Mismatched value count and null field throw.
    field.values.pop_back();
    EXPECT_THROW(extractMesh(field), std::invalid_argument);
    VtkFlyingEdges technique(config::ParamSet::defaultsOf(VtkFlyingEdges::declareParams()));
    EXPECT_THROW(technique.extract(plugin::IsosurfaceInput{}, mesh), std::invalid_argument);
}

TEST(VtkFlyingEdges, RegisteredWithEffectiveParams)
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    rtlabRegisterTechnique_isosurface_vtk_flying_edges(registry);
    const plugin::TechniqueEntry* entry = registry.findTechnique("isosurface", "vtk_flying_edges");
    ASSERT_NE(entry, nullptr);
    EXPECT_NE(entry->info.reference.find("Flying Edges"), std::string::npos);
    config::ParamSet params = config::ParamSet::defaultsOf(entry->schema);
    params.set("threads", std::int64_t(3));
    const auto technique = entry->create(params);
    EXPECT_EQ(technique->effectiveParams(), params);
    params.set("threads", std::int64_t(-1));
    EXPECT_THROW(VtkFlyingEdges{params}, std::invalid_argument);
}

} // namespace
} // namespace rtlab::isosurface
