#pragma once
// Mesh metrics against an analytic signed distance field, and topology counts.
//
// Conventions shared by every function here:
// - Distances are in world units, angles in degrees.
// - The SDF is negative inside. "Exact" results assume it is a true Euclidean distance; for a
//   bound (CSG blends, ellipsoids) |sdf| under-estimates the distance near the surface.
// - The SDF and gradient callables are called concurrently from several threads: they must be
//   safe to call at the same time (pure functions of the point).
// - Random sampling is deterministic: the same mesh, counts and seed give the same samples on
//   every machine and with any number of threads.
// - Vertices with identical positions are one point for the geometric metrics (sharp edges,
//   self-intersections); analyzeTopology works on indices only.

#include "core/mesh.h"

#include <glm/mat3x3.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace rtlab::metrics {

//! A scalar field of a point, for these metrics a signed distance in world units.
using ScalarField = std::function<double(const glm::dvec3&)>;
//! The gradient of a ScalarField (any length: it is normalised where a direction is needed).
using VectorField = std::function<glm::dvec3(const glm::dvec3&)>;

// ---- Topology ---------------------------------------------------------------------------------

struct MeshTopology {
    std::size_t vertices = 0;
    std::size_t triangles = 0;
    std::size_t edges = 0;              //!< undirected
    std::size_t boundaryEdges = 0;      //!< used by one triangle
    std::size_t nonManifoldEdges = 0;   //!< used by three or more triangles
    std::size_t inconsistentEdges = 0;  //!< two triangles traverse it in the same direction
    std::size_t degenerateTriangles = 0;  //!< repeated index or zero area
    //! Vertices whose incident triangles form more than one fan: grouping the triangles around
    //! the vertex by shared edges through it gives two or more groups (two cones touching at
    //! their apex, a bow tie). Triangles with a repeated index are ignored here. A vertex on a
    //! non-manifold edge is counted only if it also splits into several fans.
    std::size_t nonManifoldVertices = 0;
    long long eulerCharacteristic = 0;  //!< V - E + F
    bool watertight() const { return boundaryEdges == 0 && nonManifoldEdges == 0; }
    bool orientable() const { return inconsistentEdges == 0; }
    bool manifold() const { return nonManifoldEdges == 0 && nonManifoldVertices == 0; }
};

MeshTopology analyzeTopology(const TriangleMesh& mesh);

//! Distance of the mesh to the true surface, sampled at the vertices and at each triangle's
//! centroid: |sdf(p)| is the exact distance from p to the surface when sdf is a true distance.
struct SurfaceDeviation {
    double maxAbs = 0;   //!< world units (one-sided: mesh -> surface)
    double meanAbs = 0;  //!< world units
    double rms = 0;      //!< world units
    std::size_t samples = 0;
};

SurfaceDeviation measureSurfaceDeviation(const TriangleMesh& mesh,
                                         const std::function<double(const glm::dvec3&)>& sdf);

//! Volume enclosed by a closed, consistently oriented mesh (divergence theorem); positive when
//! triangles wind counter-clockwise seen from outside.
double computeEnclosedVolume(const TriangleMesh& mesh);

// ---- Sampling ---------------------------------------------------------------------------------

//! A point on a mesh triangle.
struct MeshSample {
    glm::dvec3 position{0.0};     //!< world units
    glm::dvec3 barycentric{0.0};  //!< weights of the triangle's three corners (sum 1)
    std::uint32_t triangle = 0;   //!< index of the triangle (indices[3t .. 3t+2])
};

//! `count` points uniformly distributed by area over the mesh. Stratified: sample i picks the
//! triangle at cumulative-area fraction (i + u_i) / count, then uniform barycentrics within it
//! (u and the barycentrics from a counter-based hash of seed and i). Zero-area triangles get no
//! samples; the result is empty when the mesh has no area.
std::vector<MeshSample> sampleMeshSurface(const TriangleMesh& mesh, std::size_t count,
                                          std::uint64_t seed = 1);

struct SdfSurfaceSampling {
    //! Candidates with |sdf| above this are rejected before projection (world units); 0 picks
    //! 1% of the box diagonal. Narrower bands are closer to area-uniform but accept fewer.
    double band = 0;
    //! A projected point is accepted when |sdf| <= tolerance (world units); 0 picks 1e-12 of
    //! the box diagonal.
    double tolerance = 0;
    int newtonIterations = 32;  //!< projection steps p -= sdf(p) g / |g|^2 before giving up
    //! Candidates tried before giving up on reaching `count`; 0 picks 4000 per requested point.
    std::size_t maxCandidates = 0;
};

//! Points on the zero set of `sdf`: candidates uniform in [boundsMin, boundsMax] that lie within
//! the band are projected onto the zero set by Newton steps along the gradient. For a true
//! distance the projection of a point is its closest surface point, so the result is
//! area-uniform up to a relative bias of order band x curvature, except near convex sharp edges
//! and corners, which also collect the candidates of the band's wedge outside them (a fraction
//! of order band / feature spacing). Returns `count` points, or fewer when maxCandidates ran
//! out. Deterministic (counter-based hash of seed and candidate index).
std::vector<glm::dvec3> sampleSdfSurface(const ScalarField& sdf, const VectorField& gradient,
                                         const glm::dvec3& boundsMin, const glm::dvec3& boundsMax,
                                         std::size_t count, std::uint64_t seed = 1,
                                         const SdfSurfaceSampling& options = {});

// ---- Two-sided distance -------------------------------------------------------------------------

//! Statistics of one direction's point-to-set distances (world units).
struct OneSidedDistance {
    double max = 0;
    double mean = 0;  //!< mean distance (L1)
    double rms = 0;   //!< root mean square distance (L2)
    std::size_t samples = 0;
};

struct MeshDistanceOptions {
    std::size_t meshSamples = 200000;  //!< area-uniform samples on the mesh (sampleMeshSurface)
    std::uint64_t seed = 1;
    double cellSize = 0;  //!< world units; fills the *Cells fields when positive
};

//! Two-sided distance between a mesh M and the zero set S of an SDF.
//! - meshToSurface: d(p, S) = |sdf(p)| at area-uniform samples p of M (exact for a true
//!   distance).
//! - surfaceToMesh: d(q, M) = Euclidean distance from each given point q of S to the closest
//!   point of M (exact closest point on the triangles, found with an Embree BVH point query).
//! - hausdorff = max(meshToSurface.max, surfaceToMesh.max).
//! - chamferMean = (meshToSurface.mean + surfaceToMesh.mean) / 2  (L1, world units).
//! - chamferRms = sqrt((meshToSurface.rms^2 + surfaceToMesh.rms^2) / 2)  (L2, world units).
//!   The "CD" of Neural Marching Cubes / Neural Dual Contouring (sum of the two mean squared
//!   distances, eval_cd_nc_f1_ecd_ef1.py in github.com/czq142857/NMC) is 2 chamferRms^2, except
//!   that they measure to the nearest point of a sample of the other surface, not to the surface.
//! A mesh without area has infinite distances. Throws rtlab::Error when surfacePoints is empty.
struct MeshDistance {
    OneSidedDistance meshToSurface;
    OneSidedDistance surfaceToMesh;
    double hausdorff = 0;
    double chamferMean = 0;
    double chamferRms = 0;
    double cellSize = 0;         //!< as given
    double hausdorffCells = 0;   //!< hausdorff / cellSize; NaN when cellSize <= 0
    double chamferMeanCells = 0; //!< chamferMean / cellSize; NaN when cellSize <= 0
    double chamferRmsCells = 0;  //!< chamferRms / cellSize; NaN when cellSize <= 0
};

MeshDistance measureMeshDistance(const TriangleMesh& mesh, const ScalarField& sdf,
                                 const std::vector<glm::dvec3>& surfacePoints,
                                 const MeshDistanceOptions& options = {});

// ---- Normal error -----------------------------------------------------------------------------

enum class MeshNormalSource {
    Face,          //!< the triangle's geometric normal, cross(b - a, c - a)
    Interpolated,  //!< barycentric blend of mesh.normals, renormalised
};

struct NormalErrorOptions {
    std::size_t samples = 200000;  //!< area-uniform samples on the mesh (sampleMeshSurface)
    std::uint64_t seed = 1;
    MeshNormalSource source = MeshNormalSource::Face;
};

//! Angle between the mesh normal and the SDF gradient, both evaluated at area-uniform sample
//! points of the mesh (for a true distance the gradient there is the normal of the closest
//! surface point). The angle is oriented, in [0, 180]: a flipped triangle reads 180. Samples
//! where either direction is zero or not finite are skipped and counted. Throws rtlab::Error
//! for Interpolated when mesh.normals does not have one normal per position.
struct NormalError {
    double meanDeg = 0;
    double rmsDeg = 0;
    double maxDeg = 0;
    std::size_t samples = 0;  //!< samples that entered the statistics
    std::size_t skipped = 0;
};

NormalError measureNormalError(const TriangleMesh& mesh, const VectorField& gradient,
                               const NormalErrorOptions& options = {});

// ---- Sharp features ---------------------------------------------------------------------------

//! A straight piece of a feature curve (world units).
struct FeatureSegment {
    glm::dvec3 a{0.0};
    glm::dvec3 b{0.0};
};

//! The 12 edges of the box {center + rotation * x : |x_i| <= halfExtent_i}; the columns of
//! `rotation` are the box axes (orthonormal).
std::vector<FeatureSegment> makeBoxFeatureEdges(const glm::dvec3& center,
                                                const glm::dvec3& halfExtent,
                                                const glm::dmat3& rotation = glm::dmat3(1.0));

//! Mesh edges whose crease angle exceeds minCreaseDeg. The crease angle of an edge shared by two
//! triangles is the angle between their unit normals, with one normal flipped if the two
//! traverse the edge in the same direction (0 on a flat surface, 90 on a cube edge; it is
//! 180 - the interior dihedral angle). Vertices are merged by position first. Boundary edges,
//! and edges next to a zero-area triangle, are never sharp; edges with three or more triangles
//! are always sharp.
std::vector<FeatureSegment> extractSharpEdges(const TriangleMesh& mesh,
                                              double minCreaseDeg = 30.0);

struct SharpFeatureOptions {
    double minCreaseDeg = 30.0;  //!< see extractSharpEdges
    double tolerance = 0;        //!< tau of edge-F1, world units; must be positive
    double sampleSpacing = 0;    //!< arc length between edge samples; 0 picks tolerance / 4
};

//! Sharp-feature accuracy of a mesh against the true feature curves F. Let E be the mesh's sharp
//! edges (extractSharpEdges). Both E and F are sampled uniformly by arc length (each segment cut
//! into ceil(length / sampleSpacing) equal pieces, one sample at each piece's midpoint); the
//! distance of a sample to the other set is the exact distance to its nearest segment.
//! - edgeChamfer = (meshToFeature + featureToMesh) / 2: means of those distances (L1).
//! - precision = fraction of E's samples at distance <= tolerance from F; recall = fraction of
//!   F's samples at distance <= tolerance from E; f1 = 2 P R / (P + R), 0 when P + R = 0.
//! These follow ECD / EF1 of Neural Marching Cubes (Chen & Zhang 2021) and Neural Dual
//! Contouring (2022), eval_cd_nc_f1_ecd_ef1.py in github.com/czq142857/NMC, with two changes:
//! edges come from the mesh's crease angles and the analytic feature curves instead of from
//! normal discontinuities among surface point samples, and edgeChamfer averages distances
//! where theirs sums mean squared distances (edgeChamferSquared gives that form).
//! Empty sets: the fraction over an empty set is 1 (nothing is missing or spurious), and a mean
//! distance to an empty set is infinite. So a smooth mesh against real features has recall 0,
//! precision 1, f1 0 and infinite edgeChamfer; a smooth mesh against no features scores f1 1
//! and edgeChamfer 0.
struct SharpFeatureScore {
    std::size_t meshEdges = 0;        //!< sharp mesh edges
    double meshEdgeLength = 0;        //!< their total length, world units
    double featureLength = 0;         //!< total length of the features, world units
    std::size_t meshSamples = 0;
    std::size_t featureSamples = 0;
    double meshToFeature = 0;         //!< mean distance, world units
    double featureToMesh = 0;         //!< mean distance, world units
    double edgeChamfer = 0;           //!< world units
    double edgeChamferSquared = 0;    //!< sum of the two mean squared distances, world units^2
    double precision = 1;
    double recall = 1;
    double f1 = 1;
};

SharpFeatureScore measureSharpFeatures(const TriangleMesh& mesh,
                                       const std::vector<FeatureSegment>& features,
                                       const SharpFeatureOptions& options);

// ---- Triangle quality -------------------------------------------------------------------------

//! Interior angles of all non-degenerate triangles (three each). Bin i counts the angles in
//! [i w, (i + 1) w), w = 180 / bins, the last bin including 180. An angle within 1e-3 degrees
//! below a bin edge is counted above it, so that exact angles computed from float coordinates
//! (the 60 of an equilateral triangle, the 90 of a grid) land in the bin they start. Slivers
//! are angles below sliverDeg, with the same rule.
struct TriangleAngleHistogram {
    std::vector<std::size_t> counts;
    double binWidthDeg = 0;
    std::size_t angles = 0;             //!< 3 x non-degenerate triangles
    std::size_t degenerateTriangles = 0;  //!< repeated index or zero area: not in the histogram
    double minAngleDeg = 0;             //!< NaN when there are no angles
    double maxAngleDeg = 0;             //!< NaN when there are no angles
    double sliverDeg = 0;               //!< as given
    std::size_t slivers = 0;            //!< angles below sliverDeg
    double sliverFraction = 0;          //!< slivers / angles; NaN when there are no angles
};

TriangleAngleHistogram computeTriangleAngleHistogram(const TriangleMesh& mesh, int bins = 18,
                                                     double sliverDeg = 10.0);

// ---- Self-intersections -----------------------------------------------------------------------

//! Pairs of triangles that share no vertex (after merging vertices by position) and intersect,
//! touching included (up to double rounding), found with Embree's BVH collision (rtcCollide on
//! bounding boxes) and a separating-axis test in double precision (the 2 face normals, the 9
//! edge-edge cross products and the 6 in-plane edge normals). Triangles sharing a vertex or an
//! edge are never counted, even when they fold over each other, nor are triangles with a
//! repeated (merged) vertex.
struct SelfIntersections {
    std::size_t pairs = 0;                 //!< intersecting triangle pairs
    std::vector<std::uint32_t> triangles;  //!< every triangle in some pair, ascending
    std::size_t candidatePairs = 0;        //!< pairs the broad phase passed on (boxes may overlap)
};

SelfIntersections findSelfIntersections(const TriangleMesh& mesh);

} // namespace rtlab::metrics
