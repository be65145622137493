// CSG edit lists: exact primitive distances, soft blends that revert to hard min/max beyond
// their radius, edits over frames, and the render mesher.

#include "metrics/mesh_metrics.h"
#include "scene/csg.h"
#include "scene/sdf_mesher.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace rtlab::scene;

namespace {
CsgEdit makeEdit(CsgShape shape, glm::dvec3 size, CsgOp op = CsgOp::Add, double blend = 0.0)
{
    CsgEdit e;
    e.shape = shape;
    e.size = size;
    e.op = op;
    e.blend = blend;
    return e;
}
} // namespace

TEST(Csg, PrimitiveDistancesAreExactAtKnownPoints)
{
    EXPECT_DOUBLE_EQ(makeEdit(CsgShape::Sphere, {1, 0, 0}).evaluatePrimitive({3, 0, 0}), 2.0);
    const CsgEdit box = makeEdit(CsgShape::Box, {1, 2, 3});
    EXPECT_DOUBLE_EQ(box.evaluatePrimitive({2, 0, 0}), 1.0);
    EXPECT_DOUBLE_EQ(box.evaluatePrimitive({0, 0, 0}), -1.0);               // nearest face is x
    EXPECT_DOUBLE_EQ(box.evaluatePrimitive({2, 3, 0}), std::sqrt(2.0));      // nearest is an edge
    CsgEdit rounded = makeEdit(CsgShape::RoundedBox, {1, 1, 1});
    rounded.rounding = 0.25;
    EXPECT_NEAR(rounded.evaluatePrimitive({2, 2, 2}), std::sqrt(3.0) * 1.25 - 0.25, 1e-12);
    const CsgEdit cyl = makeEdit(CsgShape::Cylinder, {1, 2, 0});
    EXPECT_DOUBLE_EQ(cyl.evaluatePrimitive({3, 0, 0}), 2.0);
    EXPECT_DOUBLE_EQ(cyl.evaluatePrimitive({0, 5, 0}), 3.0);
    const CsgEdit torus = makeEdit(CsgShape::Torus, {2, 0.5, 0});
    EXPECT_DOUBLE_EQ(torus.evaluatePrimitive({2, 0, 0}), -0.5);
    EXPECT_DOUBLE_EQ(torus.evaluatePrimitive({0, 0, 0}), 1.5);
    const CsgEdit capsule = makeEdit(CsgShape::Capsule, {0.5, 1, 0});
    EXPECT_DOUBLE_EQ(capsule.evaluatePrimitive({0, 3, 0}), 1.5);
    EXPECT_DOUBLE_EQ(capsule.evaluatePrimitive({2, 0.3, 0}), 1.5);
    // Cone with base radius 1 at y = -1 and apex at y = 1.
    const CsgEdit cone = makeEdit(CsgShape::Cone, {1, 1, 0});
    EXPECT_DOUBLE_EQ(cone.evaluatePrimitive({0, -2, 0}), 1.0);           // below the base
    EXPECT_DOUBLE_EQ(cone.evaluatePrimitive({0, 3, 0}), 2.0);            // above the apex
    EXPECT_NEAR(cone.evaluatePrimitive({0, -0.5, 0}), -0.5, 1e-12);      // inside, nearest the base
    // Ellipsoid: exact on its surface, and the sign is right on each side.
    const CsgEdit ellipsoid = makeEdit(CsgShape::Ellipsoid, {2, 1, 0.5});
    EXPECT_NEAR(ellipsoid.evaluatePrimitive({2, 0, 0}), 0.0, 1e-15);
    EXPECT_NEAR(ellipsoid.evaluatePrimitive({0, 0, 0.5}), 0.0, 1e-15);
    EXPECT_LT(ellipsoid.evaluatePrimitive({1, 0, 0}), 0.0);
    EXPECT_GT(ellipsoid.evaluatePrimitive({0, 2, 0}), 0.0);
}

TEST(Csg, RotationAndTranslationMoveTheShape)
{
    CsgEdit box = makeEdit(CsgShape::Box, {2, 0.5, 0.5});
    box.center = {10, 0, 0};
    box.rotation = glm::angleAxis(glm::half_pi<double>(), glm::dvec3(0, 0, 1));  // long axis -> y
    EXPECT_NEAR(box.evaluatePrimitive({10, 1.5, 0}), -0.5, 1e-12);
    EXPECT_NEAR(box.evaluatePrimitive({11.5, 0, 0}), 1.0, 1e-12);
    glm::dvec3 lo, hi;
    box.getBounds(lo, hi);
    EXPECT_NEAR(hi.y, 2.0, 1e-12);
    EXPECT_NEAR(hi.x, 10.5, 1e-12);
}

TEST(Csg, SoftBlendRevertsToHardMinBeyondItsRadius)
{
    const double k = 0.5;
    EXPECT_DOUBLE_EQ(computeSmoothMin(1.0, 1.5, k), 1.0);   // |a - b| = k: exactly hard
    EXPECT_DOUBLE_EQ(computeSmoothMin(-3.0, 2.0, k), -3.0);
    EXPECT_DOUBLE_EQ(computeSmoothMin(1.0, 1.0, k), 1.0 - k / 4.0);  // deepest where equal
    EXPECT_LT(computeSmoothMin(1.0, 1.2, k), 1.0);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-2, 2);
    for (int i = 0; i < 1000; ++i) {
        const double a = u(rng), b = u(rng);
        EXPECT_LE(computeSmoothMin(a, b, k), std::min(a, b));
        EXPECT_GE(computeSmoothMin(a, b, k), std::min(a, b) - k / 4.0);
    }
}

TEST(Csg, OperationsAndFrames)
{
    SdfModel m;
    m.edits.push_back(makeEdit(CsgShape::Box, glm::dvec3(1.0)));
    CsgEdit hole = makeEdit(CsgShape::Sphere, {0.5, 0, 0}, CsgOp::Subtract);
    hole.center = {1, 0, 0};
    hole.frame = 3;
    m.edits.push_back(hole);
    EXPECT_TRUE(m.changesOverTime());
    EXPECT_DOUBLE_EQ(m.evaluate({0.8, 0, 0}, 2), -0.2);   // before the dig
    EXPECT_NEAR(m.evaluate({0.8, 0, 0}, 3), 0.3, 1e-12);  // dug out: 0.5 - 0.2 from the hole
    CsgEdit cut = makeEdit(CsgShape::Box, {5, 0.1, 5}, CsgOp::Intersect);
    m.edits.push_back(cut);
    EXPECT_DOUBLE_EQ(m.evaluate({0, 0.5, 0}), 0.4);       // outside the intersecting slab
    EXPECT_EQ(SdfModel{}.evaluate({0, 0, 0}), std::numeric_limits<double>::infinity());
}

TEST(SdfMesher, SphereIsClosedAndOnTheSurface)
{
    SdfModel m{.name = "ball"};
    m.edits.push_back(makeEdit(CsgShape::Sphere, {0.7, 0, 0}));
    const SdfMesh out = meshSdfModel(m, {.resolution = 32});
    const auto topology = rtlab::metrics::analyzeTopology(out.mesh);
    EXPECT_TRUE(topology.watertight());
    EXPECT_TRUE(topology.orientable());
    EXPECT_EQ(topology.eulerCharacteristic, 2);
    EXPECT_GT(rtlab::metrics::computeEnclosedVolume(out.mesh), 0.0);  // outward winding
    // Newton projection puts vertices on the sphere up to float rounding of positions (~1e-7).
    for (const auto& p : out.mesh.positions)
        EXPECT_NEAR(glm::length(glm::dvec3(p)), 0.7, 1e-6);
    ASSERT_EQ(out.triangleMaterial.size(), out.mesh.triangleCount());
}

TEST(SdfMesher, ShapeTouchingItsBoundsStaysClosed)
{
    SdfModel m{.name = "slab"};
    m.edits.push_back(makeEdit(CsgShape::Box, {2, 0.5, 2}));
    m.boundsMin = {-1, -1, -1};  // the box pokes out of the bounds in x and z
    m.boundsMax = {1, 1, 1};
    const auto topology = rtlab::metrics::analyzeTopology(meshSdfModel(m, {.resolution = 16}).mesh);
    EXPECT_TRUE(topology.watertight());
    EXPECT_EQ(topology.eulerCharacteristic, 2);
}

TEST(SdfMesher, RejectsBadResolutionAndBounds)
{
    SdfModel m;
    m.edits.push_back(makeEdit(CsgShape::Sphere, {0.5, 0, 0}));
    EXPECT_THROW(meshSdfModel(m, {.resolution = 2}), std::invalid_argument);
    m.boundsMax = m.boundsMin;
    EXPECT_THROW(meshSdfModel(m), std::invalid_argument);
}
