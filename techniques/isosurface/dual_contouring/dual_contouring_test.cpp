#include "dual_contouring.h"

#include "dual_contouring_test_support.h"
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
using namespace dc_test;
using dc::QefSystem;

// ---------------------------------------------------------------------------------------------
// Cubes: sharp features

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
