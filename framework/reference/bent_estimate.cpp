#include "reference/bent_estimate.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::reference {

namespace {

//! Standard error of f(A) from that of A by the larger one-sided difference, which stays finite
//! where f' does not (asin(sqrt(A)) at A = 0 and 1).
template <class F> double propagateStdErr(F f, double a, double se)
{
    if (!(se > 0.0))
        return 0.0;
    const double fa = f(a);
    return std::max(std::abs(f(std::min(1.0, a + se)) - fa),
                    std::abs(fa - f(std::max(0.0, a - se))));
}

double computeAperture(double a)
{
    return std::asin(std::sqrt(std::clamp(a, 0.0, 1.0))); // sin^2(alpha) = A
}

double computeApertureUniform(double a)
{
    return std::acos(1.0 - std::clamp(a, 0.0, 1.0)); // 1 - cos(alpha) = A_u
}

} // namespace

void storeBentEstimate(ReferenceResult& r, std::size_t i, const PixelEstimate& e,
                       const glm::dvec3& normal)
{
    const glm::dvec3 m(e.mean[0], e.mean[1], e.mean[2]);
    const double length = glm::length(m);
    const double a = e.mean[3];
    const double au = e.mean[4];
    if (length > 0.0) {
        const glm::dvec3 u = m / length;
        r.bentNormal.pixels[i] = glm::vec3(u);
        // Delta method: cov(u) = P cov(m) P / |m|^2 with P = I - u u^T; the angle's standard
        // error is sqrt(trace(cov(u))), and trace(P S P) = trace(S) - u^T S u (P is a projector).
        double trace = 0.0;
        for (int k = 0; k < 3; ++k) {
            trace += e.covariance[k * kMaxChannels + k];
            for (int l = 0; l < 3; ++l)
                trace -= u[k] * e.covariance[k * kMaxChannels + l] * u[l];
        }
        r.bentNormalStdErr.pixels[i] = float(std::sqrt(std::max(0.0, trace)) / length);
    } else {
        r.bentNormal.pixels[i] = glm::vec3(normal); // nothing visible: fall back to n
        r.bentNormalStdErr.pixels[i] = 0.0f;
    }
    r.occlusion.pixels[i] = float(a);
    r.occlusionStdErr.pixels[i] = float(e.getStdErr(3));
    r.aperture.pixels[i] = float(computeAperture(a));
    r.apertureStdErr.pixels[i] = float(propagateStdErr(computeAperture, a, e.getStdErr(3)));
    r.apertureUniform.pixels[i] = float(computeApertureUniform(au));
    r.apertureUniformStdErr.pixels[i] =
        float(propagateStdErr(computeApertureUniform, au, e.getStdErr(4)));
}

} // namespace rtlab::reference
