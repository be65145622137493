#include "qef.h"

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::isosurface::dc {

double QefSystem::evaluate(const glm::dvec3& x) const
{
    // |A y - b|^2 = y^T A^T A y - 2 y^T A^T b + b^T b
    const glm::dvec3 y = x - massPoint;
    return glm::dot(y, ata * y) - 2.0 * glm::dot(y, atb) + btb;
}

SymmetricEigen computeSymmetricEigen(const glm::dmat3& m)
{
    // a[r][c] row-major copy, symmetrised.
    double a[3][3];
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            a[r][c] = 0.5 * (m[c][r] + m[r][c]);
    double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};

    double scale = 0.0;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            scale = std::max(scale, std::abs(a[r][c]));

    SymmetricEigen result;
    if (!(scale > 0.0) || !std::isfinite(scale)) {
        result.values = glm::dvec3(a[0][0], a[1][1], a[2][2]);
        return result;
    }
    constexpr int kPairs[3][2] = {{0, 1}, {0, 2}, {1, 2}};
    for (int sweep = 0; sweep < kMaxJacobiSweeps; ++sweep) {
        const double off = std::abs(a[0][1]) + std::abs(a[0][2]) + std::abs(a[1][2]);
        if (off <= 1e-18 * scale)
            break;
        result.sweeps = sweep + 1;
        for (const auto& pair : kPairs) {
            const int p = pair[0];
            const int q = pair[1];
            const double apq = a[p][q];
            if (std::abs(apq) <= 1e-300)
                continue;
            // Rotation that zeroes a[p][q] (Golub & Van Loan, Algorithm 8.5.1, "sym.schur2"):
            // t = tan(angle), the smaller root of t^2 + 2 theta t - 1 = 0.
            const double theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            double t;
            if (std::abs(theta) > 1e150)
                t = 0.5 / theta;
            else
                t = (theta >= 0.0 ? 1.0 : -1.0) /
                    (std::abs(theta) + std::sqrt(theta * theta + 1.0));
            const double c = 1.0 / std::sqrt(t * t + 1.0);
            const double s = t * c;
            a[p][p] -= t * apq;
            a[q][q] += t * apq;
            a[p][q] = a[q][p] = 0.0;
            for (int r = 0; r < 3; ++r) {
                if (r != p && r != q) {
                    const double arp = a[r][p];
                    const double arq = a[r][q];
                    a[r][p] = a[p][r] = c * arp - s * arq;
                    a[r][q] = a[q][r] = s * arp + c * arq;
                }
                const double vrp = v[r][p];
                const double vrq = v[r][q];
                v[r][p] = c * vrp - s * vrq;
                v[r][q] = s * vrp + c * vrq;
            }
        }
    }
    for (int k = 0; k < 3; ++k) {
        result.values[k] = a[k][k];
        for (int r = 0; r < 3; ++r)
            result.vectors[k][r] = v[r][k];
    }
    return result;
}

namespace {

//! The rank-1 case of the truncated solve without the eigen decomposition: most cells of a smooth
//! surface have nearly parallel normals, so A^T A has one eigenvalue far above the other two
//! (sigma_2 / sigma_1 below the threshold: only the first is kept). Then its eigenvector is what
//! power iteration converges to at the rate lambda_2 / lambda_1 per product: the largest
//! column of M^4 (M = A^T A / trace, so entries stay near 1) times M^4 is M^8 e_j, within
//! sqrt(3) (lambda_2 / lambda_1)^8 of the eigenvector. The result is accepted only when it is
//! certified: the residual |M v - mu v| (mu the Rayleigh quotient) bounds the angle to the
//! eigenvector by residual / gap [Parlett, "The Symmetric Eigenvalue Problem", thm. 11-7-1], and
//! lambda_2 + lambda_3 = trace - lambda_1 bounds both dropped eigenvalues from above, so the
//! rank is decided as the truncation rule would decide it. Returns false (the caller runs the
//! Jacobi solve) otherwise: two or three kept directions, a dropped eigenvalue near the cut, or a
//! residual above 1e-13.
bool solveRankOne(const QefSystem& qef, const glm::dvec3& residual, double threshold,
                  glm::dvec3& step)
{
    const glm::dmat3& ata = qef.ata;
    const double trace = ata[0][0] + ata[1][1] + ata[2][2];
    if (!(trace > 0.0) || !std::isfinite(trace))
        return false;
    // Symmetric products on the 6 distinct entries (xx, yy, zz, xy, xz, yz).
    struct Sym {
        double xx, yy, zz, xy, xz, yz;
        Sym squared() const
        {
            return {xx * xx + xy * xy + xz * xz, xy * xy + yy * yy + yz * yz,
                    xz * xz + yz * yz + zz * zz, xx * xy + xy * yy + xz * yz,
                    xx * xz + xy * yz + xz * zz, xy * xz + yy * yz + yz * zz};
        }
        glm::dvec3 column(int c) const
        {
            return c == 0   ? glm::dvec3(xx, xy, xz)
                   : c == 1 ? glm::dvec3(xy, yy, yz)
                            : glm::dvec3(xz, yz, zz);
        }
        glm::dvec3 times(const glm::dvec3& v) const
        {
            return {xx * v.x + xy * v.y + xz * v.z, xy * v.x + yy * v.y + yz * v.z,
                    xz * v.x + yz * v.y + zz * v.z};
        }
    };
    const double inverse = 1.0 / trace;
    // A^T A is symmetric up to rounding; its upper triangle is used.
    const Sym m{ata[0][0] * inverse, ata[1][1] * inverse, ata[2][2] * inverse,
                ata[1][0] * inverse, ata[2][0] * inverse, ata[2][1] * inverse};
    const Sym m4 = m.squared().squared();
    int best = 0;
    double bestLength = glm::dot(m4.column(0), m4.column(0));
    for (int c = 1; c < 3; ++c) {
        const double length = glm::dot(m4.column(c), m4.column(c));
        if (length > bestLength) {
            best = c;
            bestLength = length;
        }
    }
    // v is not normalised: every test below divides by |v|^2 instead (no square root on the
    // path, which is latency-bound).
    const glm::dvec3 v = m4.times(m4.column(best));
    const double vv = glm::dot(v, v);
    if (!(vv > 0.0) || !std::isfinite(vv))
        return false;
    const glm::dvec3 mv = m.times(v);
    const double mu = glm::dot(v, mv) / vv; // lambda_1 / trace
    const double rest = 1.0 - mu;           // (lambda_2 + lambda_3) / trace, both >= 0
    // The truncation keeps sigma_k >= cut sigma_max, i.e. lambda_k >= cut^2 lambda_1.
    const double cut = std::max(threshold, kSingularFloor);
    const double cutLambda = cut * cut * mu;
    if (!(rest < 0.5 * cutLambda) || !(mu > 0.5))
        return false;
    const glm::dvec3 r = mv - mu * v; // |r| / |v|: the residual of the unit vector
    if (glm::dot(r, r) > 1e-26 * vv)
        return false;
    // The dropped eigenvalues are below half the cut and mu within 1e-13 of lambda_1 / trace:
    // sigma_1 is kept (it is sigma_max) and the other two are dropped, as the Jacobi solve does.
    step = v * (glm::dot(v, residual) / (mu * trace * vv));
    return true;
}

} // namespace

QefSolution solveQefNear(const QefSystem& qef, const glm::dvec3& reference, double threshold)
{
    QefSolution solution;
    solution.position = reference;
    if (qef.planeCount == 0)
        return solution;
    {
        const glm::dvec3 residual = qef.atb - qef.ata * (reference - qef.massPoint);
        glm::dvec3 step;
        if (solveRankOne(qef, residual, threshold, step)) {
            solution.position = reference + step;
            solution.rank = 1;
            return solution;
        }
    }
    const SymmetricEigen eigen = computeSymmetricEigen(qef.ata);
    double largest = 0.0;
    for (int k = 0; k < 3; ++k)
        largest = std::max(largest, eigen.values[k]);
    if (!(largest > 0.0) || !std::isfinite(largest))
        return solution;
    // Truncated SVD [Ju et al. 2002, sec. 2.3]: A^T A = V diag(sigma^2) V^T, so dropping a
    // singular value sigma_k of A is dropping the eigenvalue sigma_k^2 of A^T A.
    const double sigmaMax = std::sqrt(largest);
    const double cut = std::max(threshold, kSingularFloor) * sigmaMax;
    // Residual of the normal equations at the reference: A^T b - A^T A (reference - m).
    const glm::dvec3 y0 = reference - qef.massPoint;
    const glm::dvec3 residual = qef.atb - qef.ata * y0;
    glm::dvec3 step(0.0);
    for (int k = 0; k < 3; ++k) {
        const double lambda = eigen.values[k];
        const double sigma = lambda > 0.0 ? std::sqrt(lambda) : 0.0;
        if (sigma < cut)
            continue;
        const glm::dvec3 axis = eigen.vectors[k];
        step += axis * (glm::dot(axis, residual) / lambda);
        ++solution.rank;
    }
    solution.position = reference + step;
    return solution;
}

QefSolution solveQefSvd(const QefSystem& qef, double threshold)
{
    return solveQefNear(qef, qef.massPoint, threshold);
}

QefSolution solveQefSchmitz(const QefSystem& qef, const glm::dvec3& start, int iterations,
                            double step)
{
    QefSolution solution;
    solution.position = start;
    if (qef.planeCount == 0)
        return solution;
    solution.rank = 3;
    // Schmitz et al. 2009, sec. 4: the force on the particle is the sum over the cell's planes of
    // n_i times the particle's signed distance to plane i (they evaluate it at the 8 cell corners
    // and interpolate trilinearly; the force is affine in x, so the interpolation is exact and it
    // is evaluated here directly). In the mass-point frame, sum_i n_i (n_i . (p_i - x)) =
    // A^T b - A^T A y. Averaging over the planes bounds the largest eigenvalue of the iteration
    // matrix by 1 (unit normals: trace(A^T A) / k = 1), so every step in (0, 2) converges.
    const double inverseCount = 1.0 / double(qef.planeCount);
    glm::dvec3 y = start - qef.massPoint;
    for (int i = 0; i < iterations; ++i) {
        const glm::dvec3 force = (qef.atb - qef.ata * y) * inverseCount;
        y += step * force;
    }
    solution.position = qef.massPoint + y;
    return solution;
}

} // namespace rtlab::isosurface::dc
