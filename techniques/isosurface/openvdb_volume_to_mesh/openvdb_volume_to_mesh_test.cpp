#include "openvdb_volume_to_mesh.h"

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

// Defined by RTLAB_REGISTER_TECHNIQUE at the bottom of openvdb_volume_to_mesh.cpp.
void rtlabRegisterTechnique_isosurface_openvdb_volume_to_mesh(rtlab::plugin::Registry& registry);

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
                         OpenVdbVolumeToMesh* keep = nullptr)
{
    config::ParamSet params = config::ParamSet::defaultsOf(OpenVdbVolumeToMesh::declareParams());
    for (const auto& [name, value] : overrides)
        params.set(name, value);
    OpenVdbVolumeToMesh technique(params);
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
        const glm::dvec2 q(glm::length(glm::dvec2(p.x, p.z)) - 0.5, p.y);
        return glm::length(q) - 0.2;
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
