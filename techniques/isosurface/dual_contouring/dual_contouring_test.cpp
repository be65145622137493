#include "dual_contouring.h"

#include "extraction.h"
#include "isosurface/case_table.h"
#include "isosurface_test_support.h"
#include "plugin/technique.h"
#include "qef.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

// Defined by RTLAB_REGISTER_TECHNIQUE at the bottom of dual_contouring.cpp.
void rtlabRegisterTechnique_isosurface_dual_contouring(rtlab::plugin::Registry& registry);

namespace rtlab::isosurface {
namespace {

using namespace test;
using Overrides = ParamOverrides;
using dc::QefSystem;

//! A signed distance function with its gradient, written here so the tests do not depend on the
//! framework's SDF evaluator.
struct Sdf {
    std::function<double(const glm::dvec3&)> value;
    std::function<glm::dvec3(const glm::dvec3&)> gradient;
};

Sdf makeSphere(glm::dvec3 center, double radius)
{
    return {[=](const glm::dvec3& p) { return glm::length(p - center) - radius; },
            [=](const glm::dvec3& p) {
                const glm::dvec3 d = p - center;
                const double l = glm::length(d);
                return l > 0.0 ? d / l : glm::dvec3(0.0, 0.0, 1.0);
            }};
}

//! Rotation by angles about x, then y, then z.
glm::dmat3 makeRotation(double ax, double ay, double az)
{
    const glm::dmat3 rx(1, 0, 0, 0, std::cos(ax), std::sin(ax), 0, -std::sin(ax), std::cos(ax));
    const glm::dmat3 ry(std::cos(ay), 0, -std::sin(ay), 0, 1, 0, std::sin(ay), 0, std::cos(ay));
    const glm::dmat3 rz(std::cos(az), std::sin(az), 0, -std::sin(az), std::cos(az), 0, 0, 0, 1);
    return rz * ry * rx;
}

//! Box of half extents `half` centred at `center`, rotated by `rotation` (box frame to world).
struct Box {
    glm::dvec3 center{0.0};
    glm::dvec3 half{0.5};
    glm::dmat3 rotation{1.0};

    glm::dvec3 toLocal(const glm::dvec3& p) const
    {
        return glm::transpose(rotation) * (p - center);
    }
    double value(const glm::dvec3& p) const
    {
        const glm::dvec3 q = glm::abs(toLocal(p)) - half;
        return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
    }
    glm::dvec3 gradient(const glm::dvec3& p) const
    {
        const glm::dvec3 local = toLocal(p);
        const glm::dvec3 q = glm::abs(local) - half;
        const glm::dvec3 sign(local.x < 0 ? -1.0 : 1.0, local.y < 0 ? -1.0 : 1.0,
                              local.z < 0 ? -1.0 : 1.0);
        glm::dvec3 g(0.0);
        if (std::max(q.x, std::max(q.y, q.z)) > 0.0) {
            g = glm::normalize(glm::max(q, 0.0)) * sign;
        } else {
            const int k = q.x >= q.y && q.x >= q.z ? 0 : (q.y >= q.z ? 1 : 2);
            g[k] = sign[k];
        }
        return rotation * g;
    }
    Sdf sdf() const
    {
        const Box box = *this;
        return {[box](const glm::dvec3& p) { return box.value(p); },
                [box](const glm::dvec3& p) { return box.gradient(p); }};
    }
    std::array<glm::dvec3, 8> corners() const
    {
        std::array<glm::dvec3, 8> c;
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 s(k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0);
            c[k] = center + rotation * (s * half);
        }
        return c;
    }
    //! Distance from p to the plane of face (axis, side), in world units.
    double distanceToFacePlane(const glm::dvec3& p, int axis, int side) const
    {
        const double coordinate = toLocal(p)[axis];
        return std::abs(coordinate - (side ? half[axis] : -half[axis]));
    }
};

//! Torus around the z axis.
Sdf makeTorus(double major, double minor)
{
    return {[=](const glm::dvec3& p) {
                const double ring = std::sqrt(p.x * p.x + p.y * p.y) - major;
                return std::sqrt(ring * ring + p.z * p.z) - minor;
            },
            [=](const glm::dvec3& p) {
                const double rho = std::sqrt(p.x * p.x + p.y * p.y);
                const double ring = rho - major;
                const double l = std::sqrt(ring * ring + p.z * p.z);
                if (!(rho > 0.0) || !(l > 0.0))
                    return glm::dvec3(0.0);
                return glm::dvec3(ring / l * p.x / rho, ring / l * p.y / rho, p.z / l);
            }};
}

//! n^3 samples spanning [-1, 1]^3 (spacing 2 / (n - 1)).
plugin::SampledField sampleUnitCube(int n, const Sdf& sdf)
{
    return test::sampleUnitCube(n, sdf.value);
}

config::ParamSet makeParams(const Overrides& overrides = {})
{
    return test::makeParams<DualContouring>(overrides);
}

struct Extraction {
    TriangleMesh mesh;
    dc::ExtractionStats stats;
    std::map<std::string, double> counters;
};

//! Runs the technique; `sdf` (when given) supplies exactValue and exactGradient.
Extraction extract(const plugin::SampledField& field, const Sdf* sdf,
                   const Overrides& overrides = {},
                   const std::vector<std::uint32_t>* materials = nullptr,
                   const plugin::HermiteData* hermite = nullptr)
{
    DualContouring technique(makeParams(overrides));
    plugin::IsosurfaceInput input;
    input.field = &field;
    if (sdf != nullptr) {
        input.exactValue = sdf->value;
        input.exactGradient = sdf->gradient;
    }
    input.materials = materials;
    input.hermite = hermite;
    Extraction result;
    technique.extract(input, result.mesh);
    result.stats = technique.stats();
    for (const auto& [name, value] : technique.counters())
        result.counters[name] = value;
    return result;
}

//! Watertight in the weaker sense that holds at non-manifold edges too: every directed edge is
//! matched by as many reverse uses.
void expectWatertight(const Topology& t)
{
    EXPECT_EQ(t.badIndices, 0u);
    EXPECT_EQ(t.unbalancedEdges, 0u) << "holes or inconsistent orientation";
    EXPECT_EQ(t.unreferencedVertices, 0u);
}

//! Vertices whose triangles do not form one closed fan (a single cycle of opposite edges): the
//! vertex-manifold condition that edge-manifoldness alone does not imply.
std::size_t countNonManifoldVertices(const TriangleMesh& mesh)
{
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> link(mesh.vertexCount());
    for (std::size_t f = 0; f < mesh.triangleCount(); ++f) {
        const std::uint32_t v[3] = {mesh.indices[3 * f], mesh.indices[3 * f + 1],
                                    mesh.indices[3 * f + 2]};
        for (int k = 0; k < 3; ++k)
            link[v[k]].push_back({v[(k + 1) % 3], v[(k + 2) % 3]});
    }
    std::size_t bad = 0;
    for (const auto& fan : link) {
        if (fan.empty())
            continue;
        std::unordered_map<std::uint32_t, std::uint32_t> next;
        bool ok = true;
        for (const auto& [a, b] : fan)
            ok = next.emplace(a, b).second && ok;
        std::size_t steps = 0;
        std::uint32_t at = fan.front().first;
        do {
            const auto it = next.find(at);
            if (it == next.end()) {
                ok = false;
                break;
            }
            at = it->second;
            ++steps;
        } while (at != fan.front().first && steps <= fan.size());
        bad += !(ok && steps == fan.size());
    }
    return bad;
}


// ---------------------------------------------------------------------------------------------
// Cubes: sharp features

//! Checks that the mesh of `box` has a vertex on each corner, every vertex on the surface and
//! every triangle in one face plane, all within `tolerance` world units.
void expectSharpBox(const TriangleMesh& mesh, const Box& box, double tolerance)
{
    for (const glm::dvec3& corner : box.corners()) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const glm::vec3& p : mesh.positions)
            nearest = std::min(nearest, glm::length(glm::dvec3(p) - corner));
        EXPECT_LE(nearest, tolerance)
            << "corner " << corner.x << " " << corner.y << " " << corner.z;
    }
    double worstSurface = 0.0;
    for (const glm::vec3& p : mesh.positions)
        worstSurface = std::max(worstSurface, std::abs(box.value(glm::dvec3(p))));
    EXPECT_LE(worstSurface, tolerance);
    // Faces stay planar: each triangle lies in the plane of one face.
    std::size_t offPlane = 0;
    double worstTriangle = 0.0;
    for (std::size_t f = 0; f < mesh.triangleCount(); ++f) {
        double best = std::numeric_limits<double>::infinity();
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                double d = 0.0;
                for (int k = 0; k < 3; ++k)
                    d = std::max(
                        d, box.distanceToFacePlane(
                               glm::dvec3(mesh.positions[mesh.indices[3 * f + k]]), axis, side));
                best = std::min(best, d);
            }
        worstTriangle = std::max(worstTriangle, best);
        offPlane += best > tolerance;
    }
    EXPECT_EQ(offPlane, 0u) << "worst triangle is " << worstTriangle << " off every face plane";
}

TEST(DualContouringCube, AxisAlignedCubeKeepsCornersAndPlanarFaces)
{
    const Box box{glm::dvec3(0.031, -0.017, 0.052), glm::dvec3(0.55), glm::dmat3(1.0)};
    const Sdf sdf = box.sdf();
    const plugin::SampledField field = sampleUnitCube(33, sdf);
    const double h = field.spacing;
    const Extraction r = extract(field, &sdf);
    const Topology t = analyzeTopology(r.mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    EXPECT_TRUE(isMeshFinite(r.mesh));
    expectSharpBox(r.mesh, box, 1e-4 * h);
    EXPECT_EQ(r.counters.at("hermite_source"), 1.0);
    EXPECT_EQ(r.stats.leftCell, 0u);
    EXPECT_EQ(r.stats.rank[3], 8u) << "one corner cell per cube corner";
    EXPECT_NEAR(computeSignedVolume(r.mesh), 8.0 * 0.55 * 0.55 * 0.55, 1e-5);
}

TEST(DualContouringCube, RotatedCubeKeepsCornersAndPlanarFacesWhenVerticesMayLeaveTheirCell)
{
    // Rotated about all three axes. Along a rotated edge the QEF line's point nearest the mass
    // point often lies outside the cell (the line clips a corner of the cell), and a cube corner
    // can sit in a cell with no sign change, so its vertex comes from a neighbouring cell. With
    // outside_policy keep the vertices stay on the features: a vertex on every corner and every
    // triangle in one face plane. The default clamp moves exactly the vertices that left
    // (counter vertices_left_cell) onto their cell boxes, off the features.
    const Box box{glm::dvec3(0.021, -0.013, 0.034), glm::dvec3(0.5),
                  makeRotation(0.41, 0.27, 0.63)};
    const Sdf sdf = box.sdf();
    const plugin::SampledField field = sampleUnitCube(41, sdf);
    const double h = field.spacing;
    const Extraction keep = extract(field, &sdf, {{"outside_policy", std::string("keep")}});
    const Extraction clamp = extract(field, &sdf);
    for (const Extraction* r : {&keep, &clamp}) {
        // Sharp edges crossing a grid face diagonally make ambiguous faces, where plain dual
        // contouring joins four quads on one edge [Ju et al. 2002 produce non-manifold meshes
        // there]: watertight and consistently oriented, not manifold.
        expectWatertight(analyzeTopology(r->mesh));
        EXPECT_TRUE(isMeshFinite(r->mesh));
        EXPECT_GT(r->stats.leftCell, 0u);
        EXPECT_EQ(r->stats.leftCell, keep.stats.leftCell);
    }
    expectSharpBox(keep.mesh, box, 1e-4 * h);
    EXPECT_NEAR(computeSignedVolume(keep.mesh), 1.0, 1e-5);
    EXPECT_NEAR(computeSignedVolume(clamp.mesh), 1.0, 2e-3);
    std::size_t moved = 0;
    for (std::size_t v = 0; v < keep.mesh.vertexCount(); ++v)
        moved += keep.mesh.positions[v] != clamp.mesh.positions[v];
    EXPECT_EQ(moved, keep.stats.leftCell);
}

TEST(DualContouringCube, AxisAlignedCubeFromHermiteDataOfSchmitzSolver)
{
    // The particle solver on the same cube: corners within its convergence error. Corner cells
    // have 3 planes with at least one crossing each among at most 12; the error contracts by
    // (1 - 1/12) per step at worst, so 400 steps reach 1e-15 of a cell.
    const Box box{glm::dvec3(0.031, -0.017, 0.052), glm::dvec3(0.55), glm::dmat3(1.0)};
    const Sdf sdf = box.sdf();
    const plugin::SampledField field = sampleUnitCube(33, sdf);
    const Extraction r =
        extract(field, &sdf,
                {{"solver", std::string("schmitz")}, {"schmitz_iterations", std::int64_t(400)}});
    expectClosedOriented(analyzeTopology(r.mesh));
    expectSharpBox(r.mesh, box, 1e-4 * field.spacing);
    EXPECT_EQ(r.counters.at("qef_solver"), 1.0);
}

TEST(DualContouringCube, SamplesOnlyGiveAWatertightRoundedCube)
{
    // From the samples alone (no exact field) the features soften, but the mesh stays closed.
    const Box box{glm::dvec3(0.031, -0.017, 0.052), glm::dvec3(0.5),
                  makeRotation(0.41, 0.27, 0.63)};
    const Sdf sdf = box.sdf();
    const plugin::SampledField field = sampleUnitCube(33, sdf);
    const Extraction r = extract(field, nullptr);
    EXPECT_EQ(r.counters.at("hermite_source"), 2.0);
    expectWatertight(analyzeTopology(r.mesh));
    EXPECT_TRUE(isMeshFinite(r.mesh));
    double worst = 0.0;
    for (const glm::vec3& p : r.mesh.positions)
        worst = std::max(worst, std::abs(box.value(glm::dvec3(p))));
    EXPECT_LT(worst, 0.5 * field.spacing);
}

// ---------------------------------------------------------------------------------------------
// Smooth closed surfaces

TEST(DualContouringSmooth, SphereIsAClosedManifoldOfGenusZero)
{
    const Sdf sdf = makeSphere(glm::dvec3(0.013, -0.021, 0.008), 0.7);
    for (const int n : {17, 33, 65}) {
        const plugin::SampledField field = sampleUnitCube(n, sdf);
        const double h = field.spacing;
        for (const bool exact : {true, false}) {
            SCOPED_TRACE("n = " + std::to_string(n) + (exact ? " exact" : " samples"));
            const Extraction r = extract(field, exact ? &sdf : nullptr);
            const Topology t = analyzeTopology(r.mesh);
            expectClosedOriented(t);
            EXPECT_EQ(t.euler(), 2);
            EXPECT_TRUE(isMeshFinite(r.mesh));
            double worst = 0.0;
            for (const glm::vec3& p : r.mesh.positions)
                worst = std::max(worst, std::abs(sdf.value(glm::dvec3(p))));
            // Exact Hermite data: tangent planes of a sphere of radius r at points within a cell
            // (sqrt(3) h) of each other meet within about (sqrt(3) h)^2 / (2 r) of the sphere.
            EXPECT_LT(worst, exact ? 3.0 * h * h / (2.0 * 0.7) + 1e-6 : 0.25 * h);
            const double volume = 4.0 / 3.0 * 3.14159265358979 * 0.7 * 0.7 * 0.7;
            EXPECT_NEAR(computeSignedVolume(r.mesh) / volume, 1.0, exact ? 0.02 : 0.05);
            for (const glm::vec3& normal : r.mesh.normals)
                EXPECT_NEAR(glm::length(normal), 1.0f, 1e-5f);
        }
    }
}

TEST(DualContouringSmooth, TorusIsAClosedManifoldOfGenusOne)
{
    const Sdf sdf = makeTorus(0.6, 0.25);
    const plugin::SampledField field = sampleUnitCube(49, sdf);
    for (const bool exact : {true, false}) {
        for (const std::string solver : {"svd", "schmitz"}) {
            SCOPED_TRACE(std::string(exact ? "exact " : "samples ") + solver);
            const Extraction r = extract(field, exact ? &sdf : nullptr, {{"solver", solver}});
            const Topology t = analyzeTopology(r.mesh);
            expectClosedOriented(t);
            EXPECT_EQ(t.euler(), 0);
            EXPECT_TRUE(isMeshFinite(r.mesh));
            EXPECT_GT(computeSignedVolume(r.mesh), 0.0);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// One vertex per surface patch: 2-manifold output

//! The family suite's torus: R 0.55, r 0.2, around the y axis through (0.01, -0.02, 0.03), 40^3
//! samples over [-1, 1]^3.
Sdf makeSuiteTorus()
{
    const glm::dvec3 c(0.01, -0.02, 0.03);
    const auto value = [c](const glm::dvec3& p) { return computeTorusSdf(p, c, 0.55, 0.2); };
    const auto gradient = [value](const glm::dvec3& p) {
        glm::dvec3 g;
        for (int axis = 0; axis < 3; ++axis) {
            glm::dvec3 d(0.0);
            d[axis] = 1e-6;
            g[axis] = (value(p + d) - value(p - d)) / 2e-6;
        }
        return g;
    };
    return {value, gradient};
}

//! Euler characteristic of the marching cubes polygon complex of a field whose surface stays
//! inside the grid (every crossed edge a vertex, every loop a face, every segment an edge shared
//! by the two cells on its face), from the same table and face rule as per_component.
long computeMarchingCubesEuler(const plugin::SampledField& field)
{
    namespace tables = isosurface::tables;
    const tables::CaseTable& table = tables::CaseTable::getInstance();
    const glm::ivec3 n = field.samples;
    long crossed = 0;
    long loops = 0;
    long loopEdges = 0;
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const bool in = field.at(x, y, z) < 0.0f;
                crossed += x + 1 < n.x && in != (field.at(x + 1, y, z) < 0.0f);
                crossed += y + 1 < n.y && in != (field.at(x, y + 1, z) < 0.0f);
                crossed += z + 1 < n.z && in != (field.at(x, y, z + 1) < 0.0f);
                if (x + 1 == n.x || y + 1 == n.y || z + 1 == n.z)
                    continue;
                unsigned cube = 0;
                std::array<double, 8> values;
                for (int c = 0; c < 8; ++c) {
                    values[c] = field.at(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1));
                    cube |= unsigned(values[c] < 0.0) << c;
                }
                const tables::CellTriangulation& entry = table.findJoined(
                    cube,
                    tables::decideJoinedFaces(cube, values, tables::AmbiguityRule::Asymptotic));
                loops += entry.loopCount;
                for (int l = 0; l < entry.loopCount; ++l)
                    loopEdges += std::popcount(unsigned(entry.loops[l]));
            }
    return crossed - loopEdges / 2 + loops;
}

//! Closed, consistently oriented, edge- and vertex-manifold, and outward.
void expectClosedTwoManifold(const TriangleMesh& mesh)
{
    expectClosedOriented(analyzeTopology(mesh));
    EXPECT_EQ(countNonManifoldVertices(mesh), 0u);
    EXPECT_TRUE(isMeshFinite(mesh));
    EXPECT_GT(computeSignedVolume(mesh), 0.0);
}

TEST(DualContouringManifold, SuiteTorusIsATwoManifoldPerComponentButNotPerCell)
{
    const Sdf sdf = makeSuiteTorus();
    const plugin::SampledField field = sampleUnitCube(40, sdf);
    for (const bool exact : {true, false}) {
        SCOPED_TRACE(exact ? "exact" : "samples");
        const Extraction r = extract(field, exact ? &sdf : nullptr);
        expectClosedTwoManifold(r.mesh);
        EXPECT_EQ(analyzeTopology(r.mesh).euler(), 0);
        EXPECT_GT(r.stats.multiVertexCells, 0u) << "cells holding two sheets get two vertices";
        EXPECT_EQ(r.stats.vertices, r.mesh.vertexCount());
        EXPECT_EQ(r.stats.patchVertices + r.stats.faceVertices, r.stats.vertices);

        // Classic dual contouring joins the two sheets of such cells at one vertex.
        const Extraction classic =
            extract(field, exact ? &sdf : nullptr, {{"vertices", std::string("per_cell")}});
        const Topology t = analyzeTopology(classic.mesh);
        expectWatertight(t);
        EXPECT_GT(t.nonManifoldEdges, 0u);
        EXPECT_EQ(classic.stats.multiVertexCells, 0u);
        EXPECT_EQ(classic.stats.vertices, classic.stats.cells);
        EXPECT_EQ(classic.stats.cells, r.stats.cells);
    }
}

TEST(DualContouringManifold, RingAroundACheckerboardFaceIsATorusWithFaceVertices)
{
    // Eight inside samples form a ring through two cells stacked along z; their shared face has
    // inside corners on one diagonal (-1) and outside ones on the other (+2), so the asymptotic
    // decider connects the outside corners across it, and in both cells one patch crosses that
    // face twice: the surface is a tube through the face.
    plugin::SampledField field;
    field.samples = glm::ivec3(4, 4, 5);
    field.spacing = 0.5;
    field.values.assign(4 * 4 * 5, 1.0f);
    for (const glm::ivec3 s :
         {glm::ivec3(1, 1, 1), glm::ivec3(2, 1, 1), glm::ivec3(2, 2, 1), glm::ivec3(1, 1, 2),
          glm::ivec3(2, 2, 2), glm::ivec3(1, 1, 3), glm::ivec3(2, 1, 3), glm::ivec3(2, 2, 3)})
        field.values[field.index(s.x, s.y, s.z)] = -1.0f;
    field.values[field.index(2, 1, 2)] = 2.0f;
    field.values[field.index(1, 2, 2)] = 2.0f;

    const Extraction r = extract(field, nullptr);
    expectClosedTwoManifold(r.mesh);
    EXPECT_EQ(analyzeTopology(r.mesh).euler(), 0) << "a tube closed into a torus";
    EXPECT_EQ(analyzeTopology(r.mesh).euler(), computeMarchingCubesEuler(field));
    EXPECT_EQ(r.stats.faceVertices, 2u) << "one per segment of the shared face";
    EXPECT_EQ(r.counters.at("face_vertices"), 2.0);
    // Each face vertex is the midpoint of its segment's two crossings on the shared face
    // (z = 2 samples). The segments cut off the inside corners: around (1, 1) the crossings are
    // at (1 + 1/3, 1) and (1, 1 + 1/3) samples, around (2, 2) at (2 - 1/3, 2) and (2, 2 - 1/3).
    for (const glm::dvec3 expected :
         {glm::dvec3(7.0 / 6.0, 7.0 / 6.0, 2.0), glm::dvec3(11.0 / 6.0, 11.0 / 6.0, 2.0)}) {
        const glm::vec3 world(expected * field.spacing);
        const bool found =
            std::any_of(r.mesh.positions.begin(), r.mesh.positions.end(),
                        [&](const glm::vec3& p) { return glm::length(p - world) < 1e-6f; });
        EXPECT_TRUE(found) << "face vertex at " << world.x << ", " << world.y << ", " << world.z;
    }

    const Topology classic =
        analyzeTopology(extract(field, nullptr, {{"vertices", std::string("per_cell")}}).mesh);
    expectWatertight(classic);
    EXPECT_GT(classic.nonManifoldEdges, 0u);
}

TEST(DualContouringManifold, RandomFieldsAreClosedTwoManifoldsPerComponent)
{
    // Random values on 12^3 samples with an outside border, so every surface is closed: most
    // cells are ambiguous somewhere. Quantised fields add ties in the asymptotic decider.
    std::size_t multiVertexCells = 0;
    std::size_t faceVertices = 0;
    for (int seed = 0; seed < 20; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        std::mt19937 rng(std::uint32_t(1000 + seed));
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        std::uniform_int_distribution<int> q(-2, 2);
        plugin::SampledField field;
        field.samples = glm::ivec3(12);
        field.spacing = 1.0 / 11.0;
        field.values.resize(12 * 12 * 12);
        const bool quantised = seed % 4 == 3;
        for (int z = 0; z < 12; ++z)
            for (int y = 0; y < 12; ++y)
                for (int x = 0; x < 12; ++x) {
                    const bool border = x == 0 || y == 0 || z == 0 || x == 11 || y == 11 || z == 11;
                    const double value = quantised ? double(q(rng)) : u(rng);
                    field.values[field.index(x, y, z)] = border ? 1.0f : float(value);
                }
        const Extraction r = extract(field, nullptr);
        expectClosedTwoManifold(r.mesh);
        EXPECT_EQ(analyzeTopology(r.mesh).euler(), computeMarchingCubesEuler(field));
        EXPECT_EQ(r.stats.vertices, r.mesh.vertexCount());
        multiVertexCells += r.stats.multiVertexCells;
        faceVertices += r.stats.faceVertices;
    }
    EXPECT_GT(multiVertexCells, 0u);
    EXPECT_GT(faceVertices, 0u) << "random fields exercise tunnels through faces";
}

TEST(DualContouringManifold, EveryTableEntryGivesEachCrossedEdgeOnePatch)
{
    namespace tables = isosurface::tables;
    const tables::CaseTable& table = tables::CaseTable::getInstance();
    for (std::size_t i = 0; i < table.entryCount(); ++i) {
        const tables::CellTriangulation& entry = table.entry(i);
        unsigned all = 0;
        for (int l = 0; l < entry.loopCount; ++l) {
            EXPECT_EQ(all & entry.loops[l], 0u) << "loops share no edge";
            all |= entry.loops[l];
            EXPECT_GE(std::popcount(unsigned(entry.loops[l])), 3);
        }
        for (int e = 0; e < tables::kEdgeCount; ++e)
            EXPECT_EQ(entry.edgeLoop[e] >= 0, ((all >> e) & 1u) != 0);
    }
}

// ---------------------------------------------------------------------------------------------
// Degenerate placements and scales

TEST(DualContouringDegenerate, FacesOnGridPlanesAndExactZeroSamples)
{
    // h = 1/16: the box faces x, y, z = +-0.5 and +-0.25 are sample planes, so samples on them are
    // exactly 0 (outside), and every crossing on those planes lands exactly on a sample.
    const Box box{glm::dvec3(0.0), glm::dvec3(0.5, 0.25, 0.5), glm::dmat3(1.0)};
    const Sdf boxSdf = box.sdf();
    const Sdf sphere = makeSphere(glm::dvec3(0.0), 0.5); // exact zeros at (+-0.5, 0, 0) etc.
    for (const Sdf* sdf : {&boxSdf, &sphere}) {
        const plugin::SampledField field = sampleUnitCube(33, *sdf);
        std::size_t zeros = 0;
        for (float v : field.values)
            zeros += v == 0.0f;
        ASSERT_GT(zeros, 0u);
        for (const bool exact : {true, false}) {
            for (const std::string policy : {"clamp", "mass_point", "keep"}) {
                SCOPED_TRACE(std::string(exact ? "exact " : "samples ") + policy);
                const Extraction r =
                    extract(field, exact ? sdf : nullptr, {{"outside_policy", policy}});
                const Topology t = analyzeTopology(r.mesh);
                expectClosedOriented(t);
                EXPECT_EQ(t.euler(), 2);
                EXPECT_TRUE(isMeshFinite(r.mesh));
            }
        }
    }
    // The box's vertices lie on its faces exactly (to rounding): corners on corners.
    const plugin::SampledField field = sampleUnitCube(33, boxSdf);
    const Extraction r = extract(field, &boxSdf);
    expectSharpBox(r.mesh, box, 1e-6 * field.spacing);
}

TEST(DualContouringDegenerate, TinyAndHugeScalesGiveTheSameMesh)
{
    // The mesher works in grid units, so scaling and moving the field scales and moves the mesh.
    const auto make = [](double scale, glm::dvec3 offset) {
        Sdf unit = makeSphere(glm::dvec3(0.013, -0.021, 0.008), 0.7);
        Sdf scaled;
        scaled.value = [=](const glm::dvec3& p) {
            return scale * unit.value((p - offset) / scale);
        };
        scaled.gradient = [=](const glm::dvec3& p) { return unit.gradient((p - offset) / scale); };
        return scaled;
    };
    const int n = 25;
    const Sdf unitSdf = make(1.0, glm::dvec3(0.0));
    const plugin::SampledField unitField = sampleUnitCube(n, unitSdf);
    const Extraction reference = extract(unitField, &unitSdf);
    struct Case {
        double scale;
        glm::dvec3 offset;
    };
    for (const Case c :
         {Case{1e-4, glm::dvec3(0.0)}, Case{1e4, glm::dvec3(1e6)}, Case{1e-4, glm::dvec3(3.0)}}) {
        SCOPED_TRACE("scale " + std::to_string(c.scale));
        const Sdf sdf = make(c.scale, c.offset);
        const plugin::SampledField field = sampleField(
            glm::ivec3(n), c.offset - glm::dvec3(c.scale), 2.0 * c.scale / (n - 1), sdf.value);
        for (const bool exact : {true, false}) {
            const Extraction r = extract(field, exact ? &sdf : nullptr);
            EXPECT_TRUE(isMeshFinite(r.mesh));
            const Topology t = analyzeTopology(r.mesh);
            expectClosedOriented(t);
            EXPECT_EQ(t.euler(), 2);
            if (!exact)
                continue;
            ASSERT_EQ(r.mesh.vertexCount(), reference.mesh.vertexCount());
            EXPECT_EQ(r.mesh.indices, reference.mesh.indices);
            // float output: relative rounding 2^-24 of |position| (up to 1e6 + 1e4 here).
            const double rounding = 1e-7 * (glm::length(c.offset) + 2.0 * c.scale);
            double worst = 0.0;
            for (std::size_t v = 0; v < r.mesh.vertexCount(); ++v) {
                const glm::dvec3 expected =
                    c.offset + c.scale * glm::dvec3(reference.mesh.positions[v]);
                worst = std::max(worst, glm::length(glm::dvec3(r.mesh.positions[v]) - expected));
            }
            EXPECT_LE(worst, rounding + 1e-6 * c.scale);
        }
    }
}

TEST(DualContouringDegenerate, FeaturesThinnerThanACellStayFinite)
{
    // A plate 0.4 cells thick holding one sample layer, a rod of radius 0.3 cells, and a plate
    // between sample layers (invisible to the samples): finite vertices, no NaN, watertight
    // (directed edges balanced; thin features may legitimately give non-manifold edges).
    const double h = 2.0 / 32.0;
    const Box plate{glm::dvec3(0.01, -0.02, 0.0), glm::dvec3(0.6, 0.5, 0.2 * h), glm::dmat3(1.0)};
    const Box rotatedPlate{glm::dvec3(0.0), glm::dvec3(0.6, 0.5, 0.3 * h),
                           makeRotation(0.3, 0.5, 0.2)};
    const Box hidden{glm::dvec3(0.0, 0.0, 0.5 * h), glm::dvec3(0.6, 0.5, 0.2 * h), glm::dmat3(1.0)};
    const Sdf rod = {
        [=](const glm::dvec3& p) {
            return std::max(std::sqrt(p.y * p.y + p.z * p.z) - 0.3 * h, std::abs(p.x) - 0.6);
        },
        [=](const glm::dvec3& p) {
            const double radial = std::sqrt(p.y * p.y + p.z * p.z);
            if (radial - 0.3 * h > std::abs(p.x) - 0.6)
                return radial > 0.0 ? glm::dvec3(0.0, p.y / radial, p.z / radial) : glm::dvec3(0.0);
            return glm::dvec3(p.x < 0.0 ? -1.0 : 1.0, 0.0, 0.0);
        }};
    const std::vector<Sdf> shapes = {plate.sdf(), rotatedPlate.sdf(), hidden.sdf(), rod};
    for (std::size_t i = 0; i < shapes.size(); ++i) {
        const plugin::SampledField field = sampleUnitCube(33, shapes[i]);
        for (const bool exact : {true, false}) {
            for (const std::string solver : {"svd", "schmitz"}) {
                SCOPED_TRACE("shape " + std::to_string(i) + (exact ? " exact " : " samples ") +
                             solver);
                const Extraction r =
                    extract(field, exact ? &shapes[i] : nullptr, {{"solver", solver}});
                EXPECT_TRUE(isMeshFinite(r.mesh));
                expectWatertight(analyzeTopology(r.mesh));
                if (i != 2) {
                    EXPECT_GT(r.mesh.triangleCount(), 0u);
                }
            }
        }
    }
}

TEST(DualContouringDegenerate, InvalidInputsThrowAndEmptyGridsGiveEmptyMeshes)
{
    const Sdf sdf = makeSphere(glm::dvec3(0.0), 0.5);
    plugin::SampledField field = sampleUnitCube(9, sdf);
    DualContouring technique(makeParams());
    plugin::IsosurfaceInput input;
    TriangleMesh mesh;
    mesh.positions.push_back(glm::vec3(1.0f));
    EXPECT_THROW(technique.extract(input, mesh), std::invalid_argument);
    input.field = &field;
    field.values[field.index(4, 4, 4)] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(technique.extract(input, mesh), std::invalid_argument);
    EXPECT_EQ(mesh.positions.size(), 1u) << "out untouched on error";
    field.values[field.index(4, 4, 4)] = -0.5f;
    const std::vector<std::uint32_t> wrongMaterials(3, 0);
    input.materials = &wrongMaterials;
    EXPECT_THROW(technique.extract(input, mesh), std::invalid_argument);
    input.materials = nullptr;
    input.isoValue = std::numeric_limits<double>::infinity();
    EXPECT_THROW(technique.extract(input, mesh), std::invalid_argument);
    input.isoValue = 0.0;
    // Infinite samples are valid: +inf outside, -inf inside.
    field.values[field.index(0, 0, 0)] = std::numeric_limits<float>::infinity();
    field.values[field.index(4, 4, 4)] = -std::numeric_limits<float>::infinity();
    technique.extract(input, mesh);
    EXPECT_TRUE(isMeshFinite(mesh));
    EXPECT_GT(mesh.triangleCount(), 0u);

    plugin::SampledField flat = sampleField(glm::ivec3(5, 5, 1), glm::dvec3(0.0), 1.0, sdf.value);
    input.field = &flat;
    technique.extract(input, mesh);
    EXPECT_EQ(mesh.vertexCount(), 0u);
    EXPECT_EQ(mesh.triangleCount(), 0u);
}

// ---------------------------------------------------------------------------------------------
// Hermite sources, outside policy, splitting, threads

plugin::HermiteData makeHermite(const plugin::SampledField& field, const Sdf& sdf)
{
    // Crossings located by dense bisection, as an evaluator would report them.
    plugin::HermiteData hermite;
    hermite.samples = field.samples;
    hermite.precision = 1e-9 * field.spacing;
    for (int z = 0; z < field.samples.z; ++z)
        for (int y = 0; y < field.samples.y; ++y)
            for (int x = 0; x < field.samples.x; ++x)
                for (int axis = 0; axis < 3; ++axis) {
                    glm::ivec3 s(x, y, z);
                    glm::ivec3 e(0);
                    e[axis] = 1;
                    if (s[axis] + 1 >= field.samples[axis])
                        continue;
                    const bool a = field.at(x, y, z) < 0.0f;
                    const bool b = field.at(x + e.x, y + e.y, z + e.z) < 0.0f;
                    if (a == b)
                        continue;
                    double lo = 0.0;
                    double hi = 1.0;
                    for (int k = 0; k < 40; ++k) {
                        const double mid = 0.5 * (lo + hi);
                        const bool in = sdf.value(field.position(x, y, z) +
                                                  mid * field.spacing * glm::dvec3(e)) < 0.0;
                        (in == a ? lo : hi) = mid;
                    }
                    plugin::HermiteEdge edge;
                    edge.sample = s;
                    edge.axis = axis;
                    edge.t = 0.5 * (lo + hi);
                    edge.normal = sdf.gradient(field.position(x, y, z) +
                                               edge.t * field.spacing * glm::dvec3(e));
                    hermite.edges.push_back(edge);
                }
    hermite.sort();
    return hermite;
}

TEST(DualContouringSources, HermiteDataComesFirstThenTheExactFieldThenTheSamples)
{
    const Box box{glm::dvec3(0.031, -0.017, 0.052), glm::dvec3(0.5),
                  makeRotation(0.41, 0.27, 0.63)};
    const Sdf sdf = box.sdf();
    const plugin::SampledField field = sampleUnitCube(25, sdf);
    plugin::HermiteData hermite = makeHermite(field, sdf);
    const Overrides keep = {{"outside_policy", std::string("keep")}};
    const Extraction fromHermite = extract(field, nullptr, keep, nullptr, &hermite);
    EXPECT_EQ(fromHermite.counters.at("hermite_source"), 0.0);
    EXPECT_EQ(fromHermite.counters.at("hermite_edges_missing"), 0.0);
    expectSharpBox(fromHermite.mesh, box, 1e-4 * field.spacing);

    const Extraction fromExact = extract(field, &sdf, keep);
    EXPECT_EQ(fromExact.counters.at("hermite_source"), 1.0);
    // Same cells and quads; the positions differ by the crossings' precision, which may tip a
    // quad split that is a near-tie (planar quads), so only the counts are compared.
    ASSERT_EQ(fromExact.mesh.vertexCount(), fromHermite.mesh.vertexCount());
    EXPECT_EQ(fromExact.mesh.triangleCount(), fromHermite.mesh.triangleCount());
    for (std::size_t v = 0; v < fromExact.mesh.vertexCount(); ++v)
        EXPECT_LT(glm::length(fromExact.mesh.positions[v] - fromHermite.mesh.positions[v]),
                  1e-4 * field.spacing);

    EXPECT_EQ(extract(field, nullptr).counters.at("hermite_source"), 2.0);
    EXPECT_EQ(
        extract(field, &sdf, {{"hermite", std::string("samples")}}).counters.at("hermite_source"),
        2.0);

    // Edges the Hermite data lacks take the next source (here the exact field).
    const std::size_t total = hermite.edges.size();
    hermite.edges.erase(hermite.edges.begin() + 10, hermite.edges.begin() + 30);
    const Extraction partial = extract(field, &sdf, keep, nullptr, &hermite);
    EXPECT_EQ(partial.counters.at("hermite_source"), 0.0);
    EXPECT_EQ(partial.counters.at("hermite_edges_missing"), 20.0);
    EXPECT_EQ(partial.counters.at("crossed_edges"), double(total));
    expectSharpBox(partial.mesh, box, 1e-4 * field.spacing);
}

TEST(DualContouringPolicy, OutsidePolicyActsOnExactlyTheVerticesThatLeftTheirCell)
{
    // A thin rotated slab gives cells whose QEF minimiser lies outside them.
    const Box slab{glm::dvec3(0.01, 0.02, 0.0), glm::dvec3(0.6, 0.5, 0.08),
                   makeRotation(0.35, 0.6, 0.1)};
    const Sdf sdf = slab.sdf();
    const plugin::SampledField field = sampleUnitCube(33, sdf);
    const Extraction keep = extract(field, &sdf, {{"outside_policy", std::string("keep")}});
    const Extraction clamp = extract(field, &sdf, {{"outside_policy", std::string("clamp")}});
    const Extraction mass = extract(field, &sdf, {{"outside_policy", std::string("mass_point")}});
    const std::size_t left = keep.stats.leftCell;
    ASSERT_GT(left, 0u);
    EXPECT_EQ(clamp.stats.leftCell, left);
    EXPECT_EQ(mass.stats.leftCell, left);
    EXPECT_DOUBLE_EQ(keep.counters.at("vertices_left_cell_share"),
                     double(left) / keep.mesh.vertexCount());
    ASSERT_EQ(keep.mesh.vertexCount(), clamp.mesh.vertexCount());
    std::size_t moved = 0;
    std::size_t movedByMass = 0;
    for (std::size_t v = 0; v < keep.mesh.vertexCount(); ++v) {
        moved += keep.mesh.positions[v] != clamp.mesh.positions[v];
        movedByMass += keep.mesh.positions[v] != mass.mesh.positions[v];
    }
    EXPECT_EQ(moved, left);
    EXPECT_EQ(movedByMass, left);
    for (const Extraction* r : {&keep, &clamp, &mass}) {
        EXPECT_TRUE(isMeshFinite(r->mesh));
        expectWatertight(analyzeTopology(r->mesh));
    }
}

TEST(DualContouringSplit, QuadsSplitAlongTheDiagonalWhoseNormalsAgree)
{
    // Each quad's two triangles: the chosen split's normals agree at least as well as the other.
    const Sdf sdf = makeTorus(0.6, 0.25);
    const plugin::SampledField field = sampleUnitCube(25, sdf);
    const Extraction r = extract(field, &sdf);
    const auto normal = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        const glm::dvec3 pa = r.mesh.positions[a];
        const glm::dvec3 n =
            glm::cross(glm::dvec3(r.mesh.positions[b]) - pa, glm::dvec3(r.mesh.positions[c]) - pa);
        const double l = glm::length(n);
        return l > 0.0 ? n / l : glm::dvec3(0.0);
    };
    ASSERT_EQ(r.mesh.triangleCount() % 2, 0u);
    for (std::size_t q = 0; q < r.mesh.triangleCount() / 2; ++q) {
        const std::uint32_t* t = &r.mesh.indices[6 * q];
        // Recover the quad cycle: the shared diagonal is the pair in both triangles.
        std::array<std::uint32_t, 4> cycle;
        if (t[0] == t[3] && t[2] == t[4])
            cycle = {t[0], t[1], t[2], t[5]}; // diagonal 0-2: (0,1,2), (0,2,3)
        else
            cycle = {t[0], t[1], t[4], t[2]}; // diagonal 1-3: (0,1,3), (1,2,3)
        const double chosen = glm::dot(normal(t[0], t[1], t[2]), normal(t[3], t[4], t[5]));
        const bool diagonal02 = t[0] == t[3];
        const double other = diagonal02 ? glm::dot(normal(cycle[0], cycle[1], cycle[3]),
                                                   normal(cycle[1], cycle[2], cycle[3]))
                                        : glm::dot(normal(cycle[0], cycle[1], cycle[2]),
                                                   normal(cycle[0], cycle[2], cycle[3]));
        EXPECT_GE(chosen, other - 1e-6) << "quad " << q;
    }
}

TEST(DualContouringThreads, OutputDoesNotDependOnTheThreadCount)
{
    const Sdf sdf = makeTorus(0.55, 0.3);
    const plugin::SampledField field = sampleUnitCube(41, sdf);
    std::vector<std::uint32_t> materials(field.values.size());
    for (std::size_t i = 0; i < materials.size(); ++i)
        materials[i] = field.position(int(i % 41), int(i / 41 % 41), int(i / (41 * 41))).x > 0.1;
    const std::vector<Overrides> variants = {
        {},
        {{"vertices", std::string("per_cell")}},
        {{"solver", std::string("schmitz")}},
        {{"material_relaxation_iterations", std::int64_t(5)}},
    };
    for (const Overrides& overrides : variants) {
        for (const bool exact : {true, false}) {
            Extraction one;
            Extraction many;
            tbb::task_arena(1).execute(
                [&] { one = extract(field, exact ? &sdf : nullptr, overrides, &materials); });
            tbb::task_arena(8).execute(
                [&] { many = extract(field, exact ? &sdf : nullptr, overrides, &materials); });
            EXPECT_EQ(one.mesh.positions, many.mesh.positions);
            EXPECT_EQ(one.mesh.normals, many.mesh.normals);
            EXPECT_EQ(one.mesh.indices, many.mesh.indices);
            EXPECT_EQ(one.counters, many.counters);
            EXPECT_TRUE(isMeshFinite(one.mesh));
        }
    }
}

TEST(DualContouringThreads, PatchAndFaceVerticesDoNotDependOnTheThreadCount)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    plugin::SampledField field;
    field.samples = glm::ivec3(24, 20, 22);
    field.spacing = 0.1;
    field.values.resize(24 * 20 * 22);
    for (float& value : field.values)
        value = float(u(rng));
    std::vector<std::uint32_t> materials(field.values.size());
    for (std::size_t i = 0; i < materials.size(); ++i)
        materials[i] = std::uint32_t(i % 24 > 11);
    for (const Overrides& overrides :
         {Overrides{}, Overrides{{"material_relaxation_iterations", std::int64_t(3)}}}) {
        Extraction one;
        Extraction many;
        tbb::task_arena(1).execute([&] { one = extract(field, nullptr, overrides, &materials); });
        tbb::task_arena(8).execute([&] { many = extract(field, nullptr, overrides, &materials); });
        EXPECT_GT(one.stats.faceVertices, 0u);
        EXPECT_GT(one.stats.multiVertexCells, 0u);
        EXPECT_EQ(one.mesh.positions, many.mesh.positions);
        EXPECT_EQ(one.mesh.normals, many.mesh.normals);
        EXPECT_EQ(one.mesh.indices, many.mesh.indices);
        EXPECT_EQ(one.counters, many.counters);
        EXPECT_TRUE(isMeshFinite(one.mesh));
    }
}

// ---------------------------------------------------------------------------------------------
// Material relaxation

TEST(DualContouringMaterials, RelaxationStraightensTheMaterialStaircaseOnTheSurface)
{
    // Ground plane z = z0 between sample layers; the material below it changes across the line
    // x + 0.5 y = c, so quads take a staircase of materials. Relaxed boundary vertices must stay
    // on the plane and in their cells, and their distances to the line must spread less.
    const int n = 33;
    const double z0 = 0.0171;
    const Sdf ground = {[=](const glm::dvec3& p) { return p.z - z0; },
                        [](const glm::dvec3&) { return glm::dvec3(0, 0, 1); }};
    const plugin::SampledField field = sampleUnitCube(n, ground);
    const double h = field.spacing;
    const glm::dvec3 lineNormal = glm::normalize(glm::dvec3(1.0, 0.5, 0.0));
    const double c = 0.1;
    std::vector<std::uint32_t> materials(field.values.size());
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                materials[field.index(x, y, z)] =
                    glm::dot(lineNormal, field.position(x, y, z)) < c ? 1u : 2u;

    const auto spread = [&](const TriangleMesh& mesh, const std::vector<bool>& boundary) {
        double sum = 0.0;
        double sum2 = 0.0;
        double count = 0.0;
        for (std::size_t v = 0; v < mesh.vertexCount(); ++v) {
            if (!boundary[v])
                continue;
            const double d = glm::dot(lineNormal, glm::dvec3(mesh.positions[v])) - c;
            sum += d;
            sum2 += d * d;
            count += 1.0;
        }
        return std::sqrt(std::max(0.0, sum2 / count - (sum / count) * (sum / count)));
    };

    for (const bool exact : {true, false}) {
        SCOPED_TRACE(exact ? "exact projection" : "QEF projection");
        const Extraction still = extract(field, exact ? &ground : nullptr, {}, &materials);
        const Extraction relaxed =
            extract(field, exact ? &ground : nullptr,
                    {{"material_relaxation_iterations", std::int64_t(20)}}, &materials);
        ASSERT_EQ(still.mesh.vertexCount(), relaxed.mesh.vertexCount());
        EXPECT_EQ(still.mesh.triangleCount(), relaxed.mesh.triangleCount());
        // Boundary vertices, found independently: cells whose four crossed z edges (all interior
        // away from the grid's sides) have lower samples of different materials.
        std::vector<bool> boundary(still.mesh.vertexCount(), false);
        std::size_t boundaryCount = 0;
        for (std::size_t v = 0; v < still.mesh.vertexCount(); ++v) {
            const glm::dvec3 p = (glm::dvec3(still.mesh.positions[v]) - field.origin) / h;
            const int cx = std::clamp(int(std::floor(p.x)), 0, n - 2);
            const int cy = std::clamp(int(std::floor(p.y)), 0, n - 2);
            const int cz = int(std::floor(p.z));
            std::uint32_t seen = 0;
            bool mixed = false;
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i) {
                    const int sx = cx + i;
                    const int sy = cy + j;
                    if (sx < 1 || sx > n - 2 || sy < 1 || sy > n - 2)
                        continue; // boundary edge: no quad
                    const std::uint32_t m = materials[field.index(sx, sy, cz)];
                    mixed |= seen != 0 && m != seen;
                    seen = m;
                }
            boundary[v] = mixed;
            boundaryCount += mixed;
        }
        EXPECT_EQ(relaxed.counters.at("material_boundary_vertices"), double(boundaryCount));
        EXPECT_GT(boundaryCount, 20u);
        for (std::size_t v = 0; v < relaxed.mesh.vertexCount(); ++v) {
            const glm::dvec3 before = still.mesh.positions[v];
            const glm::dvec3 after = relaxed.mesh.positions[v];
            EXPECT_NEAR(after.z, z0, 1e-6 * h) << "vertex " << v << " left the surface";
            if (!boundary[v]) {
                EXPECT_EQ(before, after) << "vertex " << v << " is not on the boundary";
            }
            // Still in its cell (the talk keeps relaxed vertices in their DC cube).
            const glm::dvec3 cellBefore = glm::floor((before - field.origin) / h + 1e-9);
            const glm::dvec3 local = (after - field.origin) / h - cellBefore;
            EXPECT_GE(std::min(local.x, local.y), -1e-5);
            EXPECT_LE(std::max(local.x, local.y), 1.0 + 1e-5);
        }
        const double before = spread(still.mesh, boundary);
        const double after = spread(relaxed.mesh, boundary);
        EXPECT_LT(after, 0.8 * before)
            << "spread " << before / h << " -> " << after / h << " cells";
        EXPECT_GT(relaxed.counters.at("material_relaxation_max_shift"), 0.05);
    }
}

TEST(DualContouringMaterials, RelaxedVerticesStayOnACurvedExactSurface)
{
    const Sdf sdf = makeSphere(glm::dvec3(0.013, -0.021, 0.008), 0.7);
    const plugin::SampledField field = sampleUnitCube(33, sdf);
    std::vector<std::uint32_t> materials(field.values.size());
    for (int z = 0; z < 33; ++z)
        for (int y = 0; y < 33; ++y)
            for (int x = 0; x < 33; ++x)
                materials[field.index(x, y, z)] = (x + 2 * y) / 5 % 2;
    const Extraction still = extract(field, &sdf, {}, &materials);
    const Extraction relaxed =
        extract(field, &sdf, {{"material_relaxation_iterations", std::int64_t(10)}}, &materials);
    EXPECT_GT(relaxed.counters.at("material_boundary_vertices"), 0.0);
    EXPECT_EQ(still.mesh.triangleCount(), relaxed.mesh.triangleCount());
    const Topology t = analyzeTopology(relaxed.mesh);
    expectClosedOriented(t);
    EXPECT_EQ(t.euler(), 2);
    EXPECT_TRUE(isMeshFinite(relaxed.mesh));
    std::size_t moved = 0;
    for (std::size_t v = 0; v < relaxed.mesh.vertexCount(); ++v) {
        const glm::dvec3 before = still.mesh.positions[v];
        const glm::dvec3 after = relaxed.mesh.positions[v];
        if (before == after)
            continue;
        ++moved;
        // Newton projection onto the exact sphere; steps that would leave the cell are halved
        // or dropped, never clamped, so moved vertices are on the sphere.
        EXPECT_LT(std::abs(sdf.value(after)), 1e-5 * field.spacing) << "vertex " << v;
    }
    EXPECT_GT(moved, 0u);
}

// ---------------------------------------------------------------------------------------------
// Timing (disabled; run with --gtest_also_run_disabled_tests --gtest_filter='*Timing*')

TEST(DualContouringTiming, DISABLED_SphereExtractionTimes)
{
    const Sdf sdf = makeSphere(glm::dvec3(0.013, -0.021, 0.008), 0.7);
    for (const int n : {65, 129, 257}) {
        const plugin::SampledField field = sampleUnitCube(n, sdf);
        for (const bool exact : {false, true}) {
            for (const std::string solver : {"svd", "schmitz"}) {
                DualContouring technique(makeParams({{"solver", solver}}));
                plugin::IsosurfaceInput input;
                input.field = &field;
                if (exact) {
                    input.exactValue = sdf.value;
                    input.exactGradient = sdf.gradient;
                }
                TriangleMesh mesh;
                technique.extract(input, mesh); // warm-up
                const auto start = std::chrono::steady_clock::now();
                constexpr int kRuns = 3;
                for (int k = 0; k < kRuns; ++k)
                    technique.extract(input, mesh);
                const double ms = std::chrono::duration<double, std::milli>(
                                      std::chrono::steady_clock::now() - start)
                                      .count() /
                                  kRuns;
                std::printf("n=%d %-7s %-7s %8.2f ms  %zu vertices %zu triangles\n", n,
                            exact ? "exact" : "samples", solver.c_str(), ms, mesh.vertexCount(),
                            mesh.triangleCount());
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Registration and parameters

TEST(DualContouringTechnique, RegistersWithItsParametersAndCounters)
{
    plugin::Registry registry;
    plugin::registerBuiltinFamilies(registry);
    rtlabRegisterTechnique_isosurface_dual_contouring(registry);
    const plugin::TechniqueEntry* entry = registry.findTechnique("isosurface", "dual_contouring");
    ASSERT_NE(entry, nullptr);
    EXPECT_FALSE(entry->info.reference.empty());
    EXPECT_NE(entry->info.seed.find("000_3da000e866ebc485"), std::string::npos);
    const config::ParamSet defaults = config::ParamSet::defaultsOf(entry->schema);
    const std::unique_ptr<plugin::Technique> technique = entry->create(defaults);
    EXPECT_EQ(technique->effectiveParams(), defaults);
    EXPECT_EQ(defaults.getFloat("svd_threshold"), 0.1);
    EXPECT_EQ(defaults.getString("outside_policy"), "clamp");
    EXPECT_EQ(defaults.getString("solver"), "svd");
    EXPECT_EQ(defaults.getString("vertices"), "per_component");
    EXPECT_EQ(defaults.getInt("schmitz_iterations"), 20);
    EXPECT_EQ(defaults.getInt("material_relaxation_iterations"), 0);

    const Overrides custom = {{"vertices", std::string("per_cell")},
                              {"solver", std::string("schmitz")},
                              {"svd_threshold", 0.25},
                              {"outside_policy", std::string("keep")},
                              {"schmitz_iterations", std::int64_t(7)},
                              {"material_relaxation_iterations", std::int64_t(3)}};
    const config::ParamSet params = makeParams(custom);
    EXPECT_EQ(DualContouring(params).effectiveParams(), params);

    EXPECT_THROW(DualContouring(makeParams({{"solver", std::string("qr")}})),
                 std::invalid_argument);
    EXPECT_THROW(DualContouring(makeParams({{"vertices", std::string("per_edge")}})),
                 std::invalid_argument);
    EXPECT_THROW(DualContouring(makeParams({{"svd_threshold", 2.0}})), std::invalid_argument);
    EXPECT_THROW(DualContouring(makeParams({{"schmitz_step", 2.5}})), std::invalid_argument);

    const Sdf sdf = makeSphere(glm::dvec3(0.0), 0.6);
    const plugin::SampledField field = sampleUnitCube(17, sdf);
    const Extraction r = extract(field, &sdf);
    for (const char* name : {"hermite_source",
                             "hermite_edges_missing",
                             "qef_solver",
                             "crossed_edges",
                             "cells",
                             "vertices",
                             "cells_multi_vertex",
                             "face_vertices",
                             "quads",
                             "cells_rank_0",
                             "cells_rank_1",
                             "cells_rank_2",
                             "cells_rank_3",
                             "normals_skipped",
                             "cells_without_normals",
                             "vertices_left_cell",
                             "vertices_left_cell_share",
                             "split_diagonal_13_share",
                             "material_boundary_vertices",
                             "material_relaxation_max_shift"})
        EXPECT_EQ(r.counters.count(name), 1u) << name;
    EXPECT_EQ(r.counters.at("vertices"), double(r.mesh.vertexCount()));
    EXPECT_EQ(r.counters.at("cells"), double(r.mesh.vertexCount()))
        << "a sphere: one sheet per cell";
    EXPECT_EQ(r.counters.at("cells_multi_vertex"), 0.0);
    EXPECT_EQ(r.counters.at("face_vertices"), 0.0);
    EXPECT_EQ(2.0 * r.counters.at("quads"), double(r.mesh.triangleCount()));
    EXPECT_EQ(r.counters.at("qef_solver"), 0.0);
    EXPECT_EQ(extract(field, &sdf, {{"solver", std::string("schmitz")}}).counters.at("qef_solver"),
              1.0);
    EXPECT_TRUE(extract(field, &sdf, {{"normals", std::string("none")}}).mesh.normals.empty());
}

} // namespace
} // namespace rtlab::isosurface
