#include "openvdb_volume_to_mesh.h"

#include "isosurface_test_support.h"
#include "plugin/technique.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

// Defined by RTLAB_REGISTER_TECHNIQUE at the bottom of openvdb_volume_to_mesh.cpp.
void rtlabRegisterTechnique_isosurface_openvdb_volume_to_mesh(rtlab::plugin::Registry& registry);

namespace rtlab::isosurface {
namespace {

using namespace test;
using Sdf = SdfFunction;

//! Float rounding of samples and of index-space vertex positions (2^-24 relative, indices <= 64
//! here) mapped to world units (spacing <= 2/31): below 1e-6.
constexpr double kRounding = 1e-6;

TriangleMesh extractMesh(const plugin::SampledField& field, const ParamOverrides& overrides = {},
                         OpenVdbVolumeToMesh* keep = nullptr)
{
    OpenVdbVolumeToMesh technique(makeParams<OpenVdbVolumeToMesh>(overrides));
    return extractMeshWith(keep != nullptr ? *keep : technique, field);
}

//! Cells whose eight corners are not all on one side: with one sheet per cell, one point each.
std::size_t countMixedCells(const plugin::SampledField& field)
{
    std::size_t count = 0;
    const glm::ivec3 n = field.samples;
    for (int z = 0; z + 1 < n.z; ++z)
        for (int y = 0; y + 1 < n.y; ++y)
            for (int x = 0; x + 1 < n.x; ++x) {
                int inside = 0;
                for (int c = 0; c < 8; ++c)
                    inside += field.at(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1)) < 0.0f;
                count += inside != 0 && inside != 8;
            }
    return count;
}

class OpenVdbSphere : public ::testing::TestWithParam<int> {};

TEST_P(OpenVdbSphere, ClosedManifoldOutwardWithBoundedErrors)
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
    EXPECT_TRUE(mesh.normals.empty());
    // Dual mesh: one point per mixed cell (a sphere this smooth crosses each once), one quad per
    // crossed grid edge, split into two triangles.
    EXPECT_EQ(mesh.vertexCount(), countMixedCells(field));
    EXPECT_EQ(mesh.triangleCount(), 2 * countCrossedEdges(field));

    // Each edge crossing is the zero of the linear interpolant, inside the sphere by at most
    // depth = h^2 / (8 (r - h)) (the sphere SDF is convex along the edge with f'' <= 1 / (r - h)).
    // A point is a mean of crossings of one cell, at most D = sqrt(3) h apart; a convex combination
    // q of points v_i has |q|^2 = sum l_i |v_i|^2 - sum_{i<j} l_i l_j |v_i - v_j|^2
    // >= (r - depth)^2 - D^2 / 3, and |q| <= r. So r - |q| <= r - sqrt((r - depth)^2 - h^2).
    const double depth = h * h / (8.0 * (radius - h));
    const double pointDepth = radius - std::sqrt(std::pow(radius - depth, 2) - h * h);
    double maxAbs = 0.0;
    double maxSigned = -std::numeric_limits<double>::infinity();
    for (const glm::vec3& p : mesh.positions) {
        const double d = sdf(glm::dvec3(p));
        maxAbs = std::max(maxAbs, std::abs(d));
        maxSigned = std::max(maxSigned, d);
    }
    EXPECT_LE(maxAbs, pointDepth + kRounding) << "h = " << h;
    EXPECT_LE(maxSigned, kRounding);

    // Volume: a triangle joins points of cells around one grid edge, at most D = 3 h apart
    // (offsets of up to 2 h on two axes and h on the third), so with the same identity its points
    // have |q|^2 >= (r - pointDepth)^2 - 3 h^2: between two balls. Positive: outward winding.
    const double innerRadius = std::sqrt(std::pow(radius - pointDepth, 2) - 3.0 * h * h);
    const double ballVolume = 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
    const double innerVolume = 4.0 / 3.0 * std::numbers::pi * std::pow(innerRadius, 3);
    const double roundingVolume = 4.0 * std::numbers::pi * radius * radius * kRounding;
    const double volume = computeSignedVolume(mesh);
    EXPECT_GT(volume, 0.0) << "triangles face inward";
    EXPECT_LE(volume, ballVolume + roundingVolume);
    EXPECT_GE(volume, innerVolume - roundingVolume)
        << "relative error " << (ballVolume - volume) / ballVolume;
}

INSTANTIATE_TEST_SUITE_P(Resolutions, OpenVdbSphere, ::testing::Values(32, 64));

TEST(OpenVdbVolumeToMesh, TorusIsClosedWithGenusOne)
{
    const Sdf sdf = [](const glm::dvec3& p) {
        return computeTorusSdf(p, glm::dvec3(0.0), 0.5, 0.2);
    };
    const TriangleMesh mesh = extractMesh(sampleUnitCube(48, sdf));
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 0);
    const double analytic = 2.0 * std::numbers::pi * std::numbers::pi * 0.5 * 0.2 * 0.2;
    const double volume = computeSignedVolume(mesh);
    EXPECT_GT(volume, 0.9 * analytic);
    EXPECT_LE(volume, analytic * (1.0 + 1e-6));
}

TEST(OpenVdbVolumeToMesh, BoxBetweenSamplePlanesHasExactCounts)
{
    // Samples at integer coordinates 0..9; box [2.5, 5.5]^3: the inside samples are the 3x3x3
    // block 3..5. Mixed cells span 2..6 per axis (4^3 = 64) minus the 2^3 inside ones: 56 points.
    // Crossed edges: 3x3 per block face, 54 quads, 108 triangles; 56 - 162 + 108 = 2.
    // Every crossing is at a face plane (SDF -0.5 to +0.5). Points are means of their cell's
    // crossings: a face cell's four crossings lie on one face plane (SDF 0, 24 points); an edge
    // cell's are (5.5, 5, z), (5.5, 5, z + 1), (5, 5.5, z), (5, 5.5, z + 1) up to symmetry, mean
    // (5.25, 5.25, z + 1/2), SDF -1/4 (24 points); a corner cell's are (5.5, 5, 5), (5, 5.5, 5),
    // (5, 5, 5.5), mean 5 + 1/6 per axis, SDF -1/3 (8 points).
    const glm::dvec3 center(4.0);
    const glm::dvec3 halfExtent(1.5);
    const Sdf sdf = [&](const glm::dvec3& p) { return computeBoxSdf(p, center, halfExtent); };
    const plugin::SampledField field = sampleField(glm::ivec3(10), glm::dvec3(0.0), 1.0, sdf);
    const TriangleMesh mesh = extractMesh(field);

    EXPECT_EQ(mesh.vertexCount(), 56u);
    EXPECT_EQ(mesh.triangleCount(), 108u);
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    std::map<int, int> byDepth;  // SDF in units of 1/12
    for (const glm::vec3& p : mesh.positions) {
        const double d = 12.0 * sdf(glm::dvec3(p));
        EXPECT_NEAR(d, std::round(d), 1e-5);
        ++byDepth[int(std::lround(d))];
    }
    EXPECT_EQ(byDepth, (std::map<int, int>{{0, 24}, {-3, 24}, {-4, 8}}));
    EXPECT_GT(computeSignedVolume(mesh), 0.0);
    EXPECT_LT(computeSignedVolume(mesh), 27.0);
}

TEST(OpenVdbVolumeToMesh, SurfaceLeavingTheGridIsCappedOnItsFaces)
{
    // The plane x = 3.3 through 8^3 samples: the half-space x < 3.3 is inside, the background
    // beyond the grid outside, so the mesh closes the slab [0, 3.3] x [0, 7]^2 with points on the
    // grid faces and on the plane. Only where the plane meets a grid face is the slab chamfered:
    // the voxel beyond the face straddling the plane averages crossings (3.3, 0, .) and (3, 0, .)
    // to x = 3.15 on the face, while the next point in is (3.3, 0.5, .). In cross-section that
    // cuts the triangle (3.15, 0), (3.3, 0), (3.3, 0.5) of area 0.0375, along four edges of length
    // 7 (overlapping at the corners): the volume is in [3.3 * 49 - 4 * 7 * 0.0375, 3.3 * 49].
    const plugin::SampledField field = sampleField(glm::ivec3(8), glm::dvec3(0.0), 1.0,
                                                   [](const glm::dvec3& p) { return p.x - 3.3; });
    const TriangleMesh mesh = extractMesh(field);
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    for (const glm::vec3& p : mesh.positions) {
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_GE(p[axis], -1e-6f);
            EXPECT_LE(p[axis], 7.0f + 1e-6f);
        }
        EXPECT_LE(p.x, 3.3f + 1e-6f);
    }
    const double volume = computeSignedVolume(mesh);
    EXPECT_LE(volume, 3.3 * 49.0 + 1e-4);
    EXPECT_GE(volume, 3.3 * 49.0 - 4.0 * 7.0 * 0.0375 - 1e-4);
}

TEST(OpenVdbVolumeToMesh, AdaptivityMergesPolygons)
{
    // Adaptive meshes join large and small polygons with T-junctions, so they are not checked
    // for watertightness; volume and orientation still hold.
    const Sdf sdf = [](const glm::dvec3& p) {
        return computeBoxSdf(p, glm::dvec3(0.03, -0.02, 0.01), glm::dvec3(0.6, 0.5, 0.4));
    };
    const plugin::SampledField field = sampleUnitCube(48, sdf);
    OpenVdbVolumeToMesh adaptive(
        [] {
            config::ParamSet p =
                config::ParamSet::defaultsOf(OpenVdbVolumeToMesh::declareParams());
            p.set("adaptivity", 0.5);
            return p;
        }());
    const TriangleMesh uniform = extractMesh(field);
    const TriangleMesh merged = extractMesh(field, {}, &adaptive);
    EXPECT_LT(merged.triangleCount(), uniform.triangleCount() / 2);
    EXPECT_TRUE(isMeshFinite(merged));
    const double boxVolume = 1.2 * 1.0 * 0.8;
    EXPECT_NEAR(computeSignedVolume(merged), boxVolume, 0.05 * boxVolume);
    EXPECT_NEAR(computeSignedVolume(uniform), boxVolume, 0.05 * boxVolume);
}

TEST(OpenVdbVolumeToMesh, ThreadCountDoesNotChangeTheMeshAndCountersSplitTheTime)
{
    const Sdf sdf = [](const glm::dvec3& p) { return glm::length(p) - 0.6; };
    const plugin::SampledField field = sampleUnitCube(40, sdf);
    config::ParamSet params = config::ParamSet::defaultsOf(OpenVdbVolumeToMesh::declareParams());
    params.set("threads", std::int64_t(1));
    OpenVdbVolumeToMesh single(params);
    const TriangleMesh one = extractMesh(field, {}, &single);
    const auto counters = single.counters();
    std::map<std::string, double> byName(counters.begin(), counters.end());
    ASSERT_EQ(byName.size(), 6u);
    EXPECT_GE(byName.at("grid_ms"), 0.0);
    EXPECT_GE(byName.at("mesh_ms"), 0.0);
    EXPECT_GE(byName.at("convert_ms"), 0.0);
    EXPECT_EQ(byName.at("active_voxels"), 40.0 * 40.0 * 40.0);
    EXPECT_EQ(2.0 * byName.at("quads") + byName.at("triangles"), double(one.triangleCount()));

    const TriangleMesh all = extractMesh(field);
    EXPECT_EQ(one.positions, all.positions);
    EXPECT_EQ(one.indices, all.indices);
}

TEST(OpenVdbVolumeToMesh, EmptyAndDegenerateGrids)
{
    plugin::SampledField field = sampleUnitCube(8, [](const glm::dvec3&) { return 1.0; });
    TriangleMesh mesh = extractMesh(field);
    EXPECT_EQ(mesh.vertexCount(), 0u);
    EXPECT_EQ(mesh.triangleCount(), 0u);
    field = sampleField(glm::ivec3(8, 8, 1), glm::dvec3(0.0), 1.0,
                        [](const glm::dvec3& p) { return p.x - 3.5; });
    mesh = extractMesh(field);
    EXPECT_EQ(mesh.vertexCount(), 0u);
    field.values.pop_back();
    EXPECT_THROW(extractMesh(field), std::invalid_argument);
    OpenVdbVolumeToMesh technique(
        config::ParamSet::defaultsOf(OpenVdbVolumeToMesh::declareParams()));
    EXPECT_THROW(technique.extract(plugin::IsosurfaceInput{}, mesh), std::invalid_argument);
}

TEST(OpenVdbVolumeToMesh, RegisteredWithEffectiveParams)
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    rtlabRegisterTechnique_isosurface_openvdb_volume_to_mesh(registry);
    const plugin::TechniqueEntry* entry =
        registry.findTechnique("isosurface", "openvdb_volume_to_mesh");
    ASSERT_NE(entry, nullptr);
    EXPECT_NE(entry->info.reference.find("Museth 2013"), std::string::npos);
    config::ParamSet params = config::ParamSet::defaultsOf(entry->schema);
    params.set("adaptivity", 0.25);
    params.set("threads", std::int64_t(2));
    const auto technique = entry->create(params);
    EXPECT_EQ(technique->effectiveParams(), params);
    params.set("adaptivity", 1.5);
    EXPECT_THROW(OpenVdbVolumeToMesh{params}, std::invalid_argument);
}

} // namespace
} // namespace rtlab::isosurface
