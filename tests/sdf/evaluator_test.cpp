// The hierarchical SDF evaluator against brute force (SdfModel::evaluate at every sample): values
// bit-identical in the band and clamped with the right sign outside it, on the CSG gallery, the
// Tomorrow Town landscape over its frames and random edit lists; Hermite crossings within the
// stated precision with unit normals; thread-count independence; degenerate inputs. The culling
// tests are in evaluator_culling_test.cpp.

#include "evaluator_test_support.h"
#include "sdf/edit_ops.h"
#include "sdf/primitive_bounds.h"

#include <glm/geometric.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

using namespace rtlab;
using namespace rtlab::sdf;
using namespace rtlab::sdf::testing;

namespace {

// Sign-change edges of a field, by definition (inside when <= 0).
std::size_t countSignChanges(const SampledField& f)
{
    std::size_t n = 0;
    for (int z = 0; z < f.samples.z; ++z)
        for (int y = 0; y < f.samples.y; ++y)
            for (int x = 0; x < f.samples.x; ++x) {
                const bool in = f.at(x, y, z) <= 0.0f;
                if (x + 1 < f.samples.x && (f.at(x + 1, y, z) <= 0.0f) != in) ++n;
                if (y + 1 < f.samples.y && (f.at(x, y + 1, z) <= 0.0f) != in) ++n;
                if (z + 1 < f.samples.z && (f.at(x, y, z + 1) <= 0.0f) != in) ++n;
            }
    return n;
}

void expectSameHermite(const HermiteData& a, const HermiteData& b, const std::string& what)
{
    ASSERT_EQ(a.edges.size(), b.edges.size()) << what;
    std::size_t different = 0;
    for (std::size_t i = 0; i < a.edges.size(); ++i) {
        const auto& x = a.edges[i];
        const auto& y = b.edges[i];
        if (x.sample != y.sample || x.axis != y.axis || !isSameDouble(x.t, y.t) ||
            !isSameDouble(x.normal.x, y.normal.x) || !isSameDouble(x.normal.y, y.normal.y) ||
            !isSameDouble(x.normal.z, y.normal.z))
            ++different;
    }
    EXPECT_EQ(different, 0u) << what;
}

} // namespace

TEST(SdfEvaluator, GalleryModelsMatchBruteForce)
{
    for (const SdfModel& m : getGallery())
        for (int samples : {20, 37, 64})
            expectMatchesBruteForce(m, makeModelGrid(m, samples), kAllFrames);
}

TEST(SdfEvaluator, LandscapeMatchesBruteForceOverFrames)
{
    const SdfModel& land = getLandscape();
    ASSERT_FALSE(land.edits.empty());
    EvaluationOptions bounded;
    bounded.ellipsoidGradientBound = true;
    for (int frame : {0, 2, 3, 5, 7}) {
        expectMatchesBruteForce(land, makeModelGrid(land, 56), frame);
        expectMatchesBruteForce(land, makeModelGrid(land, 56), frame, bounded, "gradient bound");
    }
    expectMatchesBruteForce(land, makeModelGrid(land, 100), 7);
    expectMatchesBruteForce(land, makeModelGrid(land, 100), 7, bounded, "gradient bound");
}

TEST(SdfEvaluator, OptionsKeepValuesExact)
{
    const SdfModel& land = getLandscape();
    for (int leaf : {1, 2, 3, 8})
        for (double bandCells : {0.5, 2.0, 6.0}) {
            EvaluationOptions o;
            o.leafSamples = leaf;
            o.bandCells = bandCells;
            o.computeHermite = leaf % 2 == 0;
            o.ellipsoidGradientBound = leaf != 3; // the landscape's hills are ellipsoids
            expectMatchesBruteForce(land, makeModelGrid(land, 44), 7, o,
                                    "leaf " + std::to_string(leaf) + " band " + std::to_string(bandCells));
        }
}

TEST(SdfEvaluator, RandomEditListsMatchBruteForce)
{
    for (unsigned seed = 1; seed <= 24; ++seed) {
        const SdfModel m = makeRandomModel(seed, 8 + int(seed % 5) * 6);
        expectMatchesBruteForce(m, makeCubeGrid(-1.2, 1.2, 33 + int(seed % 3) * 7), kAllFrames);
        expectMatchesBruteForce(m, makeCubeGrid(-1.2, 1.2, 29), 1);
    }
}

TEST(SdfEvaluator, AnisotropicEllipsoidsMatchBruteForce)
{
    // The ellipsoid's value is only a distance bound and is not 1-Lipschitz; its culling uses
    // interval arithmetic and, inside a leaf, its gradient bound (primitive_bounds.h). Thin
    // ellipsoids are the hard case.
    for (unsigned seed = 100; seed < 112; ++seed) {
        SdfModel m = makeRandomModel(seed, 12, 12.0);
        for (auto& e : m.edits)
            e.shape = CsgShape::Ellipsoid;
        for (bool gradientBound : {false, true}) {
            EvaluationOptions o;
            o.ellipsoidGradientBound = gradientBound;
            expectMatchesBruteForce(m, makeCubeGrid(-1.5, 1.5, 41), kAllFrames, o,
                                    gradientBound ? "gradient bound" : "");
        }
    }
}

TEST(SdfEvaluator, PrimitiveBoundsContainValues)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 2000; ++trial) {
        SdfModel m = makeRandomModel(1000 + trial, 1, trial % 2 ? 10.0 : 2.0);
        CsgEdit e = m.edits[0];
        e.shape = CsgShape(trial % 8);
        const double halfSize = std::pow(10.0, -2.0 + 2.5 * u(rng));
        const glm::dvec3 c = glm::dvec3(u(rng), u(rng), u(rng)) * 3.0 - 1.5;
        const glm::dvec3 lo = c - halfSize * glm::dvec3(u(rng), u(rng), u(rng));
        const glm::dvec3 hi = c + halfSize * glm::dvec3(u(rng), u(rng), u(rng));
        // A margin of 1e-12 (coordinates are O(1)) for rounding, as the evaluator's 1e-10 x scale.
        const Interval b = boundPrimitive(e, lo, hi, 1e-12);
        ASSERT_LE(b.lo, b.hi);
        for (int k = 0; k < 100; ++k) {
            glm::dvec3 t(u(rng), u(rng), u(rng));
            if (k < 8)
                t = glm::dvec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
            const double v = e.evaluatePrimitive(lo + (hi - lo) * t);
            ASSERT_TRUE(v >= b.lo && v <= b.hi)
                << scene::toString(e.shape) << " trial " << trial << " value " << v << " bound ["
                << b.lo << ", " << b.hi << "]";
        }
    }
}

TEST(SdfEvaluator, PrimitiveGradientBoundsHoldBetweenPointsOfTheBox)
{
    // |f(p) - f(q)| <= L |p - q| for p, q in the box, L = boundLipschitzConstant: what a leaf's
    // proofs rely on. Ellipsoids of aspect up to 100 with random rotations, boxes from 1e-3 to 3
    // wide anywhere around them, the pairs including the box's corners. The 1e-12 covers the
    // rounding of two values of size O(10).
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int bounded = 0;
    double steepest = 0.0; // the largest |f(p) - f(q)| / (L |p - q|) seen
    for (int trial = 0; trial < 3000; ++trial) {
        SdfModel m = makeRandomModel(5000 + trial, 1, 2.0);
        CsgEdit e = m.edits[0];
        e.shape = trial % 4 == 0 ? CsgShape(trial / 4 % 8) : CsgShape::Ellipsoid;
        if (e.shape == CsgShape::Ellipsoid)
            e.size = glm::dvec3(std::pow(10.0, -1.0 + 2.0 * u(rng)),
                                std::pow(10.0, -1.0 + 2.0 * u(rng)), 0.1 + u(rng));
        const double halfSize = std::pow(10.0, -3.0 + 3.5 * u(rng));
        const glm::dvec3 c = e.center + (glm::dvec3(u(rng), u(rng), u(rng)) * 2.0 - 1.0) * 2.5;
        const glm::dvec3 lo = c - halfSize * glm::dvec3(u(rng), u(rng), u(rng));
        const glm::dvec3 hi = c + halfSize * glm::dvec3(u(rng), u(rng), u(rng));
        const double l = boundLipschitzConstant(e, lo, hi);
        ASSERT_GE(l, 1.0);
        if (e.shape != CsgShape::Ellipsoid) {
            EXPECT_EQ(l, 1.0) << scene::toString(e.shape);
            continue;
        }
        if (!(l < std::numeric_limits<double>::infinity()))
            continue; // the box reaches the centre
        ++bounded;
        for (int k = 0; k < 64; ++k) {
            glm::dvec3 t(u(rng), u(rng), u(rng)), t2(u(rng), u(rng), u(rng));
            if (k < 8)
                t = glm::dvec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
            const glm::dvec3 p = lo + (hi - lo) * t;
            glm::dvec3 q = lo + (hi - lo) * t2;
            if (k >= 32) {
                // A short step along the gradient: the steepest pair, where the bound is tight.
                const double h = 1e-7 * (1.0 + glm::length(p));
                glm::dvec3 g;
                for (int a = 0; a < 3; ++a) {
                    glm::dvec3 d(0.0);
                    d[a] = h;
                    g[a] = e.evaluatePrimitive(p + d) - e.evaluatePrimitive(p - d);
                }
                q = glm::clamp(p + 1e-3 * halfSize * glm::normalize(g), lo, hi);
            }
            const double change = std::abs(e.evaluatePrimitive(p) - e.evaluatePrimitive(q));
            const double distance = glm::length(p - q);
            ASSERT_LE(change, l * distance + 1e-12)
                << "trial " << trial << " L " << l << " size " << e.size.x << " " << e.size.y << " "
                << e.size.z;
            if (distance > 1e-6)
                steepest = std::max(steepest, change / (l * distance));
        }
    }
    EXPECT_GT(bounded, 1000);
    // The bound is attained: some pair comes within 5 % of it (measured 0.95-0.97; near the
    // surface, where the bound is 1 + a little). Its second term is looser away from the
    // surface: the largest |grad rho| k0 over directions is 0.39-0.46 of R^2 - 1 for aspect
    // ratios 1.1-100 (maximised over the two-axis weightings), which costs the landscape
    // 0.04 points of culling at 256.
    EXPECT_GT(steepest, 0.95);
    // Near the surface of a nearly round ellipsoid the bound is nearly 1 (what makes it useful),
    // and a box around the centre has none.
    CsgEdit e;
    e.shape = CsgShape::Ellipsoid;
    e.size = glm::dvec3(1.0, 1.0, 1.1);
    EXPECT_LT(
        boundLipschitzConstant(e, glm::dvec3(0.95, -0.05, -0.05), glm::dvec3(1.05, 0.05, 0.05)),
        1.03);
    EXPECT_EQ(boundLipschitzConstant(e, glm::dvec3(-0.1), glm::dvec3(0.1)),
              std::numeric_limits<double>::infinity());
}

TEST(SdfEvaluator, AnOpSkippedAtASampleLeavesItsValueBitIdentical)
{
    // isUnchangedBy: where it lets a sample skip an op, applying the op to any value s in the op's
    // bound [lo, hi] returns the running value d, every bit; and it does skip where the op is
    // far on the losing side. Values near the blend radius, hard (k = 0) and soft blends, d of
    // both signs, +inf (an empty list so far).
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-3.0, 3.0);
    scene::CsgEdit edit;
    std::uint64_t skipped = 0, tried = 0;
    for (int trial = 0; trial < 200000; ++trial) {
        edit.blend = trial % 3 == 0 ? 0.0 : std::abs(u(rng)) * 0.5;
        const detail::OpKind kind = detail::OpKind(trial % 3); // Add, Subtract, Intersect
        const double lo = u(rng), hi = lo + std::abs(u(rng)) * 0.5;
        const double d = trial % 101 == 0 ? std::numeric_limits<double>::infinity() : u(rng);
        const detail::Op op{&edit, kind, lo, hi};
        ++tried;
        if (!detail::isUnchangedBy(op, d, 1e-12))
            continue;
        ++skipped;
        for (double t : {0.0, 0.25, 0.5, 1.0}) {
            const double s = t == 1.0 ? hi : lo + t * (hi - lo);
            const double v = detail::applyOp(kind, d, s, edit.blend);
            ASSERT_EQ(std::memcmp(&v, &d, sizeof v), 0)
                << "kind " << int(kind) << " d " << d << " s " << s << " k " << edit.blend;
        }
    }
    EXPECT_GT(skipped, tried / 10);
    EXPECT_LT(skipped, tried);
}

TEST(SdfEvaluator, OutputIndependentOfThreadCount)
{
    const SdfModel& land = getLandscape();
    const SdfModel random = makeRandomModel(5, 30);
    for (const SdfModel* m : {&land, &random}) {
        const GridSpec g = m == &land ? makeModelGrid(land, 72) : makeCubeGrid(-1.2, 1.2, 60);
        EvaluationOptions o;
        o.computeMaterials = true;
        o.keepExactValues = true;
        o.threadCount = 1;
        const EvaluationResult one = evaluateModel(*m, g, kAllFrames, o);
        for (int threads : {2, 3, 0}) {
            o.threadCount = threads;
            const EvaluationResult r = evaluateModel(*m, g, kAllFrames, o);
            const std::string what = m->name + " threads " + std::to_string(threads);
            EXPECT_EQ(std::memcmp(one.field.values.data(), r.field.values.data(),
                                  r.field.values.size() * sizeof(float)), 0) << what;
            EXPECT_EQ(one.materials, r.materials) << what;
            EXPECT_EQ(std::memcmp(one.exactValues.data(), r.exactValues.data(),
                                  r.exactValues.size() * sizeof(double)), 0) << what;
            expectSameHermite(one.hermite, r.hermite, what);
            EXPECT_EQ(one.stats.sampleEvaluations, r.stats.sampleEvaluations) << what;
            EXPECT_EQ(one.stats.boundEvaluations, r.stats.boundEvaluations) << what;
            EXPECT_EQ(one.stats.hermiteEvaluations, r.stats.hermiteEvaluations) << what;
            EXPECT_EQ(one.stats.cellsEmpty, r.stats.cellsEmpty) << what;
            EXPECT_EQ(one.stats.cellsFull, r.stats.cellsFull) << what;
        }
    }
}

TEST(SdfEvaluator, HermiteMatchesBruteForceAndSignChanges)
{
    // Same pruned values -> same root-finding steps: the crossings and normals are bit-identical
    // to those computed on the full edit list, and there is one per sign-changing edge.
    std::vector<std::pair<SdfModel, GridSpec>> cases;
    for (const SdfModel& m : getGallery())
        cases.push_back({m, makeModelGrid(m, 40)});
    cases.push_back({getLandscape(), makeModelGrid(getLandscape(), 64)});
    cases.push_back({makeRandomModel(11, 25), makeCubeGrid(-1.2, 1.2, 48)});
    for (const auto& [m, g] : cases) {
        const EvaluationResult h = evaluateModel(m, g);
        const EvaluationResult b = evaluateModelBruteForce(m, g);
        EXPECT_EQ(std::memcmp(h.field.values.data(), b.field.values.data(),
                              h.field.values.size() * sizeof(float)), 0) << m.name;
        expectSameHermite(h.hermite, b.hermite, m.name);
        EXPECT_EQ(h.hermite.edges.size(), countSignChanges(h.field)) << m.name;
        // (The 4 cm thin wall can fall between samples at this spacing.)
        if (m.name != "thin_wall") {
            EXPECT_GT(h.hermite.edges.size(), 0u) << m.name;
        }
        EXPECT_EQ(h.hermite.samples, g.samples);
        EXPECT_DOUBLE_EQ(h.hermite.precision, 1e-6 * g.spacing);
        for (const auto& e : h.hermite.edges) {
            glm::ivec3 n = e.sample;
            n[e.axis] += 1;
            ASSERT_NE(h.field.at(e.sample.x, e.sample.y, e.sample.z) <= 0.0f, h.field.at(n.x, n.y, n.z) <= 0.0f);
            ASSERT_EQ(h.hermite.find(e.sample, e.axis), &e);
        }
    }
}

TEST(SdfEvaluator, HermiteCrossingsWithinPrecisionAndNormalsMatchGradient)
{
    std::vector<std::pair<SdfModel, GridSpec>> cases;
    for (const SdfModel& m : getGallery())
        cases.push_back({m, makeModelGrid(m, 33)});
    cases.push_back({getLandscape(), makeModelGrid(getLandscape(), 64)});
    cases.push_back({makeRandomModel(12, 20), makeCubeGrid(-1.2, 1.2, 40)});
    std::size_t checked = 0, singleRoot = 0, smooth = 0;
    for (const auto& [m, g] : cases) {
        const EvaluationResult r = evaluateModel(m, g);
        const double precision = r.hermite.precision;
        const double hs = 1e-4 * g.spacing;
        for (const auto& e : r.hermite.edges) {
            glm::ivec3 ns = e.sample;
            ns[e.axis] += 1;
            const glm::dvec3 p0 = r.field.position(e.sample.x, e.sample.y, e.sample.z);
            const glm::dvec3 p1 = r.field.position(ns.x, ns.y, ns.z);
            auto f = [&](double t) { return m.evaluate(p0 + (p1 - p0) * t); };
            ++checked;
            // A reference crossing by 80 bisection steps, where the edge has one sign change.
            bool single = true;
            const bool in0 = f(0.0) <= 0.0;
            int changes = 0;
            bool prev = in0;
            for (int k = 1; k <= 64; ++k) {
                const bool in = f(k / 64.0) <= 0.0;
                changes += in != prev ? 1 : 0;
                prev = in;
            }
            single = changes == 1;
            if (single) {
                ++singleRoot;
                double a = 0.0, b = 1.0;
                for (int k = 0; k < 80; ++k) {
                    const double mid = 0.5 * (a + b);
                    ((f(mid) <= 0.0) == in0 ? a : b) = mid;
                }
                EXPECT_LE(std::abs(e.t - 0.5 * (a + b)) * g.spacing, precision * (1.0 + 1e-9))
                    << m.name << " edge " << e.sample.x << "," << e.sample.y << "," << e.sample.z
                    << " axis " << e.axis;
            }
            // Wherever it is: a sign change within `precision` of t.
            const double dt = precision / g.spacing;
            EXPECT_NE((f(std::max(0.0, e.t - dt)) <= 0.0), (f(std::min(1.0, e.t + dt)) <= 0.0))
                << m.name;
            // Normals: unit, and along the field's central-difference gradient where the field
            // is smooth (its one-sided differences agree); at CSG kinks they follow one side.
            const double len = glm::length(e.normal);
            if (len == 0.0)
                continue;
            EXPECT_NEAR(len, 1.0, 1e-12);
            const glm::dvec3 p = p0 + (p1 - p0) * e.t;
            const double v = m.evaluate(p);
            glm::dvec3 gc(0.0), gf(0.0), gb(0.0);
            for (int i = 0; i < 3; ++i) {
                glm::dvec3 d(0.0);
                d[i] = hs;
                const double fp = m.evaluate(p + d), fm = m.evaluate(p - d);
                gc[i] = fp - fm;
                gf[i] = fp - v;
                gb[i] = v - fm;
            }
            if (glm::dot(glm::normalize(gf), glm::normalize(gb)) < 0.9999)
                continue;
            ++smooth;
            EXPECT_GT(glm::dot(e.normal, glm::normalize(gc)), 0.9999)
                << m.name << " edge " << e.sample.x << "," << e.sample.y << "," << e.sample.z << " axis "
                << e.axis << " t " << e.t << " normal " << e.normal.x << "," << e.normal.y << ","
                << e.normal.z << " gradient " << gc.x << "," << gc.y << "," << gc.z;
        }
    }
    EXPECT_GT(checked, 1000u);
    EXPECT_GT(singleRoot, checked * 9 / 10);
    EXPECT_GT(smooth, checked * 9 / 10);
}

TEST(SdfEvaluator, MaterialsMatchEvaluateMaterialInBand)
{
    std::vector<std::pair<SdfModel, GridSpec>> cases;
    cases.push_back({getLandscape(), makeModelGrid(getLandscape(), 64)});
    for (unsigned seed = 30; seed < 36; ++seed)
        cases.push_back({makeRandomModel(seed, 20), makeCubeGrid(-1.2, 1.2, 37)});
    for (const auto& [m, g] : cases)
        for (int frame : {1, kAllFrames}) {
            EvaluationOptions o;
            o.computeMaterials = true;
            o.keepExactValues = true;
            const EvaluationResult r = evaluateModel(m, g, frame, o);
            const EvaluationResult b = evaluateModelBruteForce(m, g, frame, o);
            std::size_t compared = 0, different = 0;
            for (int z = 0; z < g.samples.z; ++z)
                for (int y = 0; y < g.samples.y; ++y)
                    for (int x = 0; x < g.samples.x; ++x) {
                        const std::size_t i = r.field.index(x, y, z);
                        // Clamped values are +-band: compare where the field itself is in the band.
                        if (std::abs(m.evaluate(r.field.position(x, y, z), frame)) > r.band)
                            continue;
                        ++compared;
                        different += r.materials[i] != b.materials[i] ? 1 : 0;
                    }
            EXPECT_GT(compared, 0u);
            EXPECT_EQ(different, 0u) << m.name << " frame " << frame;
        }
}

TEST(SdfEvaluator, EmptyModelIsOutsideEverywhere)
{
    SdfModel empty;
    const GridSpec g = makeCubeGrid(-1.0, 1.0, 30);
    EvaluationOptions o;
    o.computeMaterials = true;
    const EvaluationResult r = evaluateModel(empty, g, kAllFrames, o);
    const float band = toFieldValue(r.band);
    for (float v : r.field.values)
        ASSERT_EQ(v, band);
    EXPECT_TRUE(r.hermite.edges.empty());
    EXPECT_EQ(r.stats.getFieldEvaluations(), 0u);
    EXPECT_EQ(r.stats.bruteForceEvaluations, 0u);
    EXPECT_EQ(r.stats.getCullingRate(), 0.0);
    // Edits that start after the evaluated frame are not there yet.
    SdfModel later = makeRandomModel(3, 5);
    for (auto& e : later.edits)
        e.frame = 5;
    const EvaluationResult l = evaluateModel(later, g, 4, o);
    for (float v : l.field.values)
        ASSERT_EQ(v, band);
    EXPECT_EQ(l.stats.activeEdits, 0u);
    EXPECT_EQ(l.stats.getFieldEvaluations(), 0u);
}

TEST(SdfEvaluator, ZeroSizePrimitives)
{
    // Points, flat boxes, zero-length capsules and zero-radius tori are exact distances and give
    // finite fields. A zero-size cone or ellipsoid evaluates to NaN in SdfModel itself; such edits
    // are never culled, so the evaluator reproduces brute force there too (NaN where it is NaN).
    for (int shape = 0; shape < 8; ++shape) {
        SdfModel m;
        m.name = std::string("zero_") + scene::toString(CsgShape(shape));
        CsgEdit big;
        big.shape = CsgShape::Box;
        big.size = glm::dvec3(0.4);
        CsgEdit zero;
        zero.shape = CsgShape(shape);
        zero.size = glm::dvec3(0.0);
        zero.center = glm::dvec3(0.5, 0.1, 0.0);
        m.edits = {big, zero};
        CsgEdit cut = zero;
        cut.op = CsgOp::Subtract;
        cut.center = glm::dvec3(0.0, 0.4, 0.0);
        cut.blend = 0.1;
        m.edits.push_back(cut);
        const GridSpec g = makeCubeGrid(-1.0, 1.0, 31);
        expectMatchesBruteForce(m, g, kAllFrames);
        const bool degenerate = CsgShape(shape) == CsgShape::Cone || CsgShape(shape) == CsgShape::Ellipsoid;
        if (!degenerate) {
            const EvaluationResult r = evaluateModel(m, g);
            for (float v : r.field.values)
                ASSERT_TRUE(std::isfinite(v)) << m.name;
        }
    }
}

TEST(SdfEvaluator, HugeCoordinatesStayFiniteAndExact)
{
    SdfModel m = makeRandomModel(21, 16);
    const glm::dvec3 offset(1e6, -2e6, 1e6);
    for (auto& e : m.edits)
        e.center += offset;
    GridSpec g = makeCubeGrid(-1.2, 1.2, 41);
    g.origin += offset;
    expectMatchesBruteForce(m, g, kAllFrames);
    const EvaluationResult r = evaluateModel(m, g);
    for (float v : r.field.values)
        ASSERT_TRUE(std::isfinite(v));
    EXPECT_GT(r.hermite.edges.size(), 0u);
    for (const auto& e : r.hermite.edges) {
        ASSERT_TRUE(e.t >= 0.0 && e.t <= 1.0);
        ASSERT_TRUE(std::isfinite(e.normal.x + e.normal.y + e.normal.z));
    }
    EXPECT_GT(r.stats.getCullingRate(), 0.0);
}

TEST(SdfEvaluator, ExactFunctionsMatchModel)
{
    const SdfModel& land = getLandscape();
    const ExactFunctions f = makeExactFunctions(land, 7);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int compared = 0;
    for (int i = 0; i < 2000; ++i) {
        const glm::dvec3 p = land.boundsMin + (land.boundsMax - land.boundsMin) * glm::dvec3(u(rng), u(rng), u(rng));
        ASSERT_TRUE(isSameDouble(f.value(p), land.evaluate(p, 7)));
        const glm::dvec3 g = f.gradient(p);
        const double len = glm::length(g);
        if (len == 0.0)
            continue;
        ASSERT_NEAR(len, 1.0, 1e-12);
        const glm::dvec3 ref = land.evaluateGradient(p, 7);
        compared += 1;
        // Points within the reference's step of a kink of the field may differ.
        if (glm::dot(g, ref) < 0.999)
            --compared;
    }
    EXPECT_GT(compared, 1900);
}

TEST(SdfEvaluator, FieldValueKeepsTheSign)
{
    EXPECT_GT(toFieldValue(1e-60), 0.0f);
    EXPECT_LE(toFieldValue(-1e-60), 0.0f);
    EXPECT_LE(toFieldValue(0.0), 0.0f);
    EXPECT_EQ(toFieldValue(0.25), 0.25f);
    EXPECT_EQ(clampToBand(3.0, 2.0), 2.0);
    EXPECT_EQ(clampToBand(-3.0, 2.0), -2.0);
    EXPECT_EQ(clampToBand(1.5, 2.0), 1.5);
}

TEST(SdfEvaluator, InvalidArgumentsThrow)
{
    const SdfModel& m = getGallery()[0];
    GridSpec g = makeModelGrid(m, 16);
    EvaluationOptions o;
    o.bandCells = 0.0;
    EXPECT_THROW(evaluateModel(m, g, kAllFrames, o), std::invalid_argument);
    o = {};
    o.leafSamples = 0;
    EXPECT_THROW(evaluateModel(m, g, kAllFrames, o), std::invalid_argument);
    g.spacing = 0.0;
    EXPECT_THROW(evaluateModel(m, g), std::invalid_argument);
    EXPECT_THROW(makeModelGrid(m, 2), std::invalid_argument);
}
