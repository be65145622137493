// The isosurface family suite: every registered isosurface technique through the same checks, at
// its default parameters. A new isosurface plugin inherits them by registering.
//
// Each case is a field sampled from an analytic SDF (shapes from isosurface_test_support.h and
// below; the exact value and gradient are passed too, as the harness does for analytic models).
// The checks:
// - closed shapes (sphere, torus, box, off-centre and between sample planes): every undirected
//   edge is shared by exactly two triangles, each directed edge is used once (consistent
//   orientation), no triangle repeats a vertex, and the enclosed volume is positive (triangles
//   wind counter-clockwise seen from outside, the family's contract);
// - planes exactly on grid planes (exact zeros on whole sample planes) and a box whose faces lie
//   on sample planes: finite output;
// - very small (spacing 1e-5) and very large (origin 1e6, spacing 1e3) grids: finite vertices;
// - features thinner than a cell (plates, rods, a sphere smaller than a cell, single samples):
//   finite output, no exception;
// - a field that is positive everywhere: an empty mesh;
// - everywhere: indices in range, positions and normals finite, every vertex inside the grid's
//   box up to float rounding (kBoundsTolerance below).

#include "core/mesh.h"
#include "isosurface_test_support.h"
#include "families/isosurface/isosurface.h"
#include "plugin/technique.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

using namespace rtlab;

namespace {

using namespace rtlab::test;
using Sdf = SdfFunction;

// ---------------------------------------------------------------------------------------------
// Shapes (SDFs in world units, negative inside)

//! Capsule (rod) from a to b.
double computeRodSdf(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, double radius)
{
    const glm::dvec3 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    return glm::length(p - (a + t * ab)) - radius;
}

struct Case {
    std::string name;
    plugin::SampledField field;
    Sdf sdf;  //!< exact field; empty when the samples are written directly
};

//! A case on n^3 samples spanning `origin` + [0, (n - 1) h]^3.
Case makeCase(std::string name, int n, glm::dvec3 origin, double h, Sdf sdf)
{
    Case c{std::move(name), sampleField(glm::ivec3(n), origin, h, sdf), sdf};
    return c;
}

//! Samples written from sample indices, so that zeros are exact.
Case makeIndexCase(std::string name, glm::ivec3 n, double h,
                   const std::function<double(int, int, int)>& value)
{
    Case c;
    c.name = std::move(name);
    c.field.samples = n;
    c.field.spacing = h;
    c.field.values.resize(std::size_t(n.x) * n.y * n.z);
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x)
                c.field.values[c.field.index(x, y, z)] = float(value(x, y, z));
    return c;
}

//! Closed surfaces well inside their grids.
std::vector<Case> makeClosedCases()
{
    const double h = 2.0 / 31.0;  // 32^3 samples over [-1, 1]^3
    const glm::dvec3 o(-1.0);
    return {
        makeCase("sphere", 32, o, h,
                 [](const glm::dvec3& p) { return computeSphereSdf(p, glm::dvec3(0.0), 0.7); }),
        makeCase("sphere_off_centre", 29, o, 2.0 / 28.0,
                 [](const glm::dvec3& p) {
                     return computeSphereSdf(p, glm::dvec3(0.113, -0.071, 0.037), 0.41);
                 }),
        makeCase("torus", 40, o, 2.0 / 39.0,
                 [](const glm::dvec3& p) {
                     return computeTorusSdf(p, glm::dvec3(0.01, -0.02, 0.03), 0.55, 0.2);
                 }),
        makeCase("box_between_sample_planes", 10, glm::dvec3(0.0), 1.0,
                 [](const glm::dvec3& p) {
                     return computeBoxSdf(p, glm::dvec3(4.0), glm::dvec3(1.5));
                 }),
        makeCase("box_rotated_off_grid", 32, o, h,
                 [](const glm::dvec3& p) {
                     // Rotated about z by 0.3 rad: faces and edges cut the cells obliquely.
                     const double c = std::cos(0.3), s = std::sin(0.3);
                     const glm::dvec3 q(c * p.x + s * p.y, -s * p.x + c * p.y, p.z);
                     return computeBoxSdf(q, glm::dvec3(0.02, -0.03, 0.01),
                                          glm::dvec3(0.5, 0.4, 0.45));
                 }),
    };
}

//! Exact zeros on whole sample planes.
std::vector<Case> makeExactZeroCases()
{
    const glm::ivec3 n(12, 11, 10);
    const double h = 0.1;
    return {
        makeIndexCase("plane_z_on_samples", n, h, [=](int, int, int z) { return (z - 4) * h; }),
        makeIndexCase("plane_x_on_samples_negated", n, h,
                      [=](int x, int, int) { return (5 - x) * h; }),
        makeIndexCase("plane_diagonal_on_samples", n, h,
                      [=](int x, int y, int) { return (x + y - 9) * h / std::sqrt(2.0); }),
        makeIndexCase("plane_on_the_first_sample_layer", n, h,
                      [=](int, int y, int) { return y * h; }),
        makeIndexCase("plane_on_the_last_sample_layer", n, h,
                      [=](int, int, int z) { return (z - 9) * h; }),
        makeIndexCase("box_faces_on_samples", glm::ivec3(10), 1.0,
                      [](int x, int y, int z) {
                          return computeBoxSdf(glm::dvec3(x, y, z), glm::dvec3(4.0),
                                               glm::dvec3(2.0));
                      }),
        makeIndexCase("all_zero", glm::ivec3(6), 1.0, [](int, int, int) { return 0.0; }),
    };
}

//! A sphere of radius 9.3 cells on 24^3 samples at the given placement.
Case makeScaledSphere(std::string name, glm::dvec3 origin, double h)
{
    const glm::dvec3 center = origin + h * glm::dvec3(11.6, 11.3, 11.9);
    return makeCase(std::move(name), 24, origin, h,
                    [=](const glm::dvec3& p) { return computeSphereSdf(p, center, 9.3 * h); });
}

std::vector<Case> makeScaleCases()
{
    return {
        makeScaledSphere("tiny_spacing_1e-5", glm::dvec3(0.0), 1e-5),
        makeScaledSphere("tiny_spacing_1e-5_offset", glm::dvec3(0.25, -0.5, 3.0), 1e-5),
        makeScaledSphere("huge_origin_1e6_spacing_1e3", glm::dvec3(1e6), 1e3),
        makeScaledSphere("huge_negative_origin", glm::dvec3(-1e6, 1e6, -1e6), 1e3),
    };
}

//! Features thinner than a cell.
std::vector<Case> makeThinCases()
{
    const double h = 1.0 / 15.0;  // 16^3 samples over [0, 1]^3
    const glm::dvec3 o(0.0);
    return {
        // A plate 0.4 h thick between two sample planes: no sample inside, nothing or slivers.
        makeCase("plate_between_samples", 16, o, h,
                 [=](const glm::dvec3& p) { return std::abs(p.z - 7.5 * h) - 0.2 * h; }),
        // A plate 0.4 h thick around a sample plane: one sample layer inside.
        makeCase("plate_through_samples", 16, o, h,
                 [=](const glm::dvec3& p) { return std::abs(p.z - 7.0 * h) - 0.2 * h; }),
        // An oblique plate 0.3 h thick.
        makeCase("plate_oblique", 16, o, h,
                 [=](const glm::dvec3& p) {
                     return std::abs(glm::dot(p - glm::dvec3(0.5), glm::normalize(glm::dvec3(
                                                                      1.0, 2.0, 3.0)))) -
                            0.15 * h;
                 }),
        // Rods of radius 0.3 h, one along a sample line, one oblique.
        makeCase("rod_on_sample_line", 16, o, h,
                 [=](const glm::dvec3& p) {
                     return computeRodSdf(p, glm::dvec3(2 * h, 5 * h, 6 * h),
                                          glm::dvec3(13 * h, 5 * h, 6 * h), 0.3 * h);
                 }),
        makeCase("rod_oblique", 16, o, h,
                 [=](const glm::dvec3& p) {
                     return computeRodSdf(p, glm::dvec3(0.1, 0.15, 0.2), glm::dvec3(0.9, 0.8, 0.75),
                                          0.3 * h);
                 }),
        // A sphere smaller than a cell, between samples, and one around a sample.
        makeCase("sphere_inside_one_cell", 16, o, h,
                 [=](const glm::dvec3& p) {
                     return computeSphereSdf(p, glm::dvec3(7.5 * h), 0.3 * h);
                 }),
        makeCase("sphere_around_one_sample", 16, o, h,
                 [=](const glm::dvec3& p) {
                     return computeSphereSdf(p, glm::dvec3(7.0 * h, 8.0 * h, 9.0 * h), 0.3 * h);
                 }),
        // Isolated single negative samples in a positive field (a checkerboard of them).
        makeIndexCase("isolated_samples", glm::ivec3(9), 1.0,
                      [](int x, int y, int z) {
                          return (x % 2 == 1 && y % 2 == 1 && z % 2 == 1) ? -0.5 : 0.5;
                      }),
    };
}

// ---------------------------------------------------------------------------------------------
// Checks

//! A vertex may lie outside the grid's box only by the float rounding of its coordinates: 2^-22
//! (four float ulps) of the largest coordinate magnitude of the box, plus 1e-6 of a cell.
double computeBoundsTolerance(const plugin::SampledField& field)
{
    const glm::dvec3 far = field.origin + field.spacing * glm::dvec3(field.samples - 1);
    const double magnitude = std::max(glm::length(glm::abs(field.origin)), glm::length(glm::abs(far)));
    return std::ldexp(magnitude, -22) + 1e-6 * field.spacing;
}

//! Indices in range, positions and normals finite (normals: none or one per position), every
//! vertex inside the grid box.
void expectValidMesh(const TriangleMesh& mesh, const plugin::SampledField& field,
                     const std::string& what)
{
    ASSERT_EQ(mesh.indices.size() % 3, 0u) << what;
    for (std::size_t i = 0; i < mesh.indices.size(); ++i)
        ASSERT_LT(mesh.indices[i], mesh.vertexCount()) << what << ": index " << i;
    ASSERT_TRUE(mesh.normals.empty() || mesh.normals.size() == mesh.positions.size())
        << what << ": " << mesh.normals.size() << " normals for " << mesh.positions.size()
        << " positions";
    const double tolerance = computeBoundsTolerance(field);
    const glm::dvec3 low = field.origin;
    const glm::dvec3 high = field.origin + field.spacing * glm::dvec3(field.samples - 1);
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i) {
        const glm::vec3 p = mesh.positions[i];
        ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
            << what << ": vertex " << i;
        for (int axis = 0; axis < 3; ++axis) {
            ASSERT_GE(double(p[axis]), low[axis] - tolerance)
                << what << ": vertex " << i << " below the grid on axis " << axis;
            ASSERT_LE(double(p[axis]), high[axis] + tolerance)
                << what << ": vertex " << i << " above the grid on axis " << axis;
        }
    }
    for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
        const glm::vec3 n = mesh.normals[i];
        ASSERT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z))
            << what << ": normal " << i;
    }
}

// ---------------------------------------------------------------------------------------------
// The suite

class IsosurfaceSuite : public testing::TestWithParam<const plugin::TechniqueEntry*> {
protected:
    //! A fresh instance at default parameters.
    std::unique_ptr<plugin::Technique> make() const
    {
        return GetParam()->create(config::ParamSet::defaultsOf(GetParam()->schema));
    }

    //! Runs the technique on `c` (exact value and gradient included when the case has an SDF).
    TriangleMesh extract(const Case& c) const
    {
        const std::unique_ptr<plugin::Technique> technique = make();
        auto* iso = dynamic_cast<plugin::IsosurfaceTechnique*>(technique.get());
        if (iso == nullptr) {
            ADD_FAILURE() << GetParam()->info.name << " is not an IsosurfaceTechnique";
            return {};
        }
        plugin::IsosurfaceInput input;
        input.field = &c.field;
        input.isoValue = 0.0;
        if (c.sdf) {
            input.exactValue = c.sdf;
            const double step = 1e-3 * c.field.spacing;
            const Sdf sdf = c.sdf;
            input.exactGradient = [sdf, step](const glm::dvec3& p) {
                glm::dvec3 g;
                for (int axis = 0; axis < 3; ++axis) {
                    glm::dvec3 d(0.0);
                    d[axis] = step;
                    g[axis] = (sdf(p + d) - sdf(p - d)) / (2.0 * step);
                }
                return g;
            };
        }
        TriangleMesh mesh;
        mesh.positions.assign(2, glm::vec3(1e30f));  // stale content must be replaced
        mesh.indices = {0, 1, 1};
        EXPECT_NO_THROW(iso->extract(input, mesh)) << c.name;
        return mesh;
    }
};

TEST_P(IsosurfaceSuite, ClosedShapesAreClosedAndConsistentlyOriented)
{
    for (const Case& c : makeClosedCases()) {
        SCOPED_TRACE(c.name);
        const TriangleMesh mesh = extract(c);
        expectValidMesh(mesh, c.field, c.name);
        ASSERT_GT(mesh.triangleCount(), 0u) << c.name;
        const Topology t = analyzeTopology(mesh);
        EXPECT_EQ(t.badIndices, 0u) << c.name << ": triangles repeating a vertex";
        EXPECT_EQ(t.boundaryEdges, 0u) << c.name << ": edges used by one triangle (holes)";
        EXPECT_EQ(t.overusedEdges, 0u) << c.name << ": edges used by three or more triangles";
        EXPECT_EQ(t.repeatedDirectedEdges, 0u) << c.name << ": inconsistent orientation";
        EXPECT_GT(computeSignedVolume(mesh), 0.0) << c.name << ": triangles face inward";
    }
}

TEST_P(IsosurfaceSuite, ExactZerosOnSamplePlanesGiveFiniteOutput)
{
    for (const Case& c : makeExactZeroCases()) {
        SCOPED_TRACE(c.name);
        expectValidMesh(extract(c), c.field, c.name);
    }
}

TEST_P(IsosurfaceSuite, ExtremeScalesGiveFiniteVerticesInsideTheGrid)
{
    for (const Case& c : makeScaleCases()) {
        SCOPED_TRACE(c.name);
        const TriangleMesh mesh = extract(c);
        expectValidMesh(mesh, c.field, c.name);
        EXPECT_GT(mesh.triangleCount(), 0u) << c.name;
    }
}

TEST_P(IsosurfaceSuite, FeaturesThinnerThanACellGiveFiniteOutput)
{
    for (const Case& c : makeThinCases()) {
        SCOPED_TRACE(c.name);
        expectValidMesh(extract(c), c.field, c.name);
    }
}

TEST_P(IsosurfaceSuite, PositiveFieldGivesAnEmptyMesh)
{
    const Case c = makeIndexCase("all_positive", glm::ivec3(7, 6, 5), 0.5,
                                 [](int x, int y, int z) { return 0.25 + 0.1 * (x + y + z); });
    const TriangleMesh mesh = extract(c);
    EXPECT_EQ(mesh.vertexCount(), 0u);
    EXPECT_EQ(mesh.triangleCount(), 0u);
}

std::vector<const plugin::TechniqueEntry*> getIsosurfaceTechniques()
{
    return plugin::builtinRegistry().techniques("isosurface");
}

INSTANTIATE_TEST_SUITE_P(Registered, IsosurfaceSuite, testing::ValuesIn(getIsosurfaceTechniques()),
                         [](const auto& info) { return info.param->info.name; });
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(IsosurfaceSuite);

} // namespace
