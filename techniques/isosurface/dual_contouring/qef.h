#pragma once
// The quadratic error function of dual contouring and its two solvers.
//
// QEF [Ju et al. 2002, eq. 1]: E(x) = sum_i (n_i . (x - p_i))^2 over the Hermite points p_i and
// unit normals n_i of one cell. It is built relative to the mass point m (the mean of the p_i):
// with y = x - m, E = |A y - b|^2, A's rows n_i, b_i = n_i . (p_i - m); the system kept is A^T A,
// A^T b, b^T b. Solving near the mass point makes rank-deficient cells (flat or edge cells) pick
// the minimiser closest to m [Lindstrom 2000; Schaefer & Warren 2002, "Dual Contouring: The Secret
// Sauce"].

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>

namespace rtlab::isosurface::dc {

inline bool isFiniteVector(const glm::dvec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

//! A QEF relative to its mass point. Coordinates are whatever the caller uses (grid units here).
struct QefSystem {
    glm::dvec3 massPoint{0.0}; //!< mean of all points, with or without a usable normal
    glm::dmat3 ata{0.0};       //!< A^T A (symmetric)
    glm::dvec3 atb{0.0};       //!< A^T b, b relative to the mass point
    double btb = 0.0;          //!< b^T b
    int pointCount = 0;        //!< points given
    int planeCount = 0;        //!< points whose normal was finite and non-zero (rows of A)

    //! E(x) at a point in the caller's coordinates.
    double evaluate(const glm::dvec3& x) const;
};

//! Builds the QEF of points[i] with normals[i]. Normals are normalised; zero, NaN or infinite
//! normals (and points that are not finite) give no plane, and are counted in `skipped` when it
//! is given. Points that are not finite are also left out of the mass point.
//! (Inline: the mesher builds one per vertex.)
inline QefSystem buildQef(std::span<const glm::dvec3> points, std::span<const glm::dvec3> normals,
                          int* skipped = nullptr)
{
    // Accumulated in locals and returned whole: a default-constructed QefSystem (136 bytes) was
    // zeroed by a `rep stos` whose start-up cost was a tenth of the mesher's vertex pass.
    const std::size_t count = std::min(points.size(), normals.size());
    glm::dvec3 sum(0.0);
    int finitePoints = 0;
    for (std::size_t i = 0; i < count; ++i) {
        if (!isFiniteVector(points[i]))
            continue;
        sum += points[i];
        ++finitePoints;
    }
    if (finitePoints == 0) {
        if (skipped != nullptr)
            *skipped = int(count);
        return QefSystem{glm::dvec3(0.0), glm::dmat3(0.0), glm::dvec3(0.0), 0.0, 0, 0};
    }
    const glm::dvec3 massPoint = sum / double(finitePoints);
    glm::dmat3 ata(0.0);
    glm::dvec3 atb(0.0);
    double btb = 0.0;
    int planes = 0;
    int skippedCount = 0;
    for (std::size_t i = 0; i < count; ++i) {
        const glm::dvec3 n = normals[i];
        const double squared = glm::dot(n, n);
        if (!isFiniteVector(points[i]) || !std::isfinite(squared) || !(squared > 0.0)) {
            ++skippedCount;
            continue;
        }
        // Normals that are unit to rounding (the mesher's are) are used as they are.
        const glm::dvec3 unit = std::abs(squared - 1.0) <= 1e-15 ? n : n / std::sqrt(squared);
        const double b = glm::dot(unit, points[i] - massPoint);
        ata += glm::outerProduct(unit, unit);
        atb += unit * b;
        btb += b * b;
        ++planes;
    }
    if (skipped != nullptr)
        *skipped = skippedCount;
    return QefSystem{massPoint, ata, atb, btb, finitePoints, planes};
}

//! Eigen decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations [Golub & Van Loan,
//! "Matrix Computations", sec. 8.5]: m = V diag(values) V^T, columns of V orthonormal.
struct SymmetricEigen {
    glm::dvec3 values{0.0};
    glm::dmat3 vectors{1.0}; //!< column k is the eigenvector of values[k]
    int sweeps = 0;          //!< sweeps until the off-diagonal part vanished (<= kMaxJacobiSweeps)
};
inline constexpr int kMaxJacobiSweeps = 32;
SymmetricEigen computeSymmetricEigen(const glm::dmat3& m);

//! Singular values of A below this fraction of the largest are always dropped, whatever the
//! threshold: the eigenvalues of A^T A carry an absolute error near 1e-16 of the largest, so
//! singular values below ~1e-8 of the largest are noise; 1e-6 leaves a margin.
inline constexpr double kSingularFloor = 1e-6;

struct QefSolution {
    glm::dvec3 position{0.0}; //!< caller's coordinates
    int rank = 0;             //!< singular values kept (0 when the cell has no plane)
};

//! Minimiser of the QEF nearest to `reference` in the kept directions: the truncated
//! pseudo-inverse of A^T A [Ju et al. 2002, sec. 2.3; Lindstrom 2000] applied to the residual at
//! the reference. Singular values sigma_k = sqrt(lambda_k(A^T A)) with sigma_k < threshold *
//! sigma_max (or below kSingularFloor * sigma_max) are dropped, so the position does not move
//! from `reference` along them. Where only sigma_max is kept (most cells of a smooth surface) its
//! direction comes from a certified power iteration instead of the Jacobi sweeps (same rank,
//! the same position to rounding; 0.6x the mesher's time on a sphere at 256^3).
QefSolution solveQefNear(const QefSystem& qef, const glm::dvec3& reference, double threshold);

//! solveQefNear(qef, qef.massPoint, threshold): the SVD solver relative to the mass point.
QefSolution solveQefSvd(const QefSystem& qef, double threshold);

//! The particle solver of Schmitz, Dietrich and Comba [Schmitz et al. 2009, "Efficient and High
//! Quality Contouring of Isosurfaces on Uniform Grids", SIBGRAPI; extended as "Efficient and
//! Quality Contouring Algorithms on the GPU", Computer Graphics Forum 2010], which The Tomorrow
//! Children used instead of the SVD (seed 000_3da000e866ebc485.txt, "Dual Contouring Issues"): a
//! particle starts at `start` and is moved `iterations` times by `step` times the mean of the
//! plane forces f_i = n_i (n_i . (p_i - x)), each pulling it onto its plane along the normal.
//! Rank is reported as planeCount > 0 ? 3 : 0 (the iteration has no notion of rank).
QefSolution solveQefSchmitz(const QefSystem& qef, const glm::dvec3& start, int iterations,
                            double step);

} // namespace rtlab::isosurface::dc
