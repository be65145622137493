// The QEF of dual_contouring: the symmetric eigen decomposition, the truncated-SVD solve about the
// mass point on exact and adversarial systems, and the Schmitz particle solver. The mesher's own
// tests are in dual_contouring_test.cpp.

#include "qef.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace rtlab::isosurface {
namespace {

using dc::QefSystem;
// ---------------------------------------------------------------------------------------------
// QEF solver

//! Points on the plane n . x = d, spread around `around`, with normal n.
void addPlanePoints(std::vector<glm::dvec3>& points, std::vector<glm::dvec3>& normals, glm::dvec3 n,
                    double d, glm::dvec3 around, int count, std::mt19937& rng)
{
    n = glm::normalize(n);
    std::uniform_real_distribution<double> u(-0.4, 0.4);
    for (int i = 0; i < count; ++i) {
        glm::dvec3 p = around + glm::dvec3(u(rng), u(rng), u(rng));
        p -= n * (glm::dot(n, p) - d);
        points.push_back(p);
        normals.push_back(n);
    }
}

TEST(DualContouringQef, JacobiEigenDecompositionReconstructsSymmetricMatrices)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        glm::dmat3 m(0.0);
        for (int r = 0; r < 3; ++r)
            for (int c = r; c < 3; ++c)
                m[c][r] = m[r][c] = u(rng) * (trial % 3 == 0 ? 1e-8 : 1.0);
        const dc::SymmetricEigen e = dc::computeSymmetricEigen(m);
        EXPECT_LT(e.sweeps, dc::kMaxJacobiSweeps);
        glm::dmat3 diag(0.0);
        for (int k = 0; k < 3; ++k)
            diag[k][k] = e.values[k];
        const glm::dmat3 back = e.vectors * diag * glm::transpose(e.vectors);
        const glm::dmat3 identity = glm::transpose(e.vectors) * e.vectors;
        double scale = 0.0;
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
                scale = std::max(scale, std::abs(m[c][r]));
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(back[c][r], m[c][r], 1e-14 * scale) << "trial " << trial;
                EXPECT_NEAR(identity[c][r], r == c ? 1.0 : 0.0, 1e-14) << "trial " << trial;
            }
    }
}

TEST(DualContouringQef, ThreePlanesGiveTheirCorner)
{
    std::mt19937 rng(1);
    // Orthogonal planes, and three oblique ones meeting at the same point.
    const glm::dvec3 corner(0.3, 0.6, 0.2);
    const std::vector<std::array<glm::dvec3, 3>> frames = {
        {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1)},
        {glm::dvec3(1, 0.3, 0), glm::dvec3(-0.2, 1, 0.4), glm::dvec3(0.5, 0.1, 1)},
    };
    for (const auto& frame : frames) {
        std::vector<glm::dvec3> points;
        std::vector<glm::dvec3> normals;
        for (int k = 0; k < 3; ++k)
            addPlanePoints(points, normals, frame[k], glm::dot(glm::normalize(frame[k]), corner),
                           corner, 2 + k, rng);
        const QefSystem qef = dc::buildQef(points, normals);
        const dc::QefSolution s = dc::solveQefSvd(qef, 0.1);
        EXPECT_EQ(s.rank, 3);
        EXPECT_LT(glm::length(s.position - corner), 1e-12);
        // E evaluated from the normal equations cancels to about eps * b^T b.
        EXPECT_LT(qef.evaluate(s.position), 1e-14);
    }
}

TEST(DualContouringQef, TwoPlanesGiveThePointOfTheirEdgeNearestTheMassPoint)
{
    std::mt19937 rng(2);
    // Edge along z through (0.3, 0.6), and an oblique edge.
    const glm::dvec3 onEdge(0.3, 0.6, 0.5);
    const std::vector<std::array<glm::dvec3, 2>> pairs = {
        {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0)},
        {glm::dvec3(1, 0.2, 0.3), glm::dvec3(-0.1, 1, 0.5)},
    };
    for (const auto& pair : pairs) {
        std::vector<glm::dvec3> points;
        std::vector<glm::dvec3> normals;
        addPlanePoints(points, normals, pair[0], glm::dot(glm::normalize(pair[0]), onEdge), onEdge,
                       3, rng);
        addPlanePoints(points, normals, pair[1], glm::dot(glm::normalize(pair[1]), onEdge), onEdge,
                       2, rng);
        const QefSystem qef = dc::buildQef(points, normals);
        const dc::QefSolution s = dc::solveQefSvd(qef, 0.1);
        EXPECT_EQ(s.rank, 2);
        const glm::dvec3 direction = glm::normalize(glm::cross(pair[0], pair[1]));
        const glm::dvec3 expected =
            onEdge + direction * glm::dot(direction, qef.massPoint - onEdge);
        EXPECT_LT(glm::length(s.position - expected), 1e-12);
    }
}

TEST(DualContouringQef, OnePlaneGivesTheProjectionOfTheMassPoint)
{
    std::mt19937 rng(3);
    const glm::dvec3 n = glm::normalize(glm::dvec3(0.3, -0.4, 1.0));
    std::vector<glm::dvec3> points;
    std::vector<glm::dvec3> normals;
    addPlanePoints(points, normals, n, 0.4, glm::dvec3(0.5), 4, rng);
    const QefSystem qef = dc::buildQef(points, normals);
    const dc::QefSolution s = dc::solveQefSvd(qef, 0.1);
    EXPECT_EQ(s.rank, 1);
    const glm::dvec3 expected = qef.massPoint - n * (glm::dot(n, qef.massPoint) - 0.4);
    EXPECT_LT(glm::length(s.position - expected), 1e-12);
}

TEST(DualContouringQef, ParallelNormalsGiveTheMidPlaneAtTheMassPoint)
{
    // Two sheets of a feature thinner than a cell: z = 0.3 facing down, z = 0.5 facing up. The
    // QEF is rank 1; its minimiser nearest the mass point is the mass point moved to z = 0.4.
    const std::vector<glm::dvec3> points = {
        {0.2, 0.1, 0.3}, {0.9, 0.4, 0.3}, {0.3, 0.7, 0.5}, {0.6, 0.8, 0.5}};
    const std::vector<glm::dvec3> normals = {{0, 0, -1}, {0, 0, -1}, {0, 0, 1}, {0, 0, 1}};
    const QefSystem qef = dc::buildQef(points, normals);
    const dc::QefSolution s = dc::solveQefSvd(qef, 0.1);
    EXPECT_EQ(s.rank, 1);
    EXPECT_LT(glm::length(s.position - glm::dvec3(0.5, 0.5, 0.4)), 1e-12);
    // Same-direction parallel normals on one plane.
    const std::vector<glm::dvec3> flat = {{0.1, 0.2, 0.7}, {0.8, 0.3, 0.7}, {0.5, 0.9, 0.7}};
    const std::vector<glm::dvec3> up(3, glm::dvec3(0, 0, 1));
    const dc::QefSolution f = dc::solveQefSvd(dc::buildQef(flat, up), 0.1);
    EXPECT_LT(glm::length(f.position - glm::dvec3(1.4 / 3, 1.4 / 3, 0.7)), 1e-12);
}

TEST(DualContouringQef, ASingleNormalGivesItsPoint)
{
    const std::vector<glm::dvec3> points = {{0.25, 0.5, 0.75}};
    const std::vector<glm::dvec3> normals = {{2.0, -1.0, 0.5}};
    const dc::QefSolution s = dc::solveQefSvd(dc::buildQef(points, normals), 0.1);
    EXPECT_EQ(s.rank, 1);
    EXPECT_LT(glm::length(s.position - points[0]), 1e-15);
}

TEST(DualContouringQef, NoisyNormalsStayNearTheAnswer)
{
    std::mt19937 rng(4);
    std::normal_distribution<double> noise(0.0, 1e-3);
    const auto perturb = [&](std::vector<glm::dvec3>& normals) {
        for (glm::dvec3& n : normals)
            n = glm::normalize(n + glm::dvec3(noise(rng), noise(rng), noise(rng)));
    };
    // Corner: well conditioned, so 1e-3 normal noise moves it by about 1e-3 cells.
    const glm::dvec3 corner(0.4, 0.5, 0.6);
    for (int trial = 0; trial < 50; ++trial) {
        std::vector<glm::dvec3> points;
        std::vector<glm::dvec3> normals;
        for (int k = 0; k < 3; ++k) {
            glm::dvec3 axis(0.0);
            axis[k] = 1.0;
            addPlanePoints(points, normals, axis, corner[k], corner, 3, rng);
        }
        perturb(normals);
        const dc::QefSolution s = dc::solveQefSvd(dc::buildQef(points, normals), 0.1);
        EXPECT_EQ(s.rank, 3);
        EXPECT_LT(glm::length(s.position - corner), 1e-2) << "trial " << trial;
    }
    // Plane: noise makes A^T A full rank with tiny singular values; the truncation drops them,
    // so the vertex stays near the mass point's projection instead of running off along them.
    for (int trial = 0; trial < 50; ++trial) {
        std::vector<glm::dvec3> points;
        std::vector<glm::dvec3> normals;
        addPlanePoints(points, normals, glm::dvec3(0, 0, 1), 0.5, glm::dvec3(0.5), 4, rng);
        perturb(normals);
        const QefSystem qef = dc::buildQef(points, normals);
        const dc::QefSolution s = dc::solveQefSvd(qef, 0.1);
        EXPECT_EQ(s.rank, 1) << "trial " << trial;
        const glm::dvec3 expected(qef.massPoint.x, qef.massPoint.y, 0.5);
        EXPECT_LT(glm::length(s.position - expected), 1e-2) << "trial " << trial;
    }
}

TEST(DualContouringQef, NanInfiniteAndZeroNormalsAreSkipped)
{
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<glm::dvec3> points = {{0.3, 0.1, 0.2}, {0.1, 0.6, 0.9}, {0.9, 0.2, 0.2},
                                            {0.5, 0.5, 0.5}, {0.2, 0.2, 0.8}, {0.7, 0.7, 0.1}};
    const std::vector<glm::dvec3> normals = {{1, 0, 0}, {0, 1, 0},   {nan, 0, 1},
                                             {0, 0, 0}, {inf, 1, 0}, {0, 0, 1}};
    int skipped = -1;
    const QefSystem qef = dc::buildQef(points, normals, &skipped);
    EXPECT_EQ(skipped, 3);
    EXPECT_EQ(qef.planeCount, 3);
    EXPECT_EQ(qef.pointCount, 6);
    const dc::QefSolution s = dc::solveQefSvd(qef, 0.1);
    EXPECT_LT(glm::length(s.position - glm::dvec3(0.3, 0.6, 0.1)), 1e-12);

    // No usable normal at all: the mass point.
    const std::vector<glm::dvec3> bad(points.size(), glm::dvec3(nan));
    const QefSystem none = dc::buildQef(points, bad, &skipped);
    EXPECT_EQ(skipped, int(points.size()));
    EXPECT_EQ(none.planeCount, 0);
    const dc::QefSolution m = dc::solveQefSvd(none, 0.1);
    EXPECT_EQ(m.rank, 0);
    EXPECT_LT(glm::length(m.position - none.massPoint), 1e-15);
    const dc::QefSolution p = dc::solveQefSchmitz(none, glm::dvec3(0.5), 20, 1.0);
    EXPECT_EQ(p.position, glm::dvec3(0.5));
}

TEST(DualContouringQef, RandomSystemsGiveFiniteSolutionsNoWorseThanTheMassPoint)
{
    // Truncating never raises the error above the mass point's: with c_k = v_k . A^T b, the
    // kept directions lower E by c_k^2 / lambda_k each.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uniform_real_distribution<double> s(-1.0, 1.0);
    std::uniform_int_distribution<int> count(1, 12);
    for (int trial = 0; trial < 2000; ++trial) {
        std::vector<glm::dvec3> points;
        std::vector<glm::dvec3> normals;
        const int n = count(rng);
        for (int i = 0; i < n; ++i) {
            points.emplace_back(u(rng), u(rng), u(rng));
            normals.emplace_back(s(rng), s(rng), s(rng));
        }
        const QefSystem qef = dc::buildQef(points, normals);
        for (const double threshold : {0.0, 0.1, 0.5, 1.0}) {
            const dc::QefSolution sol = dc::solveQefSvd(qef, threshold);
            ASSERT_TRUE(std::isfinite(sol.position.x) && std::isfinite(sol.position.y) &&
                        std::isfinite(sol.position.z));
            EXPECT_LE(qef.evaluate(sol.position), qef.evaluate(qef.massPoint) + 1e-12)
                << "trial " << trial << " threshold " << threshold;
        }
        const dc::QefSolution particle = dc::solveQefSchmitz(qef, glm::dvec3(0.5), 20, 1.0);
        ASSERT_TRUE(std::isfinite(particle.position.x) && std::isfinite(particle.position.y) &&
                    std::isfinite(particle.position.z));
    }
}

TEST(DualContouringQef, TheRankOneShortcutAgreesWithTheJacobiSolve)
{
    // Cells of a smooth surface: normals within a small cone (rank 1 at threshold 0.1), and, for
    // contrast, cones wide enough to keep two or three directions. solveQefSvd takes the
    // certified power-iteration shortcut where only one direction is kept; the reference here is
    // the truncated solve written out on the Jacobi eigen decomposition. Same rank, positions
    // within 1e-11 of the step's length (both are accurate to rounding; the shortcut's
    // eigenvector is certified to 1e-13 / gap, and the Jacobi sweeps stop at 1e-18 of the matrix).
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uniform_real_distribution<double> s(-1.0, 1.0);
    std::uniform_int_distribution<int> count(1, 12);
    int shortcut = 0;
    for (int trial = 0; trial < 3000; ++trial) {
        const double spread = std::pow(10.0, -4.0 + 4.0 * u(rng)); // 1e-4 .. 1
        const glm::dvec3 axis = glm::normalize(glm::dvec3(s(rng), s(rng), s(rng)) + 1e-9);
        std::vector<glm::dvec3> points;
        std::vector<glm::dvec3> normals;
        const int n = count(rng);
        for (int i = 0; i < n; ++i) {
            points.emplace_back(u(rng), u(rng), u(rng));
            normals.push_back(axis + spread * glm::dvec3(s(rng), s(rng), s(rng)));
        }
        const QefSystem qef = dc::buildQef(points, normals);
        for (const double threshold : {0.0, 0.1, 0.5}) {
            const dc::SymmetricEigen eigen = dc::computeSymmetricEigen(qef.ata);
            const double largest = std::max({eigen.values.x, eigen.values.y, eigen.values.z});
            const double cut = std::max(threshold, dc::kSingularFloor) * std::sqrt(largest);
            glm::dvec3 step(0.0);
            int rank = 0;
            for (int k = 0; k < 3; ++k) {
                const double lambda = eigen.values[k];
                if (!(lambda > 0.0) || std::sqrt(lambda) < cut)
                    continue;
                step += eigen.vectors[k] * (glm::dot(eigen.vectors[k], qef.atb) / lambda);
                ++rank;
            }
            const dc::QefSolution sol = dc::solveQefSvd(qef, threshold);
            EXPECT_EQ(sol.rank, rank) << "trial " << trial << " threshold " << threshold;
            // Relative to the step: with the floor (threshold 0) a direction of lambda near
            // 1e-12 lambda_max is kept and the step is large.
            EXPECT_LT(glm::length(sol.position - (qef.massPoint + step)),
                      1e-11 * (1.0 + glm::length(step)))
                << "trial " << trial << " threshold " << threshold << " spread " << spread;
            shortcut += rank == 1;
        }
    }
    // The shortcut's case is the common one in this mix, and the others are exercised too.
    EXPECT_GT(shortcut, 1000);
    EXPECT_LT(shortcut, 8000);
}

TEST(DualContouringQef, SchmitzConvergesToTheSvdCorner)
{
    // A cube corner seen by one cell: crossings on its 3 faces, 3 + 2 + 1 of them. The mean
    // force contracts the error along eigenvector k by (1 - step lambda_k / planeCount) per
    // iteration; here lambda_min / planeCount = 1/6, so 20 steps of 1 leave (5/6)^20 = 2.6% of
    // the start's distance (at most sqrt(3) cells): tolerance 0.05 cells. 200 steps: 1e-12.
    std::mt19937 rng(6);
    const glm::dvec3 corner(0.35, 0.55, 0.45);
    std::vector<glm::dvec3> points;
    std::vector<glm::dvec3> normals;
    for (int k = 0; k < 3; ++k) {
        glm::dvec3 axis(0.0);
        axis[k] = 1.0;
        addPlanePoints(points, normals, axis, corner[k], corner, 3 - k, rng);
    }
    const QefSystem qef = dc::buildQef(points, normals);
    const glm::dvec3 svd = dc::solveQefSvd(qef, 0.1).position;
    ASSERT_LT(glm::length(svd - corner), 1e-12);
    for (const glm::dvec3& start : {qef.massPoint, glm::dvec3(0.5)}) {
        const double error20 = glm::length(dc::solveQefSchmitz(qef, start, 20, 1.0).position - svd);
        const double error200 =
            glm::length(dc::solveQefSchmitz(qef, start, 200, 1.0).position - svd);
        const double bound20 = std::pow(5.0 / 6.0, 20) * glm::length(start - svd);
        EXPECT_LE(error20, bound20 + 1e-15);
        EXPECT_LT(error20, 0.05);
        EXPECT_LT(error200, 1e-12);
    }
}

} // namespace
} // namespace rtlab::isosurface
