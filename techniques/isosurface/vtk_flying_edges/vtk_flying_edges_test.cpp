#include "vtk_flying_edges.h"

#include "isosurface_test_support.h"
#include "plugin/technique.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

// Defined by RTLAB_REGISTER_TECHNIQUE at the bottom of vtk_flying_edges.cpp.
void rtlabRegisterTechnique_isosurface_vtk_flying_edges(rtlab::plugin::Registry& registry);

namespace rtlab::isosurface {
namespace {

using namespace test;
using Sdf = SdfFunction;

//! Float rounding of samples and of index-space vertex positions (2^-24 relative, indices <= 64
//! here) mapped to world units (spacing <= 2/31): below 1e-6.
constexpr double kRounding = 1e-6;

TriangleMesh extractMesh(const plugin::SampledField& field, const ParamOverrides& overrides = {},
                         VtkFlyingEdges* keep = nullptr)
{
    VtkFlyingEdges technique(makeParams<VtkFlyingEdges>(overrides));
    return extractMeshWith(keep != nullptr ? *keep : technique, field);
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
        return computeTorusSdf(p, glm::dvec3(0.0), 0.5, 0.2);
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
