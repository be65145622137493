#include "marching_cubes.h"

#include "case_table.h"
#include "isosurface_test_support.h"
#include "plugin/technique.h"

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <tuple>
#include <vector>

// Defined by RTLAB_REGISTER_TECHNIQUE at the bottom of marching_cubes.cpp.
void rtlabRegisterTechnique_isosurface_marching_cubes(rtlab::plugin::Registry& registry);

namespace rtlab::isosurface {
namespace {

using namespace test;
using Sdf = SdfFunction;

//! Float rounding of samples (2^-24 relative, |f| <= 2 here) and of vertex positions (2^-24
//! relative, |p| <= 10 here) is below 1e-6 by more than an order of magnitude.
constexpr double kRounding = 1e-6;

TriangleMesh extractMesh(const plugin::SampledField& field, const ParamOverrides& overrides = {},
                         double isoValue = 0.0)
{
    MarchingCubes technique(makeParams<MarchingCubes>(overrides));
    return extractMeshWith(technique, field, isoValue);
}

double computeTriangleArea(const TriangleMesh& mesh, std::size_t f)
{
    const glm::dvec3 a = mesh.positions[mesh.indices[3 * f]];
    const glm::dvec3 b = mesh.positions[mesh.indices[3 * f + 1]];
    const glm::dvec3 c = mesh.positions[mesh.indices[3 * f + 2]];
    return 0.5 * glm::length(glm::cross(b - a, c - a));
}

std::size_t countDuplicatePositions(const TriangleMesh& mesh)
{
    std::vector<std::array<float, 3>> sorted;
    for (const glm::vec3& p : mesh.positions)
        sorted.push_back({p.x, p.y, p.z});
    std::sort(sorted.begin(), sorted.end());
    return std::size_t(sorted.end() - std::unique(sorted.begin(), sorted.end()));
}

// ---------------------------------------------------------------------------------------------
// Case table

TEST(MarchingCubesCaseTable, EntriesUseCrossedEdgesAndNoDiagonalAcrossAnAmbiguousFace)
{
    const mc::CaseTable& table = mc::CaseTable::getInstance();
    std::size_t expectedEntries = 0;
    std::size_t interiorVertices = 0;
    std::size_t loops = 0;
    for (unsigned cube = 0; cube < 256; ++cube) {
        const unsigned ambiguous = table.ambiguousFaces(cube);
        for (int f = 0; f < mc::kFaceCount; ++f)
            EXPECT_EQ(((ambiguous >> f) & 1u) != 0, mc::isFaceAmbiguous(cube, f));
        const unsigned combinations = 1u << std::popcount(ambiguous);
        expectedEntries += combinations;
        std::array<bool, mc::kEdgeCount> crossed{};
        int crossedCount = 0;
        for (int e = 0; e < mc::kEdgeCount; ++e) {
            const mc::CellEdge& edge = mc::getCellEdges()[e];
            crossed[e] = ((cube >> edge.start) & 1u) != ((cube >> edge.end) & 1u);
            crossedCount += crossed[e];
        }
        for (unsigned decisions = 0; decisions < combinations; ++decisions) {
            SCOPED_TRACE("case " + std::to_string(cube) + " decisions " +
                         std::to_string(decisions));
            // The face decisions as a per-face mask, as the table spreads them.
            unsigned joined = 0;
            for (int f = 0, bit = 0; f < mc::kFaceCount; ++f) {
                if ((ambiguous >> f) & 1u)
                    joined |= ((decisions >> bit++) & 1u) << f;
            }
            const mc::CellTriangulation& cell = table.find(cube, decisions);
            std::array<bool, mc::kEdgeCount> referenced{};
            for (int k = 0; k < 3 * cell.triangleCount; ++k) {
                const int id = cell.vertices[k];
                ASSERT_LT(id, mc::kExtraVertex + cell.extraCount);
                if (id < mc::kEdgeCount)
                    referenced[id] = true;
            }
            EXPECT_EQ(referenced, crossed);
            // A loop of L edges gives L - 2 triangles, or L around an interior vertex.
            EXPECT_LE(cell.triangleCount, crossedCount);
            EXPECT_GE(3 * cell.triangleCount, crossedCount);
            // The fixed rules never need interior vertices; only mixed decisions can.
            if (decisions == 0 || decisions == combinations - 1) {
                EXPECT_EQ(cell.extraCount, 0);
            }
            interiorVertices += cell.extraCount;
            // triangles = crossed - 2 loops + 2 interior vertices
            loops += std::size_t((crossedCount - cell.triangleCount) / 2 + cell.extraCount);

            // No triangle side may join two edges of an ambiguous face unless a segment of that
            // face joins them, i.e. they surround a corner the decision cuts off: inside corners
            // when separated, outside corners when joined. (On other faces the two crossed edges
            // are always the face's segment.)
            for (int t = 0; t < cell.triangleCount; ++t) {
                for (int k = 0; k < 3; ++k) {
                    const int a = cell.vertices[3 * t + k];
                    const int b = cell.vertices[3 * t + (k + 1) % 3];
                    for (int f = 0; f < mc::kFaceCount; ++f) {
                        if (((ambiguous >> f) & 1u) == 0)
                            continue;
                        const mc::CellFace& face = mc::getCellFaces()[f];
                        const auto slot = [&](int e) {
                            return int(std::find(face.edges.begin(), face.edges.end(), e) -
                                       face.edges.begin());
                        };
                        const int i = slot(a);
                        const int j = slot(b);
                        if (i == 4 || j == 4)
                            continue;
                        // Edges k-1 and k surround corner k.
                        const int corner = (j == (i + 1) % 4) ? j : (i == (j + 1) % 4) ? i : -1;
                        ASSERT_NE(corner, -1) << "diagonal across face " << f;
                        const bool cornerInside = (cube >> face.corners[corner]) & 1u;
                        const bool cutsInside = ((joined >> f) & 1u) == 0;
                        EXPECT_EQ(cornerInside, cutsInside) << "side across face " << f;
                    }
                }
            }
        }
    }
    EXPECT_EQ(table.entryCount(), expectedEntries);
    // 116 of the table's 1026 loops cannot be triangulated on their edge vertices alone.
    EXPECT_EQ(loops, 1026u);
    EXPECT_EQ(interiorVertices, 116u);
    // The checkerboard configurations have all six faces ambiguous.
    EXPECT_EQ(table.ambiguousFaces(0x69), 0x3fu);
    EXPECT_EQ(table.ambiguousFaces(0x96), 0x3fu);
    EXPECT_EQ(table.ambiguousFaces(0x01), 0u);
}

TEST(MarchingCubesCaseTable, ComplementWithOppositeDecisionsIsTheSameSurfaceReversed)
{
    // Swapping inside and outside while also swapping every face decision describes the same
    // curve network, so the triangles must be the same with the opposite winding.
    const auto canonical = [](std::array<int, 3> t) {
        std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
        return t;
    };
    for (unsigned cube = 0; cube < 256; ++cube) {
        const unsigned ambiguous = mc::CaseTable::getInstance().ambiguousFaces(cube);
        for (unsigned joined = 0; joined < 64; ++joined) {
            if ((joined & ~ambiguous) != 0)
                continue;
            const mc::CellTriangulation a = mc::triangulateCell(cube, joined);
            const mc::CellTriangulation b = mc::triangulateCell(~cube & 255u, ~joined & ambiguous);
            ASSERT_EQ(a.triangleCount, b.triangleCount) << "case " << cube;
            ASSERT_EQ(a.extraCount, b.extraCount) << "case " << cube;
            EXPECT_EQ(a.extraLoops, b.extraLoops) << "case " << cube;
            std::vector<std::array<int, 3>> reversedA;
            std::vector<std::array<int, 3>> trianglesB;
            for (int t = 0; t < a.triangleCount; ++t) {
                reversedA.push_back(
                    canonical({a.vertices[3 * t + 2], a.vertices[3 * t + 1], a.vertices[3 * t]}));
                trianglesB.push_back(
                    canonical({b.vertices[3 * t], b.vertices[3 * t + 1], b.vertices[3 * t + 2]}));
            }
            std::sort(reversedA.begin(), reversedA.end());
            std::sort(trianglesB.begin(), trianglesB.end());
            EXPECT_EQ(reversedA, trianglesB) << "case " << cube << " joined " << joined;
        }
    }
}

TEST(MarchingCubesCaseTable, SingleCornerTrianglesFaceAwayFromTheInside)
{
    // One inside corner: one triangle on its three edges, normal pointing away from the corner.
    // Seven inside corners: one triangle, normal pointing toward the single outside corner.
    const auto midpoint = [](int edge) {
        const mc::CellEdge& e = mc::getCellEdges()[edge];
        glm::dvec3 p(0.0);
        for (int axis = 0; axis < 3; ++axis)
            p[axis] = 0.5 * (mc::getCornerBit(e.start, axis) + mc::getCornerBit(e.end, axis));
        return p;
    };
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 cornerPos(mc::getCornerBit(corner, 0), mc::getCornerBit(corner, 1),
                                   mc::getCornerBit(corner, 2));
        for (const bool single : {true, false}) {
            const unsigned cube = single ? (1u << corner) : (~(1u << corner) & 255u);
            const mc::CellTriangulation& cell = mc::CaseTable::getInstance().find(cube, 0);
            ASSERT_EQ(cell.triangleCount, 1);
            const glm::dvec3 a = midpoint(cell.vertices[0]);
            const glm::dvec3 b = midpoint(cell.vertices[1]);
            const glm::dvec3 c = midpoint(cell.vertices[2]);
            const glm::dvec3 normal = glm::cross(b - a, c - a);
            const glm::dvec3 awayFromCorner = (a + b + c) / 3.0 - cornerPos;
            const double facing = glm::dot(normal, awayFromCorner);
            EXPECT_GT(single ? facing : -facing, 0.0) << "corner " << corner;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Sphere

class MarchingCubesSphere : public ::testing::TestWithParam<int> {};

TEST_P(MarchingCubesSphere, ClosedManifoldWithBoundedErrors)
{
    const int n = GetParam();
    const double radius = 0.7;
    const double h = 2.0 / (n - 1);
    const Sdf sdf = [&](const glm::dvec3& p) { return computeSphereSdf(p, radius); };
    const plugin::SampledField field = sampleUnitCube(n, sdf);
    const TriangleMesh mesh = extractMesh(field);

    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    EXPECT_EQ(t.components, 1u);
    EXPECT_TRUE(isMeshFinite(mesh));
    // One vertex per crossed grid edge, none duplicated.
    EXPECT_EQ(mesh.vertexCount(), countCrossedEdges(field));
    EXPECT_EQ(countDuplicatePositions(mesh), 0u);

    // Vertex error. Along a grid edge the sphere SDF |p| - r is convex with second derivative
    // (1 - (p.d)^2/|p|^2)/|p| <= 1/|p| <= 1/(r - h) (a crossed edge lies within h of the
    // surface). The chord of a convex function with f'' <= K lies above it by at most K h^2 / 8,
    // so at the chord's zero the SDF is in [-h^2 / (8 (r - h)), 0]: every vertex is inside or on
    // the sphere, within that depth.
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

    // Volume. A point q of a triangle is a convex combination of its vertices v_i, and
    // |q|^2 = sum l_i |v_i|^2 - sum_{i<j} l_i l_j |v_i - v_j|^2 >= (r - depth)^2 - D^2 / 3, where
    // the vertices of one cell are at most D = sqrt(3) h apart and sum_{i<j} l_i l_j <= 1/3. So
    // the mesh lies in the shell between r_in = sqrt((r - depth)^2 - h^2) and r, and the volume
    // it encloses lies between the two balls' volumes.
    const double innerRadius = std::sqrt(std::pow(radius - depthBound, 2) - h * h);
    const double ballVolume = 4.0 / 3.0 * std::numbers::pi * std::pow(radius, 3);
    const double innerVolume = 4.0 / 3.0 * std::numbers::pi * std::pow(innerRadius, 3);
    const double roundingVolume = 4.0 * std::numbers::pi * radius * radius * kRounding;
    const double volume = computeSignedVolume(mesh);
    EXPECT_GT(volume, 0.0) << "triangles face inward";
    EXPECT_LE(volume, ballVolume + roundingVolume);
    EXPECT_GE(volume, innerVolume - roundingVolume)
        << "relative error " << (ballVolume - volume) / ballVolume;

    // Normals. With edge ends a, b (unit radial directions A, B at angle
    // theta <= 2 asin(h / (2 (r - h)))) and vertex parameter s, the exact gradients mix to
    // (1 - s) A + s B while the vertex direction is that of (1 - s)|a| A + s|b| B. Their weights
    // on B differ by s (1 - s) ||b| - |a|| / ((1 - s)|a| + s|b|) <= h / (4 (r - h)), and the
    // direction of (1 - w) A + w B turns by at most sin(theta) / cos^2(theta / 2) per unit of w.
    // Central differences add h^2/6 |f'''| per component, with |f'''| <= 2 / (sqrt(3) R^2) on an
    // axis line at distance >= R = r - 2h from the centre: at most eps = h^2 / (3 R^2) in length,
    // which turns a vector of length >= cos(theta / 2) by at most asin(eps / cos(theta / 2)).
    ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
    const double theta = 2.0 * std::asin(h / (2.0 * (radius - h)));
    const double halfCos = std::cos(theta / 2.0);
    const double eps = h * h / (3.0 * std::pow(radius - 2.0 * h, 2));
    const double angleBound = std::sin(theta) / (halfCos * halfCos) * h / (4.0 * (radius - h)) +
                              std::asin(eps / halfCos) + kRounding;
    double maxAngle = 0.0;
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i) {
        const glm::dvec3 normal = mesh.normals[i];
        EXPECT_NEAR(glm::length(normal), 1.0, 1e-6);
        const double cosine =
            glm::dot(glm::normalize(normal), glm::normalize(glm::dvec3(mesh.positions[i])));
        maxAngle = std::max(maxAngle, std::acos(std::clamp(cosine, -1.0, 1.0)));
    }
    EXPECT_LE(maxAngle, angleBound);
}

INSTANTIATE_TEST_SUITE_P(Resolutions, MarchingCubesSphere, ::testing::Values(32, 64));

TEST(MarchingCubes, MidpointPlacementMovesVerticesOnly)
{
    const double radius = 0.7;
    const int n = 32;
    const double h = 2.0 / (n - 1);
    const Sdf sdf = [&](const glm::dvec3& p) { return computeSphereSdf(p, radius); };
    const plugin::SampledField field = sampleUnitCube(n, sdf);
    const TriangleMesh linear = extractMesh(field);
    const TriangleMesh midpoint =
        extractMesh(field, {{"vertex_placement", std::string("midpoint")}});

    // The topology comes from the signs (and face decisions), not from where vertices go.
    EXPECT_EQ(midpoint.indices, linear.indices);
    expectClosedOriented(analyzeTopology(midpoint));
    // The surface crosses the edge, the SDF is 1-Lipschitz: a midpoint is within h/2 of it.
    double maxAbs = 0.0;
    for (const glm::vec3& p : midpoint.positions)
        maxAbs = std::max(maxAbs, std::abs(sdf(glm::dvec3(p))));
    EXPECT_LE(maxAbs, h / 2.0 + kRounding);
    // And it is really a different placement: worse than linear interpolation's bound.
    EXPECT_GT(maxAbs, h * h / (8.0 * (radius - h)));
}

TEST(MarchingCubes, TorusIsClosedWithGenusOne)
{
    const double major = 0.5;
    const double minor = 0.2;
    const Sdf sdf = [&](const glm::dvec3& p) {
        return computeTorusSdf(p, glm::dvec3(0.0), major, minor);
    };
    const TriangleMesh mesh = extractMesh(sampleUnitCube(48, sdf));
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 0);
    EXPECT_EQ(t.components, 1u);
    EXPECT_GT(computeSignedVolume(mesh), 0.0);
    EXPECT_TRUE(isMeshFinite(mesh));
}

// ---------------------------------------------------------------------------------------------
// Exact counts

TEST(MarchingCubes, BoxBetweenSamplePlanesHasExactCounts)
{
    // Samples at integer coordinates 0..9; box [2.5, 5.5]^3, so the inside samples are the
    // 3x3x3 block 3..5 and every face lies halfway between two sample planes.
    // Vertices: one per grid edge leaving the block, 3x3 per block face: 6 * 9 = 54.
    // Cells with mixed corners span 2..6 per axis (4^3 = 64) minus the 2^3 fully inside ones: 56.
    //   boundary on one axis   (6 faces * 2x2 cells = 24): 4 inside corners, a quad: 48 triangles
    //   boundary on two axes   (12 edges * 2 cells  = 24): 2 inside corners, a quad: 48 triangles
    //   boundary on three axes (8 corner cells):           1 inside corner, 1 triangle:  8
    // Triangles: 104. Edges 3 * 104 / 2 = 156, and 54 - 156 + 104 = 2.
    // Every crossed edge joins a sample at SDF -0.5 to one at +0.5, so linear interpolation puts
    // the vertex on the face plane. The mesh is the box cut by u+v <= 2.5 at edges and
    // u+v+w <= 3.5 at corners (u, v, w = |p - 4| per axis); per octant, splitting [0, 1.5]^3 at 1:
    // 1 + 3 * 0.5 + 3 * 0.125 + 0.5^3 / 6 = 139/48, so the volume is 139/6.
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

    // Every crossing is at t = 1/2, so the midpoint placement gives the very same mesh.
    const TriangleMesh midpoint =
        extractMesh(field, {{"vertex_placement", std::string("midpoint")}});
    EXPECT_EQ(midpoint.positions, mesh.positions);
    EXPECT_EQ(midpoint.indices, mesh.indices);
}

// ---------------------------------------------------------------------------------------------
// Ambiguous faces

//! Random values in [-1, 1] on the inner inner^3 samples, padded with +1 so that the surface is
//! closed. With `levels` > 0 the values are quantised to `levels` steps on each side of zero, so
//! that exact zeros and exact ties of the asymptotic decider (ac == bd) are frequent.
plugin::SampledField makeRandomField(int inner, unsigned seed, int levels = 0)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> continuous(-1.0f, 1.0f);
    std::uniform_int_distribution<int> discrete(-levels, levels);
    const auto uniform = [&](std::mt19937&) {
        return levels > 0 ? float(discrete(rng)) / float(levels) : continuous(rng);
    };
    plugin::SampledField field;
    field.samples = glm::ivec3(inner + 2);
    field.values.assign(std::size_t(inner + 2) * (inner + 2) * (inner + 2), 1.0f);
    for (int z = 1; z <= inner; ++z)
        for (int y = 1; y <= inner; ++y)
            for (int x = 1; x <= inner; ++x)
                field.values[field.index(x, y, z)] = uniform(rng);
    return field;
}

TEST(MarchingCubes, RandomFieldIsWatertightUnderEveryAmbiguityRule)
{
    const plugin::SampledField field = makeRandomField(16, 20240611u);

    // Count the ambiguous faces of the grid and how the asymptotic decider resolves them, so the
    // test is known to exercise both decisions.
    std::size_t joinedFaces = 0;
    std::size_t separatedFaces = 0;
    const glm::ivec3 n = field.samples;
    for (int axis = 0; axis < 3; ++axis) {
        const int u = axis == 0 ? 1 : 0;
        const int v = axis == 2 ? 1 : 2;
        for (int z = 0; z < n.z; ++z)
            for (int y = 0; y < n.y; ++y)
                for (int x = 0; x < n.x; ++x) {
                    glm::ivec3 p(x, y, z);
                    glm::ivec3 pu = p, puv = p, pv = p;
                    pu[u] += 1;
                    puv[u] += 1;
                    puv[v] += 1;
                    pv[v] += 1;
                    if (puv[u] >= n[u] || puv[v] >= n[v])
                        continue;
                    const double a = field.at(p.x, p.y, p.z);
                    const double b = field.at(pu.x, pu.y, pu.z);
                    const double c = field.at(puv.x, puv.y, puv.z);
                    const double d = field.at(pv.x, pv.y, pv.z);
                    if ((a < 0) != (c < 0) || (b < 0) != (d < 0) || (a < 0) == (b < 0))
                        continue;
                    const double inside = a < 0 ? a * c : b * d;
                    const double outside = a < 0 ? b * d : a * c;
                    ++(inside > outside ? joinedFaces : separatedFaces);
                }
    }
    EXPECT_GT(joinedFaces, 0u);
    EXPECT_GT(separatedFaces, 0u);

    std::map<std::string, std::vector<std::uint32_t>> indices;
    for (const std::string rule : {"asymptotic", "separate_inside", "join_inside"}) {
        SCOPED_TRACE(rule);
        const TriangleMesh mesh = extractMesh(field, {{"ambiguity", rule}});
        const Topology t = analyzeTopology(mesh);
        expectClosedOriented(t);
        EXPECT_EQ(t.euler() % 2, 0) << "a closed orientable surface has an even Euler number";
        // One vertex per crossed edge; the decider's mixed decisions may add interior vertices,
        // the fixed rules never do.
        if (rule == "asymptotic") {
            // This field has cells that need one, so the interior vertex path is exercised.
            EXPECT_GT(mesh.vertexCount(), countCrossedEdges(field));
        } else {
            EXPECT_EQ(mesh.vertexCount(), countCrossedEdges(field));
        }
        EXPECT_TRUE(isMeshFinite(mesh));
        indices[rule] = mesh.indices;
    }
    // The decider joins some faces and separates others, so it agrees with neither fixed rule.
    EXPECT_NE(indices["asymptotic"], indices["separate_inside"]);
    EXPECT_NE(indices["asymptotic"], indices["join_inside"]);
}

TEST(MarchingCubes, RandomFieldsOfManySeedsAreWatertight)
{
    // Continuous values, and values quantised to {-1, -1/2, 0, 1/2, 1}: exact zeros (outside),
    // zero products and exact decider ties on many faces.
    for (const int levels : {0, 2}) {
        for (unsigned seed = 1; seed <= 12; ++seed) {
            SCOPED_TRACE("levels " + std::to_string(levels) + " seed " + std::to_string(seed));
            const plugin::SampledField field = makeRandomField(12, seed, levels);
            for (const std::string rule : {"asymptotic", "separate_inside", "join_inside"}) {
                SCOPED_TRACE(rule);
                const TriangleMesh mesh = extractMesh(field, {{"ambiguity", rule}});
                const Topology t = analyzeTopology(mesh);
                expectClosedOriented(t);
                EXPECT_EQ(t.euler() % 2, 0);
                EXPECT_TRUE(isMeshFinite(mesh));
            }
        }
    }
}

TEST(MarchingCubes, ShiftingAFieldAlongLongRowsShiftsTheMesh)
{
    // The grid walk keeps a row's inside flags as 64-sample words and finds crossed edges and
    // active cells by shifting words into each other. A random 70 x 9 x 8 block (wider than one
    // word) padded with outside samples, moved right by 0 .. 130 samples, must give the same
    // triangles and vertex order, the vertices moved by exactly the shift: the padding's rows are
    // uniform, so no crossing appears or disappears. Shifts on both sides of the word boundaries
    // (63, 64, 65, 127, 128) catch a lost or doubled carry bit.
    std::mt19937 rng(91u);
    std::uniform_real_distribution<float> uniform(-1.0f, 1.0f);
    const glm::ivec3 block(70, 9, 8);
    std::vector<float> values(std::size_t(block.x) * block.y * block.z);
    for (float& v : values)
        v = uniform(rng);
    const auto makeShifted = [&](int shift) {
        plugin::SampledField field;
        field.samples = glm::ivec3(block.x + shift + 4, block.y + 2, block.z + 2);
        field.values.assign(std::size_t(field.samples.x) * field.samples.y * field.samples.z, 1.0f);
        for (int z = 0; z < block.z; ++z)
            for (int y = 0; y < block.y; ++y)
                for (int x = 0; x < block.x; ++x)
                    field.values[field.index(x + shift + 2, y + 1, z + 1)] =
                        values[(std::size_t(z) * block.y + y) * block.x + x];
        return field;
    };
    const TriangleMesh base = extractMesh(makeShifted(0));
    expectClosedOriented(analyzeTopology(base));
    ASSERT_GT(base.indices.size(), 3000u) << "the block should hold a rich surface";
    for (const int shift : {1, 30, 61, 62, 63, 64, 65, 126, 127, 128, 130}) {
        SCOPED_TRACE("shift " + std::to_string(shift));
        const TriangleMesh moved = extractMesh(makeShifted(shift));
        ASSERT_EQ(moved.indices, base.indices);
        ASSERT_EQ(moved.positions.size(), base.positions.size());
        for (std::size_t i = 0; i < base.positions.size(); ++i) {
            // y and z are computed from the same values; x = shift + the same offset, in floats
            // of magnitude <= 200: 2^-24 * 200 < 2e-5.
            EXPECT_NEAR(moved.positions[i].x, base.positions[i].x + float(shift), 2e-5);
            EXPECT_EQ(moved.positions[i].y, base.positions[i].y);
            EXPECT_EQ(moved.positions[i].z, base.positions[i].z);
            EXPECT_NEAR(glm::length(moved.normals[i] - base.normals[i]), 0.0f, 1e-6f);
        }
    }
}

TEST(MarchingCubes, AsymptoticDeciderFollowsTheSaddleValue)
{
    // Two inside columns, samples (1,1,z) and (2,2,z) for z = 1, 2, in a field of +1. The cell
    // between them has ambiguous faces z = 1 and z = 2 with inside pair -1, -1 and outside pair
    // v, v. The bilinear saddle value (ac - bd) / (a + c - b - d) = (1 - v^2) / (-2 - 2v) is
    // negative (inside, columns joined: one sphere) for v < 1, zero for v = 1 (on the
    // iso-value, counted outside: two spheres) and positive for v > 1 (two spheres).
    const auto makeColumns = [](float v) {
        plugin::SampledField field;
        field.samples = glm::ivec3(4);
        field.values.assign(64, 1.0f);
        for (int z = 1; z <= 2; ++z) {
            field.values[field.index(1, 1, z)] = -1.0f;
            field.values[field.index(2, 2, z)] = -1.0f;
            field.values[field.index(2, 1, z)] = v;
            field.values[field.index(1, 2, z)] = v;
        }
        return field;
    };
    struct Case {
        float v;
        std::string rule;
        std::size_t components;
    };
    const Case cases[] = {
        {0.5f, "asymptotic", 1},      {1.0f, "asymptotic", 2},      {2.0f, "asymptotic", 2},
        {0.5f, "separate_inside", 2}, {2.0f, "separate_inside", 2}, {0.5f, "join_inside", 1},
        {2.0f, "join_inside", 1},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.rule + " v=" + std::to_string(c.v));
        const TriangleMesh mesh = extractMesh(makeColumns(c.v), {{"ambiguity", c.rule}});
        const Topology t = analyzeTopology(mesh);
        expectClosedOriented(t);
        EXPECT_EQ(t.components, c.components);
        EXPECT_EQ(t.euler(), long(2 * c.components));
    }
}

// ---------------------------------------------------------------------------------------------
// Determinism

TEST(MarchingCubes, OutputDoesNotDependOnThreadsOrGrain)
{
    // A sphere with noise: many cells, ambiguous faces, and slabs of very different sizes.
    std::mt19937 rng(7u);
    std::uniform_real_distribution<double> noise(-0.05, 0.05);
    plugin::SampledField field =
        sampleUnitCube(40, [](const glm::dvec3& p) { return computeSphereSdf(p, 0.6); });
    for (float& value : field.values)
        value += float(noise(rng));

    const auto run = [&](int threads, std::int64_t grain) {
        tbb::task_arena arena(threads);
        TriangleMesh mesh;
        arena.execute([&] { mesh = extractMesh(field, {{"grain", grain}}); });
        return mesh;
    };
    const TriangleMesh reference = run(1, 1);
    ASSERT_GT(reference.triangleCount(), 1000u);
    // Interior vertices too, whose numbering goes through the per-slab fix-up.
    EXPECT_GT(reference.vertexCount(), countCrossedEdges(field));
    expectClosedOriented(analyzeTopology(reference));
    for (const auto& [threads, grain] :
         {std::pair{2, std::int64_t(1)}, std::pair{2, std::int64_t(3)},
          std::pair{2, std::int64_t(1024)}, std::pair{1, std::int64_t(8)}}) {
        SCOPED_TRACE("threads " + std::to_string(threads) + " grain " + std::to_string(grain));
        const TriangleMesh mesh = run(threads, grain);
        EXPECT_EQ(mesh.positions, reference.positions);
        EXPECT_EQ(mesh.normals, reference.normals);
        EXPECT_EQ(mesh.indices, reference.indices);
    }
}

// ---------------------------------------------------------------------------------------------
// Exact zeros, non-finite values, degenerate grids

TEST(MarchingCubes, PlaneOnSamplesGivesFlatNonDegenerateQuads)
{
    // f = z - 3 on samples 0..7: the layer z = 3 is exactly on the iso-value, hence outside, so
    // the crossed edges are the 8x8 z-edges from layer 2 to 3, each with its vertex exactly on
    // layer 3 (t = 1). The 7x7 cells between the layers each give a quad: 98 triangles of
    // area 1/2. The sheet is open on the grid boundary: 4 * 7 boundary edges, the others shared
    // by two triangles; it is a disk, Euler number 1.
    const plugin::SampledField field = sampleField(glm::ivec3(8), glm::dvec3(0.0), 1.0,
                                                   [](const glm::dvec3& p) { return p.z - 3.0; });
    const TriangleMesh mesh = extractMesh(field);
    EXPECT_EQ(mesh.vertexCount(), 64u);
    EXPECT_EQ(mesh.triangleCount(), 98u);
    const Topology t = analyzeTopology(mesh);
    EXPECT_EQ(t.boundaryEdges, 28u);
    EXPECT_EQ(t.overusedEdges, 0u);
    EXPECT_EQ(t.repeatedDirectedEdges, 0u);
    EXPECT_EQ(t.euler(), 1);
    for (const glm::vec3& p : mesh.positions)
        EXPECT_EQ(p.z, 3.0f);
    for (const glm::vec3& normal : mesh.normals)
        EXPECT_EQ(normal, glm::vec3(0.0f, 0.0f, 1.0f));
    for (std::size_t f = 0; f < mesh.triangleCount(); ++f) {
        EXPECT_DOUBLE_EQ(computeTriangleArea(mesh, f), 0.5);
        const glm::dvec3 a = mesh.positions[mesh.indices[3 * f]];
        const glm::dvec3 b = mesh.positions[mesh.indices[3 * f + 1]];
        const glm::dvec3 c = mesh.positions[mesh.indices[3 * f + 2]];
        EXPECT_GT(glm::cross(b - a, c - a).z, 0.0) << "faces toward +z, the positive side";
    }
}

TEST(MarchingCubes, BoxWithFacesOnSamplesIsClosedAndNonDegenerate)
{
    // Box [2, 6]^3 on samples 0..9: samples on its faces are exactly 0, hence outside; the inside
    // samples are again the 3x3x3 block 3..5, so the counts are those of the box between sample
    // planes (54, 104), but every vertex now sits exactly on a zero sample (t = 1). Each such
    // sample has a single inside neighbour, so no two vertices coincide and no triangle is
    // degenerate. Volume: per octant, splitting [0, 2]^3 at 1 (constraints u+v <= 3,
    // u+v+w <= 4): 1 + 3 * 1 + 3 * 0.5 + 1/6 = 17/3, so 136/3.
    const Sdf sdf = [](const glm::dvec3& p) {
        return computeBoxSdf(p, glm::dvec3(4.0), glm::dvec3(2.0));
    };
    const plugin::SampledField field = sampleField(glm::ivec3(10), glm::dvec3(0.0), 1.0, sdf);
    const TriangleMesh mesh = extractMesh(field);
    EXPECT_EQ(mesh.vertexCount(), 54u);
    EXPECT_EQ(mesh.triangleCount(), 104u);
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    EXPECT_NEAR(computeSignedVolume(mesh), 136.0 / 3.0, 1e-9);
    EXPECT_EQ(countDuplicatePositions(mesh), 0u);
    for (const glm::vec3& p : mesh.positions)
        EXPECT_EQ(sdf(glm::dvec3(p)), 0.0);
    double minArea = std::numeric_limits<double>::infinity();
    for (std::size_t f = 0; f < mesh.triangleCount(); ++f)
        minArea = std::min(minArea, computeTriangleArea(mesh, f));
    EXPECT_GE(minArea, 0.5); // the smallest are the half-unit triangles of the face quads
}

TEST(MarchingCubes, ZerosWithSeveralInsideNeighboursGiveDegenerateButClosedMeshes)
{
    // Sphere of radius 3 centred on sample (5, 5, 5): samples at offsets like (2, 2, 1) are
    // exactly on it. Sample (7, 7, 6) has three inside neighbours in the cell below it, whose
    // three crossings all land on it: that cell's triangle has zero area. The policy keeps such
    // triangles, so the mesh must still be a closed oriented sphere, and every zero-area
    // triangle must come from vertices that coincide on a zero sample.
    const glm::dvec3 center(5.0);
    const Sdf sdf = [&](const glm::dvec3& p) { return computeSphereSdf(p - center, 3.0); };
    const plugin::SampledField field = sampleField(glm::ivec3(11), glm::dvec3(0.0), 1.0, sdf);
    const TriangleMesh mesh = extractMesh(field);
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    EXPECT_TRUE(isMeshFinite(mesh));
    EXPECT_GT(computeSignedVolume(mesh), 0.0);

    const auto isZeroSample = [&](const glm::vec3& p) {
        const glm::ivec3 s(glm::round(p));
        return glm::vec3(s) == p && field.at(s.x, s.y, s.z) == 0.0f;
    };
    std::size_t degenerate = 0;
    for (std::size_t f = 0; f < mesh.triangleCount(); ++f) {
        if (computeTriangleArea(mesh, f) > 0.0)
            continue;
        ++degenerate;
        const glm::vec3 a = mesh.positions[mesh.indices[3 * f]];
        const glm::vec3 b = mesh.positions[mesh.indices[3 * f + 1]];
        const glm::vec3 c = mesh.positions[mesh.indices[3 * f + 2]];
        const bool coincide = (a == b && isZeroSample(a)) || (b == c && isZeroSample(b)) ||
                              (a == c && isZeroSample(a));
        EXPECT_TRUE(coincide) << "zero-area triangle " << f << " not explained by a zero sample";
    }
    EXPECT_GT(degenerate, 0u);
}

TEST(MarchingCubes, NanSampleThrowsAndLeavesOutputUntouched)
{
    plugin::SampledField field =
        sampleUnitCube(8, [](const glm::dvec3& p) { return computeSphereSdf(p, 0.5); });
    field.values[field.index(3, 4, 5)] = std::numeric_limits<float>::quiet_NaN();
    config::ParamSet params = config::ParamSet::defaultsOf(MarchingCubes::declareParams());
    MarchingCubes technique(params);
    plugin::IsosurfaceInput input;
    input.field = &field;
    TriangleMesh out;
    out.positions = {glm::vec3(1.0f, 2.0f, 3.0f)};
    out.indices = {0, 0, 0};
    try {
        technique.extract(input, out);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("(3, 4, 5)"), std::string::npos) << error.what();
    }
    EXPECT_EQ(out.positions.size(), 1u);
    EXPECT_EQ(out.indices.size(), 3u);
}

TEST(MarchingCubes, InfiniteSamplesGiveFiniteClosedMeshes)
{
    // +inf is outside, -inf inside. Crossings toward an infinite end land on the finite end;
    // gradients touching infinities fall back to the edge direction.
    const double radius = 0.5;
    plugin::SampledField field =
        sampleUnitCube(16, [&](const glm::dvec3& p) { return computeSphereSdf(p, radius); });
    std::size_t infinities = 0;
    for (int z = 0; z < 16; ++z)
        for (int y = 0; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                const double r = glm::length(field.position(x, y, z));
                float& value = field.values[field.index(x, y, z)];
                if (r > 0.6 || r < 0.3) {
                    value = r > 0.6 ? std::numeric_limits<float>::infinity()
                                    : -std::numeric_limits<float>::infinity();
                    ++infinities;
                }
            }
    ASSERT_GT(infinities, 0u);
    const TriangleMesh mesh = extractMesh(field);
    const Topology t = analyzeTopology(mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    EXPECT_TRUE(isMeshFinite(mesh));
    for (const glm::vec3& normal : mesh.normals)
        EXPECT_NEAR(glm::length(glm::dvec3(normal)), 1.0, 1e-6);

    // One cell, -inf at corner 0 and +inf elsewhere: both ends infinite, vertices at midpoints.
    plugin::SampledField cell;
    cell.samples = glm::ivec3(2);
    cell.values.assign(8, std::numeric_limits<float>::infinity());
    cell.values[0] = -std::numeric_limits<float>::infinity();
    const TriangleMesh corner = extractMesh(cell);
    ASSERT_EQ(corner.vertexCount(), 3u);
    ASSERT_EQ(corner.triangleCount(), 1u);
    std::vector<glm::vec3> sorted = corner.positions;
    std::sort(sorted.begin(), sorted.end(), [](const glm::vec3& a, const glm::vec3& b) {
        return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    });
    EXPECT_EQ(sorted[0], glm::vec3(0.0f, 0.0f, 0.5f));
    EXPECT_EQ(sorted[1], glm::vec3(0.0f, 0.5f, 0.0f));
    EXPECT_EQ(sorted[2], glm::vec3(0.5f, 0.0f, 0.0f));
}

TEST(MarchingCubes, GridsWithoutCellsGiveEmptyMeshes)
{
    for (const glm::ivec3 samples : {glm::ivec3(1, 5, 5), glm::ivec3(5, 0, 5), glm::ivec3(0)}) {
        plugin::SampledField field;
        field.samples = samples;
        field.values.assign(std::size_t(std::max(samples.x * samples.y * samples.z, 0)), -1.0f);
        TriangleMesh out;
        out.positions = {glm::vec3(1.0f)};
        out.normals = {glm::vec3(1.0f)};
        out.indices = {0, 0, 0};
        config::ParamSet params = config::ParamSet::defaultsOf(MarchingCubes::declareParams());
        MarchingCubes technique(params);
        plugin::IsosurfaceInput input;
        input.field = &field;
        technique.extract(input, out);
        EXPECT_TRUE(out.positions.empty());
        EXPECT_TRUE(out.normals.empty());
        EXPECT_TRUE(out.indices.empty());
    }
}

TEST(MarchingCubes, InvalidInputsThrow)
{
    const plugin::SampledField good =
        sampleUnitCube(4, [](const glm::dvec3& p) { return computeSphereSdf(p, 0.5); });
    MarchingCubes technique(config::ParamSet::defaultsOf(MarchingCubes::declareParams()));
    TriangleMesh out;
    plugin::IsosurfaceInput input;
    EXPECT_THROW(technique.extract(input, out), std::invalid_argument); // null field

    input.field = &good;
    input.isoValue = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(technique.extract(input, out), std::invalid_argument);
    input.isoValue = std::numeric_limits<double>::infinity();
    EXPECT_THROW(technique.extract(input, out), std::invalid_argument);

    input.isoValue = 0.0;
    plugin::SampledField shortField = good;
    shortField.values.pop_back();
    input.field = &shortField;
    EXPECT_THROW(technique.extract(input, out), std::invalid_argument);

    plugin::SampledField zeroSpacing = good;
    zeroSpacing.spacing = 0.0;
    input.field = &zeroSpacing;
    EXPECT_THROW(technique.extract(input, out), std::invalid_argument);
}

TEST(MarchingCubes, IsoValueShiftsTheSurface)
{
    // Extracting f = 0.2 from the SDF of a sphere of radius 0.5 is the sphere of radius 0.7.
    const TriangleMesh shifted = extractMesh(
        sampleUnitCube(32, [](const glm::dvec3& p) { return computeSphereSdf(p, 0.5); }), {}, 0.2);
    const TriangleMesh direct = extractMesh(
        sampleUnitCube(32, [](const glm::dvec3& p) { return computeSphereSdf(p, 0.7); }));
    EXPECT_EQ(shifted.indices, direct.indices);
    ASSERT_EQ(shifted.vertexCount(), direct.vertexCount());
    double maxDistance = 0.0;
    for (std::size_t i = 0; i < shifted.vertexCount(); ++i)
        maxDistance =
            std::max(maxDistance, double(glm::length(shifted.positions[i] - direct.positions[i])));
    // The two fields differ only by float rounding of the samples.
    EXPECT_LE(maxDistance, kRounding);
}

TEST(MarchingCubes, NormalsCanBeTurnedOff)
{
    const plugin::SampledField field =
        sampleUnitCube(16, [](const glm::dvec3& p) { return computeSphereSdf(p, 0.5); });
    const TriangleMesh with = extractMesh(field);
    const TriangleMesh without = extractMesh(field, {{"normals", std::string("none")}});
    EXPECT_EQ(with.normals.size(), with.positions.size());
    EXPECT_TRUE(without.normals.empty());
    EXPECT_EQ(without.positions, with.positions);
    EXPECT_EQ(without.indices, with.indices);
}

// ---------------------------------------------------------------------------------------------
// Registration and parameters

TEST(MarchingCubes, RegistersWithItsSchema)
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    rtlabRegisterTechnique_isosurface_marching_cubes(registry);
    const plugin::TechniqueEntry* entry = registry.findTechnique("isosurface", "marching_cubes");
    ASSERT_NE(entry, nullptr);
    EXPECT_EQ(entry->info.family, "isosurface");
    EXPECT_EQ(entry->info.name, "marching_cubes");
    EXPECT_NE(entry->info.reference.find("Lorensen"), std::string::npos);
    EXPECT_NE(entry->info.seed.find("000_3da000e866ebc485.txt"), std::string::npos);
    EXPECT_EQ(entry->schema.names(), MarchingCubes::declareParams().names());
    EXPECT_EQ(entry->schema.names(),
              (std::vector<std::string>{"grain", "vertex_placement", "ambiguity", "normals"}));
    for (const config::ParamSpec& spec : entry->schema.specs())
        EXPECT_FALSE(spec.doc.empty()) << spec.name;
    EXPECT_EQ(entry->schema.find("grain")->unit, "cells");
    EXPECT_EQ(entry->schema.find("grain")->min, 1.0);
    EXPECT_EQ(entry->schema.find("grain")->max, 1024.0);

    const std::unique_ptr<plugin::Technique> technique =
        entry->create(config::ParamSet::defaultsOf(entry->schema));
    auto* isosurface = dynamic_cast<plugin::IsosurfaceTechnique*>(technique.get());
    ASSERT_NE(isosurface, nullptr);
    const plugin::SampledField field =
        sampleUnitCube(12, [](const glm::dvec3& p) { return computeSphereSdf(p, 0.5); });
    plugin::IsosurfaceInput input;
    input.field = &field;
    TriangleMesh mesh;
    isosurface->extract(input, mesh);
    EXPECT_GT(mesh.triangleCount(), 0u);
}

TEST(MarchingCubes, EffectiveParamsReportEveryDeclaredParameter)
{
    const config::ParamSchema schema = MarchingCubes::declareParams();
    config::ParamSet params = config::ParamSet::defaultsOf(schema);
    EXPECT_EQ(MarchingCubes(params).effectiveParams(), params);

    params.set("grain", std::int64_t(3));
    params.set("vertex_placement", std::string("midpoint"));
    params.set("ambiguity", std::string("join_inside"));
    params.set("normals", std::string("none"));
    const config::ParamSet effective = MarchingCubes(params).effectiveParams();
    EXPECT_EQ(effective, params);
    EXPECT_EQ(effective.values().size(), schema.specs().size());
    for (const config::ParamSpec& spec : schema.specs()) {
        ASSERT_TRUE(effective.has(spec.name)) << spec.name;
        EXPECT_EQ(spec.checkValue(effective.get(spec.name)), "") << spec.name;
    }

    params.set("ambiguity", std::string("coin_flip"));
    EXPECT_THROW(MarchingCubes{params}, std::invalid_argument);
}

} // namespace
} // namespace rtlab::isosurface
