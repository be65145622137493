#include "metrics/mesh_metrics.h"

#include "core/error.h"
#include "mesh_test_shapes.h"
#include "metrics/mesh_metrics_detail.h"

#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <limits>

namespace rtlab::metrics {
namespace {

using testing::appendMesh;
using testing::evaluateBoxGradient;
using testing::evaluateBoxSdf;
using testing::evaluateSphereSdf;
using testing::findMaxCircumradius;
using testing::makeChamferedCube;
using testing::makeCubeMesh;
using testing::makeIcosphere;
using testing::makeOctahedron;

constexpr double kDeg = 57.29577951308232;  // degrees per radian
const glm::dvec3 kUnit(1.0);

ScalarField makeBoxField() { return [](const glm::dvec3& p) { return evaluateBoxSdf(p, kUnit); }; }
VectorField makeBoxGradientField()
{
    return [](const glm::dvec3& p) { return evaluateBoxGradient(p, kUnit); };
}
ScalarField makeSphereField(double r)
{
    return [r](const glm::dvec3& p) { return evaluateSphereSdf(p, r); };
}
VectorField makeSphereGradientField() { return [](const glm::dvec3& p) { return p; }; }

std::vector<glm::dvec3> sampleSphere(double r, std::size_t count)
{
    return sampleSdfSurface(makeSphereField(r), makeSphereGradientField(), glm::dvec3(-1.5 * r),
                            glm::dvec3(1.5 * r), count, 7, {.tolerance = 1e-13});
}

//! Largest distance between an inscribed triangle and the sphere: the sagitta of the triangle's
//! circumcircle, r - sqrt(r^2 - R^2), at its circumcentre (for acute triangles, as here).
double computeSagitta(double r, double circumradius)
{
    return r - std::sqrt(r * r - circumradius * circumradius);
}

// ---- Sampling -----------------------------------------------------------------------------------

TEST(MeshSampling, StratifiedAreaUniformOnCube)
{
    // The 6 faces have equal area, so stratification gives each exactly count / 6 samples, +-1.
    const TriangleMesh cube = makeCubeMesh(1.0f, 3);
    const auto samples = sampleMeshSurface(cube, 6000, 3);
    ASSERT_EQ(samples.size(), 6000u);
    int perFace[6] = {};
    for (const MeshSample& s : samples) {
        ++perFace[s.triangle / 18];  // 9 quads = 18 triangles per face
        EXPECT_NEAR(std::abs(evaluateBoxSdf(s.position, kUnit)), 0.0, 1e-15);
        EXPECT_NEAR(s.barycentric.x + s.barycentric.y + s.barycentric.z, 1.0, 1e-15);
    }
    for (int f = 0; f < 6; ++f)
        EXPECT_NEAR(perFace[f], 1000, 1) << "face " << f;
    EXPECT_EQ(sampleMeshSurface(cube, 6000, 3)[1234].position, samples[1234].position);
    EXPECT_NE(sampleMeshSurface(cube, 6000, 4)[1234].position, samples[1234].position);
}

TEST(MeshSampling, SdfSurfacePointsLieOnTheSphereEvenly)
{
    const auto points = sampleSphere(1.0, 20000);
    ASSERT_EQ(points.size(), 20000u);
    int upper = 0, positiveX = 0;
    for (const auto& p : points) {
        EXPECT_LE(std::abs(glm::length(p) - 1.0), 1e-13);
        upper += p.z > 0;
        positiveX += p.x > 0;
    }
    // Area-uniform: each hemisphere holds half the points; binomial sigma = 0.5 / sqrt(N) =
    // 0.0035, and 4 sigma = 0.014.
    EXPECT_NEAR(upper / 20000.0, 0.5, 0.014);
    EXPECT_NEAR(positiveX / 20000.0, 0.5, 0.014);
}

TEST(MeshBvh, NearestTriangleMatchesBruteForce)
{
    const TriangleMesh sphere = makeIcosphere(1.0, 2);
    std::vector<detail::Box> boxes;
    for (std::size_t t = 0; t < sphere.triangleCount(); ++t) {
        glm::dvec3 v[3];
        detail::loadTriangle(sphere, t, v);
        boxes.push_back(
            {glm::min(v[0], glm::min(v[1], v[2])), glm::max(v[0], glm::max(v[1], v[2]))});
    }
    const detail::PrimitiveBvh bvh(boxes);
    const detail::PrimitiveBvh::DistanceFunction distance = [&](std::uint32_t t,
                                                                const glm::dvec3& p) {
        glm::dvec3 v[3];
        detail::loadTriangle(sphere, t, v);
        return glm::length(p - detail::findClosestPointOnTriangle(p, v[0], v[1], v[2]));
    };
    for (std::uint64_t i = 0; i < 2000; ++i) {
        const glm::dvec3 p(detail::hashToUnit(5, i, 0) * 4 - 2, detail::hashToUnit(5, i, 1) * 4 - 2,
                           detail::hashToUnit(5, i, 2) * 4 - 2);
        double brute = std::numeric_limits<double>::infinity();
        for (std::uint32_t t = 0; t < sphere.triangleCount(); ++t)
            brute = std::min(brute, distance(t, p));
        // Same distance function: the BVH must find the very minimum.
        EXPECT_EQ(bvh.findNearestDistance(p, distance), brute) << "point " << i;
    }
}

// ---- Two-sided distance -------------------------------------------------------------------------

TEST(MeshDistance, CubeMeshMatchesBoxSdf)
{
    // The mesh is the surface itself: what remains is rounding. Mesh samples are convex
    // combinations of exact float corners (error a few 1e-16), surface points are projected to
    // |sdf| <= 1e-13 (the tolerance asked for), so both sides stay below 2e-13.
    const TriangleMesh cube = makeCubeMesh(1.0f, 4);
    const auto surface = sampleSdfSurface(makeBoxField(), makeBoxGradientField(), glm::dvec3(-1.5),
                                          glm::dvec3(1.5), 20000, 1, {.tolerance = 1e-13});
    ASSERT_EQ(surface.size(), 20000u);
    const MeshDistance d =
        measureMeshDistance(cube, makeBoxField(), surface, {.meshSamples = 50000, .cellSize = 0.5});
    EXPECT_EQ(d.meshToSurface.samples, 50000u);
    EXPECT_EQ(d.surfaceToMesh.samples, 20000u);
    EXPECT_LE(d.hausdorff, 2e-13);
    EXPECT_LE(d.chamferMean, 2e-13);
    EXPECT_LE(d.chamferRms, 2e-13);
    EXPECT_DOUBLE_EQ(d.hausdorffCells, d.hausdorff / 0.5);
}

TEST(MeshDistance, IcosphereDeviatesByItsSagitta)
{
    // Inscribed icosphere (vertices on the sphere, r = 1, 1280 acute triangles). Mesh -> surface
    // peaks at a triangle's circumcentre and surface -> mesh at the sphere point above it, both at
    // the sagitta h = r - sqrt(r^2 - R^2) of the largest circumradius R. Upper bound: h plus
    // 1e-6 for the float vertex positions (relative error 6e-8). Lower bound 0.97 h: the
    // deviation falls as h - d^2 / 2r at distance d from a circumcentre, so 0.97 h needs a sample
    // within d = sqrt(0.06 r h) = 0.014 of one of the 20 symmetric largest triangles; the
    // 200000 samples (156 per triangle, spacing 0.007; 16000 per unit area on the sphere) put
    // several there.
    const TriangleMesh sphere = makeIcosphere(1.0, 3);
    ASSERT_EQ(sphere.triangleCount(), 1280u);
    ASSERT_LT(computeTriangleAngleHistogram(sphere).maxAngleDeg, 90.0);  // acute
    const double h = computeSagitta(1.0, findMaxCircumradius(sphere));
    // The mean edge, 1.107 rad / 8, gives R = 0.08 and h = R^2 / 2r = 0.0032; normalisation grows
    // the triangles at the centres of the icosahedron's faces, by ~1.2 in edge (~1.4 in h).
    EXPECT_GT(h, 0.0032);
    EXPECT_LT(h, 0.0050);
    const MeshDistance d =
        measureMeshDistance(sphere, makeSphereField(1.0), sampleSphere(1.0, 200000));
    EXPECT_LE(d.meshToSurface.max, h + 1e-6);
    EXPECT_GE(d.meshToSurface.max, 0.97 * h);
    EXPECT_LE(d.surfaceToMesh.max, h + 1e-6);
    EXPECT_GE(d.surfaceToMesh.max, 0.97 * h);
    EXPECT_DOUBLE_EQ(d.hausdorff, std::max(d.meshToSurface.max, d.surfaceToMesh.max));
    for (const OneSidedDistance* s : {&d.meshToSurface, &d.surfaceToMesh}) {
        EXPECT_GT(s->mean, 0.0);
        EXPECT_LT(s->mean, s->rms);
        EXPECT_LT(s->rms, s->max);
    }
    EXPECT_DOUBLE_EQ(d.chamferMean, 0.5 * (d.meshToSurface.mean + d.surfaceToMesh.mean));
    EXPECT_TRUE(std::isnan(d.hausdorffCells));  // no cell size given
}

TEST(MeshDistance, OffsetSphereReadsTheOffset)
{
    // Icosphere inscribed in radius r + delta = 1.05 against the sphere of radius 1. Every mesh
    // point lies between radius (r + delta) - h' and r + delta (h' its sagitta), so mesh ->
    // surface is in [delta - h', delta]. The mesh is convex, contains the sphere and has inradius
    // >= (r + delta) - h', so surface -> mesh is in [delta - h', delta] too. Hence Hausdorff and
    // both Chamfer forms lie in [delta - h', delta], plus 1e-6 for float positions.
    const double r = 1.0, delta = 0.05;
    const TriangleMesh sphere = makeIcosphere(r + delta, 4);
    const double h = computeSagitta(r + delta, findMaxCircumradius(sphere));
    EXPECT_LT(h, 0.0013);  // a quarter of level 3's (r + delta) x 0.0045
    const MeshDistance d = measureMeshDistance(sphere, makeSphereField(r), sampleSphere(r, 50000),
                                               {.meshSamples = 50000, .cellSize = 0.1});
    for (const double v : {d.hausdorff, d.chamferMean, d.chamferRms}) {
        EXPECT_GE(v, delta - h);
        EXPECT_LE(v, delta + 1e-6);
    }
    EXPECT_NEAR(d.hausdorffCells, d.hausdorff / 0.1, 1e-15);
}

TEST(MeshDistance, RejectsMissingSurfacePoints)
{
    EXPECT_THROW(measureMeshDistance(makeCubeMesh(1.0f, 1), makeBoxField(), {}), Error);
}

// ---- Normal error -------------------------------------------------------------------------------

TEST(MeshNormal, CubeNormalsMatchBoxGradient)
{
    // Face normals and the box gradient are both exact axis vectors on every face (the gradient
    // only changes on the edges, which samples hit with probability 0): the angle is 0 up to
    // atan2 rounding, far below 1e-9 degrees.
    const NormalError face = measureNormalError(makeCubeMesh(1.0f, 4), makeBoxGradientField());
    EXPECT_EQ(face.samples, 200000u);
    EXPECT_EQ(face.skipped, 0u);
    EXPECT_LE(face.maxDeg, 1e-9);
    // Per-face vertices carry the face normal, so interpolation gives the same result.
    const NormalError smooth =
        measureNormalError(makeCubeMesh(1.0f, 4, false), makeBoxGradientField(),
                           {.source = MeshNormalSource::Interpolated});
    EXPECT_LE(smooth.maxDeg, 1e-9);
    TriangleMesh noNormals = makeCubeMesh(1.0f, 1);
    noNormals.normals.clear();
    EXPECT_THROW(measureNormalError(noNormals, makeBoxGradientField(),
                                    {.source = MeshNormalSource::Interpolated}),
                 Error);
}

TEST(MeshNormal, CoarseSphereErrorIsBoundedByTheTriangleSize)
{
    // For a triangle inscribed in the sphere the face normal points at its circumcentre c, so at a
    // point p of the face the angle to the radial gradient is atan(|p - c| / |c|), largest at the
    // corners: asin(R / r). Sampled max: in [0.95, 1] of that bound (+1e-4 degree for floats);
    // the angle falls linearly away from a corner, and with 2500 samples per triangle one of the
    // 240 corners has a sample within 5% of R.
    const TriangleMesh coarse = makeIcosphere(1.0, 1);
    const double bound = std::asin(findMaxCircumradius(coarse)) * kDeg;
    EXPECT_NEAR(bound, 20.9, 0.5);  // level 1: R = 0.357
    const NormalError e = measureNormalError(coarse, makeSphereGradientField());
    EXPECT_LE(e.maxDeg, bound + 1e-4);
    EXPECT_GE(e.maxDeg, 0.95 * bound);
    EXPECT_GT(e.meanDeg, 0.0);
    EXPECT_LT(e.meanDeg, e.rmsDeg);
    EXPECT_LT(e.rmsDeg, e.maxDeg);
    // Two more subdivisions quarter the angles (R halves per level).
    const NormalError fine = measureNormalError(makeIcosphere(1.0, 3), makeSphereGradientField());
    EXPECT_LT(fine.maxDeg, e.maxDeg / 3.0);
}

// ---- Sharp features -----------------------------------------------------------------------------

TEST(MeshSharp, CubeEdgesAreTheBoxFeatures)
{
    // 12 box edges, each cut into 4 grid edges; the flat grid and diagonal edges are not sharp.
    // The mesh edges lie exactly on the true edges (float-exact corners): distance 0.
    const auto features = makeBoxFeatureEdges(glm::dvec3(0.0), kUnit);
    ASSERT_EQ(features.size(), 12u);
    for (bool shared : {true, false}) {
        const SharpFeatureScore s =
            measureSharpFeatures(makeCubeMesh(1.0f, 4, shared), features, {.tolerance = 0.01});
        EXPECT_EQ(s.meshEdges, 48u);
        EXPECT_DOUBLE_EQ(s.meshEdgeLength, 24.0);
        EXPECT_DOUBLE_EQ(s.featureLength, 24.0);
        EXPECT_EQ(s.featureSamples, 12u * 800u);  // 2 / (0.01 / 4) samples per edge
        EXPECT_LE(s.edgeChamfer, 1e-15);
        EXPECT_EQ(s.precision, 1.0);
        EXPECT_EQ(s.recall, 1.0);
        EXPECT_EQ(s.f1, 1.0);
    }
}

TEST(MeshSharp, RotatedCubeMatchesRotatedBoxFeatures)
{
    // Rotated float positions are off by < 2.2e-7 (|x| <= 1.8, float epsilon 1.2e-7).
    const glm::dmat3 rotation(
        glm::rotate(glm::dmat4(1.0), 0.7, glm::normalize(glm::dvec3(1, 2, 3))));
    TriangleMesh cube = makeCubeMesh(1.0f, 2);
    const glm::dvec3 centre(0.25, -0.5, 1.0);
    for (auto& p : cube.positions)
        p = glm::vec3(centre + rotation * glm::dvec3(p));
    const SharpFeatureScore s = measureSharpFeatures(
        cube, makeBoxFeatureEdges(centre, kUnit, rotation), {.tolerance = 0.01});
    EXPECT_EQ(s.meshEdges, 24u);
    EXPECT_LE(s.edgeChamfer, 2.2e-7);
    EXPECT_EQ(s.f1, 1.0);
}

TEST(MeshSharp, ChamferedCubeMissesTheEdges)
{
    // Bevels of width w = 0.2 replace each edge. The mesh's sharp edges are the 24 square-bevel
    // edges (crease 45 degrees) and the 24 bevel-corner edges (crease acos(2 / sqrt 6) = 35.26).
    // Geometry of one true edge {x = y = 1}: square-bevel edges run at distance w from it,
    // bevel-corner edges at w / sqrt 2 (midpoint) to w (ends), so mesh -> feature is in
    // [w / sqrt 2, w]. The solid lies in x + y <= 2 - w, at w / sqrt 2 from the edge, and the
    // farthest true point (a corner) is w sqrt(3/2) from the corner triangle's edges, so
    // feature -> mesh is in [w / sqrt 2, w sqrt(3/2)].
    const double w = 0.2;
    const TriangleMesh mesh = makeChamferedCube(w);
    ASSERT_EQ(mesh.vertexCount(), 24u);
    ASSERT_TRUE(analyzeTopology(mesh).watertight());
    ASSERT_GT(computeEnclosedVolume(mesh), 0.0);
    const auto features = makeBoxFeatureEdges(glm::dvec3(0.0), kUnit);

    const SharpFeatureScore tight = measureSharpFeatures(mesh, features, {.tolerance = 0.05});
    EXPECT_EQ(tight.meshEdges, 48u);
    EXPECT_GE(tight.meshToFeature, w / std::sqrt(2.0) - 1e-7);
    EXPECT_LE(tight.meshToFeature, w + 1e-7);
    EXPECT_GE(tight.featureToMesh, w / std::sqrt(2.0) - 1e-7);
    EXPECT_LE(tight.featureToMesh, w * std::sqrt(1.5) + 1e-7);
    EXPECT_GT(tight.edgeChamfer, 0.14);
    // tau = 0.05 < w / sqrt 2: no sample is within tau.
    EXPECT_EQ(tight.precision, 0.0);
    EXPECT_EQ(tight.recall, 0.0);
    EXPECT_EQ(tight.f1, 0.0);

    // tau = 0.25 >= w sqrt(3/2) = 0.245: every sample is within tau.
    const SharpFeatureScore loose = measureSharpFeatures(mesh, features, {.tolerance = 0.25});
    EXPECT_EQ(loose.f1, 1.0);

    // Above 35.26 degrees only the square-bevel edges remain.
    EXPECT_EQ(extractSharpEdges(mesh, 40.0).size(), 24u);
}

TEST(MeshSharp, SmoothSphereHasNoSharpEdges)
{
    // Level 3 creases are about 8 degrees; the bare icosahedron's are 41.8 degrees.
    const TriangleMesh sphere = makeIcosphere(1.0, 3);
    EXPECT_TRUE(extractSharpEdges(sphere, 30.0).empty());
    EXPECT_EQ(extractSharpEdges(makeIcosphere(1.0, 0), 30.0).size(), 30u);

    // Against a cube's edges: nothing found (recall 0), nothing spurious (precision 1), f1 0.
    const SharpFeatureScore vsCube = measureSharpFeatures(
        sphere, makeBoxFeatureEdges(glm::dvec3(0.0), kUnit), {.tolerance = 0.05});
    EXPECT_EQ(vsCube.meshEdges, 0u);
    EXPECT_EQ(vsCube.recall, 0.0);
    EXPECT_EQ(vsCube.precision, 1.0);
    EXPECT_EQ(vsCube.f1, 0.0);
    EXPECT_TRUE(std::isinf(vsCube.edgeChamfer));
    // Against no features: a perfect (vacuous) score.
    const SharpFeatureScore vsNone = measureSharpFeatures(sphere, {}, {.tolerance = 0.05});
    EXPECT_EQ(vsNone.f1, 1.0);
    EXPECT_EQ(vsNone.edgeChamfer, 0.0);
}

// ---- Triangle angles ----------------------------------------------------------------------------

TEST(MeshAngles, EquilateralAndRightIsoscelesTriangles)
{
    const TriangleAngleHistogram octa = computeTriangleAngleHistogram(makeOctahedron());
    ASSERT_EQ(octa.counts.size(), 18u);
    EXPECT_EQ(octa.angles, 24u);
    EXPECT_EQ(octa.counts[6], 24u);  // [60, 70)
    EXPECT_NEAR(octa.minAngleDeg, 60.0, 1e-12);
    EXPECT_NEAR(octa.maxAngleDeg, 60.0, 1e-12);
    EXPECT_EQ(octa.slivers, 0u);

    // A unit square as two triangles: 45, 45, 90 each.
    const TriangleAngleHistogram square = computeTriangleAngleHistogram(makeCubeMesh(1.0f, 1));
    EXPECT_EQ(square.angles, 36u);
    EXPECT_EQ(square.counts[4], 24u);  // [40, 50)
    EXPECT_EQ(square.counts[9], 12u);  // [90, 100)
    EXPECT_NEAR(square.minAngleDeg, 45.0, 1e-12);
    EXPECT_NEAR(square.maxAngleDeg, 90.0, 1e-12);
    EXPECT_EQ(square.sliverFraction, 0.0);
}

TEST(MeshAngles, SliversAndDegenerateTriangles)
{
    // Isosceles sliver of height 0.01 over base 1: two angles of atan(0.02) = 1.146 degrees and
    // one of 177.7; plus a collapsed triangle that is left out.
    TriangleMesh mesh;
    mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0.5f, 0.01f, 0}};
    mesh.indices = {0, 1, 2, 0, 1, 1};
    const TriangleAngleHistogram h = computeTriangleAngleHistogram(mesh);
    EXPECT_EQ(h.degenerateTriangles, 1u);
    EXPECT_EQ(h.angles, 3u);
    EXPECT_EQ(h.counts[0], 2u);
    EXPECT_EQ(h.counts[17], 1u);
    EXPECT_NEAR(h.minAngleDeg, std::atan(0.02) * kDeg, 1e-5);  // 0.01f is off by 2e-10
    EXPECT_EQ(h.slivers, 2u);
    EXPECT_NEAR(h.sliverFraction, 2.0 / 3.0, 1e-15);
}

// ---- Self-intersections -------------------------------------------------------------------------

TEST(MeshSelfIntersection, CrossingQuads)
{
    // Quad A in z = 0, quad B in x = 0 shifted up by 0.3; each split along its diagonal. They
    // cross along {x = 0, z = 0}: A's halves cover y <= 0 and y >= 0 of that line, B's halves
    // y >= -0.3 and y <= -0.3, so three of the four pairs overlap on a segment.
    TriangleMesh mesh;
    mesh.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0},
                      {0, -1, -0.7f}, {0, 1, -0.7f}, {0, 1, 1.3f}, {0, -1, 1.3f}};
    mesh.indices = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7};
    const SelfIntersections s = findSelfIntersections(mesh);
    EXPECT_EQ(s.pairs, 3u);
    EXPECT_EQ(s.triangles, (std::vector<std::uint32_t>{0, 1, 2, 3}));
}

TEST(MeshSelfIntersection, ClosedMeshesHaveNone)
{
    EXPECT_EQ(findSelfIntersections(makeCubeMesh(1.0f, 3)).pairs, 0u);
    // Separate vertices per face: neighbours still count as adjacent through equal positions.
    EXPECT_EQ(findSelfIntersections(makeCubeMesh(1.0f, 3, false)).pairs, 0u);
    const SelfIntersections sphere = findSelfIntersections(makeIcosphere(1.0, 3));
    EXPECT_EQ(sphere.pairs, 0u);
    EXPECT_GT(sphere.candidatePairs, 1280u);  // neighbours' boxes overlap
}

TEST(MeshSelfIntersection, NeighboursAreNeverCounted)
{
    // Folded onto each other: the triangles share an edge and overlap in the plane.
    TriangleMesh folded;
    folded.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5f, 0.5f, 0}};
    folded.indices = {0, 1, 2, 1, 0, 3};
    EXPECT_EQ(findSelfIntersections(folded).pairs, 0u);
    // Sharing only a vertex while crossing each other.
    TriangleMesh pinned;
    pinned.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, -1}, {1, 1, 1}};
    pinned.indices = {0, 1, 2, 0, 3, 4};
    EXPECT_EQ(findSelfIntersections(pinned).pairs, 0u);
}

TEST(MeshSelfIntersection, InterpenetratingCubes)
{
    // Cube B = cube A moved by (1, 0.6, 0.3): their surfaces cross on A's faces x = 1, y = 1,
    // z = 1 and B's faces x = 0, y = -0.4, z = -0.7. A's face x = -1 and B's face x = 2 are out
    // of reach. The result must equal an all-pairs check (the broad phase misses nothing).
    TriangleMesh mesh = makeCubeMesh(1.0f, 2);
    const std::size_t perCube = mesh.triangleCount();
    appendMesh(mesh, makeCubeMesh(1.0f, 2), glm::vec3(1.0f, 0.6f, 0.3f));
    const SelfIntersections s = findSelfIntersections(mesh);
    EXPECT_GT(s.pairs, 0u);
    std::size_t inA = 0, inB = 0;
    for (const std::uint32_t t : s.triangles) {
        (t < perCube ? inA : inB) += 1;
        glm::dvec3 v[3];
        detail::loadTriangle(mesh, t, v);
        if (t < perCube)
            EXPECT_FALSE(v[0].x == -1 && v[1].x == -1 && v[2].x == -1) << "triangle " << t;
        else
            EXPECT_FALSE(v[0].x == 2 && v[1].x == 2 && v[2].x == 2) << "triangle " << t;
    }
    EXPECT_GT(inA, 0u);
    EXPECT_GT(inB, 0u);
    std::size_t brute = 0;
    for (std::size_t a = 0; a < perCube; ++a)
        for (std::size_t b = perCube; b < mesh.triangleCount(); ++b) {
            glm::dvec3 p[3], q[3];
            detail::loadTriangle(mesh, a, p);
            detail::loadTriangle(mesh, b, q);
            brute += detail::testTrianglesIntersect(p, q);
        }
    EXPECT_EQ(s.pairs, brute);
}

// ---- Topology -----------------------------------------------------------------------------------

TEST(MeshTopology, TetrahedraTouchingAtAVertex)
{
    // Two closed tetrahedra sharing vertex 0: every edge has two triangles, but the triangles
    // around vertex 0 form two separate fans.
    TriangleMesh mesh;
    mesh.positions = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                      {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    mesh.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 0, 5, 4, 0, 4, 6, 0, 6, 5, 4, 5, 6};
    const MeshTopology t = analyzeTopology(mesh);
    EXPECT_EQ(t.nonManifoldVertices, 1u);
    EXPECT_EQ(t.nonManifoldEdges, 0u);
    EXPECT_EQ(t.boundaryEdges, 0u);
    EXPECT_TRUE(t.watertight());
    EXPECT_FALSE(t.manifold());

    EXPECT_EQ(analyzeTopology(makeCubeMesh(1.0f, 3)).nonManifoldVertices, 0u);
    // An open fan (boundary vertex with a single fan) is manifold.
    TriangleMesh fan;
    fan.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}};
    fan.indices = {0, 1, 2, 0, 2, 3};
    EXPECT_EQ(analyzeTopology(fan).nonManifoldVertices, 0u);
}

} // namespace
} // namespace rtlab::metrics
