// The hierarchical SDF evaluator's culling: samples of evaluated leaves proven out of the band
// (Lipschitz balls and chains, the culled siblings' faces, the convex bounds of one convex
// primitive) with values still bit-identical to brute force, and the culling rate on the gallery
// and the landscape.

#include "evaluator_test_support.h"

#include <glm/geometric.hpp>

using namespace rtlab;
using namespace rtlab::sdf;
using namespace rtlab::sdf::testing;

TEST(SdfEvaluator, LeafSamplesOutOfTheBandsReachAreSkippedOnlyForLipschitzFields)
{
    // 96 samples per axis: every leaf is a whole 4^3 block, so a leaf evaluated in full costs
    // exactly 64 sample evaluations.
    const GridSpec grid = makeCubeGrid(-1.0, 1.0, 96);
    SdfModel sphere;
    sphere.name = "sphere";
    CsgEdit e;
    e.shape = CsgShape::Sphere;
    e.size = glm::dvec3(0.7);
    sphere.edits.push_back(e);
    // A sphere is an exact distance: inside its evaluated leaves, samples more than one spacing
    // past the band from an evaluated neighbour are known to be clamped and are not evaluated;
    // the field stays bit-identical to brute force, with a thin and a wide band.
    for (const double bandCells : {0.5, 2.0}) {
        EvaluationOptions o;
        o.bandCells = bandCells;
        o.computeHermite = false;
        const EvaluationResult r = evaluateModel(sphere, grid, kAllFrames, o);
        EXPECT_LT(r.stats.samplesEvaluated, r.stats.leavesEvaluated * 64) << bandCells;
        EXPECT_GE(r.stats.samplesEvaluated, r.stats.samplesInBand) << bandCells;
        expectMatchesBruteForce(sphere, grid, kAllFrames, o, "band " + std::to_string(bandCells));
    }
    // An ellipsoid's value is not 1-Lipschitz: by default every sample of its evaluated leaves
    // is evaluated. Its gradient has a bound over each leaf (boundLipschitzConstant: 1 plus a
    // term that vanishes at its surface): with ellipsoidGradientBound its leaves skip samples
    // too, with the distances scaled by it, and stay bit-identical. A sphere with a rotation that is not a
    // unit quaternion has no bound known (boundPrimitive and boundLipschitzConstant give up on
    // it, whatever the quaternion does to points): every sample of an evaluated leaf is evaluated.
    SdfModel ellipsoid = sphere;
    ellipsoid.edits[0].shape = CsgShape::Ellipsoid;
    ellipsoid.edits[0].size = glm::dvec3(0.7, 0.3, 0.5);
    EvaluationOptions o;
    o.computeHermite = false;
    const EvaluationResult full = evaluateModel(ellipsoid, grid, kAllFrames, o);
    EXPECT_GT(full.stats.leavesEvaluated, 0u);
    EXPECT_EQ(full.stats.samplesEvaluated, full.stats.leavesEvaluated * 64);
    expectMatchesBruteForce(ellipsoid, grid, kAllFrames, o, "ellipsoid");
    EvaluationOptions bounded = o;
    bounded.ellipsoidGradientBound = true;
    const EvaluationResult r = evaluateModel(ellipsoid, grid, kAllFrames, bounded);
    EXPECT_EQ(r.stats.leavesEvaluated, full.stats.leavesEvaluated);
    EXPECT_LT(r.stats.samplesEvaluated, r.stats.leavesEvaluated * 64);
    EXPECT_GE(r.stats.samplesEvaluated, r.stats.samplesInBand);
    expectMatchesBruteForce(ellipsoid, grid, kAllFrames, bounded, "ellipsoid, gradient bound");
    SdfModel scaled = sphere;
    scaled.edits[0].rotation = glm::dquat(1.5, 0.0, 0.0, 0.0);
    const EvaluationResult u = evaluateModel(scaled, grid, kAllFrames, bounded);
    EXPECT_GT(u.stats.leavesEvaluated, 0u);
    EXPECT_EQ(u.stats.samplesEvaluated, u.stats.leavesEvaluated * 64);
    expectMatchesBruteForce(scaled, grid, kAllFrames, bounded, "non-unit rotation");
}

TEST(SdfEvaluator, LeavesProveTheirOutOfBandSamplesWhicheverSideTheSurfaceFaces)
{
    // A slab |z - c| <= 0.2 seen through its top face and, mirrored, through its bottom face. A
    // face parallel to the grid cuts its leaves so that a layer just past the band's edge falls
    // into an evaluated leaf. Inside an evaluated leaf the samples out of the band are proven by
    // the bounds of the culled siblings on their shared faces (one spacing in), by the corners'
    // balls, and by neighbours one spacing back along a sweep that runs away from the corners
    // farther from the surface. Measured on this grid: 1 sample per leaf evaluated out of the band
    // on both faces; 4 through one face with a sweep fixed to +z (it chains its bounds outward
    // there), 11 on both without the siblings' bounds.
    const GridSpec grid = makeCubeGrid(-1.0, 1.0, 96);
    for (const double centre : {0.31, -0.31}) {
        SdfModel slab;
        slab.name = "slab";
        CsgEdit e;
        e.shape = CsgShape::Box;
        e.center = glm::dvec3(0.0, 0.0, centre);
        e.size = glm::dvec3(3.0, 3.0, 0.2);
        slab.edits.push_back(e);
        for (const bool hermite : {false, true}) {
            EvaluationOptions o;
            o.computeHermite = hermite;
            const EvaluationResult r = evaluateModel(slab, grid, kAllFrames, o);
            ASSERT_GT(r.stats.leavesEvaluated, 0u);
            // With Hermite data a cell's box reaches one sample past its upper faces (its list
            // must be exact on the edges leaving it), so leaves whose own samples all lie past
            // the band but whose boxes reach into it are evaluated too: the bound is for values
            // only.
            if (!hermite) {
                EXPECT_LE(r.stats.samplesEvaluated - r.stats.samplesInBand,
                          2 * r.stats.leavesEvaluated)
                    << centre;
            }
            expectMatchesBruteForce(slab, grid, kAllFrames, o, "slab at " + std::to_string(centre));
        }
    }
}

TEST(SdfEvaluator, ConvexPrimitivesProveTheirInsideSamplesByTheirCorners)
{
    // One convex primitive (exact distance) tilted against the grid: its field is convex, so a
    // leaf's samples lie below the trilinear interpolation of its corner values (proving samples
    // inside a tilted face) and above the line through two exact samples behind them along a
    // sweep (outside it), where the Lipschitz bounds leave them to evaluation. Values stay
    // bit-identical to brute force. Samples evaluated out of the band on this grid, without the
    // convex bounds, with the corners' bound alone, and with both: box 13,832 / 10,867 / 10,396,
    // rounded box 12,791 / 10,064 / 9,633, cylinder 13,046 / 10,341 / 9,850, cone 8,847 / 7,178 /
    // 6,806, capsule 8,109 / 6,618 / 6,290, sphere 13,827 / 10,926 / 10,357 (0.75-0.78x with
    // both). The expectation, at most 0.9x the count without them, fails if the corners' bound
    // stops proving and leaves room for small changes of the other bounds.
    const GridSpec grid = makeCubeGrid(-1.0, 1.0, 96);
    const glm::dquat tilt = glm::angleAxis(0.52, glm::normalize(glm::dvec3(1, 1, 0))) *
                            glm::angleAxis(0.35, glm::dvec3(0, 0, 1));
    struct Case {
        CsgShape shape;
        glm::dvec3 size;
        double rounding;
        std::uint64_t outOfBandWithout; // measured without the corners' bound
    };
    const Case cases[] = {
        {CsgShape::Box, glm::dvec3(0.45, 0.5, 0.4), 0.0, 13832},
        {CsgShape::RoundedBox, glm::dvec3(0.45, 0.5, 0.4), 0.1, 12791},
        {CsgShape::Cylinder, glm::dvec3(0.45, 0.55, 0.0), 0.0, 13046},
        {CsgShape::Cone, glm::dvec3(0.5, 0.6, 0.0), 0.0, 8847},
        {CsgShape::Capsule, glm::dvec3(0.3, 0.4, 0.0), 0.0, 8109},
        {CsgShape::Sphere, glm::dvec3(0.6), 0.0, 13827},
    };
    for (const Case& c : cases) {
        SdfModel m;
        m.name = scene::toString(c.shape);
        CsgEdit e;
        e.shape = c.shape;
        e.size = c.size;
        e.rounding = c.rounding;
        e.rotation = tilt;
        e.center = glm::dvec3(0.03, -0.02, 0.01);
        m.edits.push_back(e);
        EvaluationOptions o;
        o.computeHermite = false;
        const EvaluationResult r = evaluateModel(m, grid, kAllFrames, o);
        ASSERT_GE(r.stats.samplesEvaluated, r.stats.samplesInBand) << m.name;
        EXPECT_LE(double(r.stats.samplesEvaluated - r.stats.samplesInBand),
                  0.9 * double(c.outOfBandWithout))
            << m.name;
        expectMatchesBruteForce(m, grid, kAllFrames, o, m.name);
        // With Hermite data (the cells' lists exact one sample further) too.
        o.computeHermite = true;
        expectMatchesBruteForce(m, grid, kAllFrames, o, m.name + ", Hermite");
    }
    // A torus is not convex and the subtraction of a convex shape is concave: the bound is not
    // used there, and the values stay exact.
    SdfModel torus;
    torus.name = "torus";
    CsgEdit t;
    t.shape = CsgShape::Torus;
    t.size = glm::dvec3(0.5, 0.2, 0.0);
    t.rotation = tilt;
    torus.edits.push_back(t);
    expectMatchesBruteForce(torus, grid, kAllFrames, {}, "torus");
    SdfModel hollow = torus;
    hollow.name = "box minus sphere";
    hollow.edits[0].shape = CsgShape::Box;
    hollow.edits[0].size = glm::dvec3(0.7);
    CsgEdit hole;
    hole.shape = CsgShape::Sphere;
    hole.op = CsgOp::Subtract;
    hole.size = glm::dvec3(0.5);
    hollow.edits.push_back(hole);
    expectMatchesBruteForce(hollow, grid, kAllFrames, {}, "box minus sphere");
}

TEST(SdfEvaluator, CullingRateOnGalleryAt128)
{
    // Measured at 128 samples per side (band 2 cells, leaves of 4^3, bound evaluations counted
    // as work): 0.856 (cube) to 0.955 (thin_wall) on the gallery, 0.94 on the landscape. Most of
    // each grid is proven empty or full at coarse levels; what is evaluated is the shell of
    // leaves around the surface, about 6 cells thick on each side. 0.75 (0.85 for the landscape)
    // leaves room for small changes of the bounds and still fails if a level stops culling.
    for (const SdfModel& m : getGallery()) {
        EvaluationOptions o;
        o.computeHermite = false;
        const EvaluationResult r = evaluateModel(m, makeModelGrid(m, 128), kAllFrames, o);
        EXPECT_GE(r.stats.getCullingRate(), 0.75) << m.name;
        // No exact evaluator evaluates fewer primitives than there are samples in the band.
        EXPECT_LE(r.stats.getCullingRate(), r.stats.getIdealCullingRate()) << m.name;
        EXPECT_LT(r.stats.getIdealCullingRate(), 1.0) << m.name;
        EXPECT_LE(r.stats.samplesInBand, r.stats.samplesEvaluated) << m.name;
        std::uint64_t proven = 0;
        for (std::size_t l = 0; l < r.stats.cellsEmpty.size(); ++l)
            proven += r.stats.cellsEmpty[l] + r.stats.cellsFull[l];
        EXPECT_GT(proven, 0u) << m.name;
    }
    EvaluationOptions o;
    o.computeHermite = false;
    const EvaluationResult land =
        evaluateModel(getLandscape(), makeModelGrid(getLandscape(), 128), kAllFrames, o);
    EXPECT_GE(land.stats.getCullingRate(), 0.85);
    EXPECT_LE(land.stats.getCullingRate(), land.stats.getIdealCullingRate());
}
