// Dual contouring's 2-manifold output (one vertex per surface patch) and its degenerate inputs.
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

namespace rtlab::isosurface {
namespace {

using namespace test;
using namespace dc_test;

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

} // namespace
} // namespace rtlab::isosurface
