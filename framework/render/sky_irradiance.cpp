#include "render/sky_irradiance.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include "core/error.h"

namespace rtlab::render {

namespace {

constexpr double kPi = glm::pi<double>();
constexpr int kSimpsonIntervals = 512;      // per piece between kinks (even)
constexpr int kFitNormals = 512;            // normals the lobe fit matches
constexpr int kCheckNormals = 1024;         // other normals its error is measured on
constexpr double kFitRegularisation = 1e-6; // lambda / mean eigenvalue of A^T A

// Int_0^2pi max(0, A cos(phi) + B) dphi for A >= 0.
double integrateClampedCosineOverPhi(double a, double b)
{
    if (b >= a)
        return 2.0 * kPi * b;
    if (b <= -a)
        return 0.0;
    const double phi0 = std::acos(std::clamp(-b / a, -1.0, 1.0));
    return 2.0 * (b * phi0 + a * std::sin(phi0));
}

// Int_S2 f(w . z) max(0, n . w) dw for a zonal function f about an axis z with n . z = c:
// with mu = cos(theta), Int_0^pi f(cos theta) K(c, cos theta) sin(theta) dtheta (smooth at the
// poles, unlike the integral over mu), split at the kinks of K and at the angles of
// `extraSplits` (values of mu where f jumps).
template <class T>
T integrateZonal(const std::function<T(double)>& f, double c,
                 const std::vector<double>& extraSplits)
{
    c = std::clamp(c, -1.0, 1.0);
    const double sinC = std::sqrt(std::max(0.0, 1.0 - c * c));
    std::vector<double> splits = {0.0, kPi, std::acos(sinC), std::acos(-sinC)};
    for (const double mu : extraSplits)
        splits.push_back(std::acos(std::clamp(mu, -1.0, 1.0)));
    std::sort(splits.begin(), splits.end());
    auto kernel = [&](double theta) {
        return integrateClampedCosineOverPhi(sinC * std::sin(theta), c * std::cos(theta)) *
               std::sin(theta);
    };
    T sum{};
    for (std::size_t p = 0; p + 1 < splits.size(); ++p) {
        const double lo = splits[p];
        const double hi = splits[p + 1];
        if (!(hi > lo))
            continue;
        const double h = (hi - lo) / kSimpsonIntervals;
        T piece{};
        for (int i = 0; i <= kSimpsonIntervals; ++i) {
            // Evaluate just inside the piece at its ends, so a discontinuity of f at a split
            // takes the value of the side the piece lies on.
            const double theta = i == 0                   ? lo + 1e-12 * (hi - lo)
                                 : i == kSimpsonIntervals ? hi - 1e-12 * (hi - lo)
                                                          : lo + h * i;
            const double w = (i == 0 || i == kSimpsonIntervals) ? 1.0 : (i % 2 ? 4.0 : 2.0);
            piece += f(std::cos(theta)) * (w * kernel(theta));
        }
        sum += piece * (h / 3.0);
    }
    return sum;
}

glm::dvec3 evaluateGradient(const scene::Sky& sky, double y)
{
    if (y < 0.0)
        return glm::dvec3(sky.ground);
    return glm::mix(glm::dvec3(sky.horizon), glm::dvec3(sky.zenith), std::min(1.0, y));
}

// Solves the symmetric positive definite system m x = b (n x n, row-major) by Gaussian
// elimination with partial pivoting; b has three right-hand sides.
std::vector<glm::dvec3> solveLinearSystem(std::vector<double> m, std::vector<glm::dvec3> b, int n)
{
    for (int col = 0; col < n; ++col) {
        int pivot = col;
        for (int r = col + 1; r < n; ++r)
            if (std::abs(m[r * n + col]) > std::abs(m[pivot * n + col]))
                pivot = r;
        if (pivot != col) {
            for (int k = 0; k < n; ++k)
                std::swap(m[col * n + k], m[pivot * n + k]);
            std::swap(b[col], b[pivot]);
        }
        const double d = m[col * n + col];
        for (int r = col + 1; r < n; ++r) {
            const double f = m[r * n + col] / d;
            for (int k = col; k < n; ++k)
                m[r * n + k] -= f * m[col * n + k];
            b[r] -= f * b[col];
        }
    }
    std::vector<glm::dvec3> x(n);
    for (int r = n - 1; r >= 0; --r) {
        glm::dvec3 sum = b[r];
        for (int k = r + 1; k < n; ++k)
            sum -= m[r * n + k] * x[k];
        x[r] = sum / m[r * n + r];
    }
    return x;
}

} // namespace

double computeLobeIrradiance(double sharpness, double cosAngle)
{
    if (!(sharpness > 0.0))
        throw Error("computeLobeIrradiance: sharpness " + std::to_string(sharpness) +
                    " is not > 0");
    const std::function<double(double)> lobe = [sharpness](double mu) {
        return std::exp(sharpness * (mu - 1.0));
    };
    return integrateZonal(lobe, cosAngle, {});
}

std::vector<float> computeLobeIrradianceTable(double sharpness, int size)
{
    if (size < 2)
        throw Error("computeLobeIrradianceTable: size " + std::to_string(size) + " is < 2");
    std::vector<float> table(static_cast<std::size_t>(size));
    for (int i = 0; i < size; ++i) {
        const double c = -1.0 + 2.0 * double(i) / double(size - 1);
        table[static_cast<std::size_t>(i)] =
            static_cast<float>(computeLobeIrradiance(sharpness, c));
    }
    return table;
}

glm::dvec3 computeSkyIrradiance(const scene::Sky& sky, const glm::dvec3& n)
{
    switch (sky.kind) {
    case scene::Sky::Kind::None:
        return glm::dvec3(0.0);
    case scene::Sky::Kind::Constant:
        return kPi * glm::dvec3(sky.constant);
    case scene::Sky::Kind::Gradient: {
        // Zonal about +y: the radiance depends on w.y only.
        const std::function<glm::dvec3(double)> f = [&sky](double y) {
            return evaluateGradient(sky, y);
        };
        return integrateZonal(f, n.y, {0.0});
    }
    case scene::Sky::Kind::Srbf: {
        glm::dvec3 sum(0.0);
        const auto& axes = scene::getConeDirections();
        for (int k = 0; k < scene::kConeDirectionCount; ++k)
            sum += glm::dvec3(sky.lobes[k]) *
                   computeLobeIrradiance(sky.sharpness, glm::dot(n, axes[k]));
        return sum;
    }
    }
    return glm::dvec3(0.0);
}

namespace {

// Fibonacci-sphere points.
std::vector<glm::dvec3> makeFibonacciNormals(int count)
{
    std::vector<glm::dvec3> normals(static_cast<std::size_t>(count));
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int j = 0; j < count; ++j) {
        const double y = 1.0 - 2.0 * (j + 0.5) / count;
        const double r = std::sqrt(std::max(0.0, 1.0 - y * y));
        normals[std::size_t(j)] = glm::dvec3(r * std::cos(golden * j), y, r * std::sin(golden * j));
    }
    return normals;
}

} // namespace

SkyLobes fitSkyLobes(const scene::Sky& sky, double lambdaScale)
{
    SkyLobes result;
    constexpr int kLobes = scene::kConeDirectionCount;
    const double s = result.sharpness;
    const auto& axes = scene::getConeDirections();
    // Irradiance of each lobe through a fine table (linear interpolation error ~1e-6).
    const std::vector<float> table = computeLobeIrradianceTable(s, 1025);
    auto lookup = [&table](double c) {
        const double f = (std::clamp(c, -1.0, 1.0) + 1.0) * 0.5 * double(table.size() - 1);
        const std::size_t i = std::min<std::size_t>(std::size_t(f), table.size() - 2);
        const double t = f - double(i);
        return double(table[i]) * (1.0 - t) + double(table[i + 1]) * t;
    };
    auto evaluate = [&](const glm::dvec3& n, const SkyLobes& lobes) {
        glm::dvec3 e(0.0);
        for (int k = 0; k < kLobes; ++k)
            e += lookup(glm::dot(n, axes[k])) * glm::dvec3(lobes.radiance[k]);
        return e;
    };

    const std::vector<glm::dvec3> normals = makeFibonacciNormals(kFitNormals);
    std::vector<double> a(std::size_t(kFitNormals) * kLobes);
    std::vector<glm::dvec3> target(kFitNormals);
    for (int j = 0; j < kFitNormals; ++j) {
        for (int k = 0; k < kLobes; ++k)
            a[std::size_t(j) * kLobes + k] = lookup(glm::dot(normals[j], axes[k]));
        target[j] = computeSkyIrradiance(sky, normals[j]);
    }

    // Prior: each lobe carries its cone's share (4 pi / 16) of the radiance on its axis.
    const double share = scene::getConeQuadratureWeight() / scene::integrateSphericalGaussian(s);
    std::vector<glm::dvec3> prior(kLobes);
    for (int k = 0; k < kLobes; ++k)
        prior[k] = share * glm::dvec3(sky.radiance(axes[k]));

    // (A^T A + lambda I) x = A^T E + lambda x0, lambda relative to the mean eigenvalue.
    std::vector<double> m(std::size_t(kLobes) * kLobes, 0.0);
    std::vector<glm::dvec3> rhs(kLobes, glm::dvec3(0.0));
    for (int j = 0; j < kFitNormals; ++j)
        for (int k = 0; k < kLobes; ++k) {
            const double ajk = a[std::size_t(j) * kLobes + k];
            rhs[k] += ajk * target[j];
            for (int l = 0; l < kLobes; ++l)
                m[std::size_t(k) * kLobes + l] += ajk * a[std::size_t(j) * kLobes + l];
        }
    double trace = 0.0;
    for (int k = 0; k < kLobes; ++k)
        trace += m[std::size_t(k) * kLobes + k];
    const double lambda = lambdaScale * trace / kLobes;
    for (int k = 0; k < kLobes; ++k) {
        m[std::size_t(k) * kLobes + k] += lambda;
        rhs[k] += lambda * prior[k];
    }
    const std::vector<glm::dvec3> x = solveLinearSystem(m, rhs, kLobes);
    for (int k = 0; k < kLobes; ++k)
        result.radiance[k] = glm::vec3(x[k]);

    // The error on other normals than those fitted (and the poles), relative to the largest
    // irradiance over all normals and channels.
    std::vector<glm::dvec3> check = makeFibonacciNormals(kCheckNormals);
    check.push_back({0.0, 1.0, 0.0});
    check.push_back({0.0, -1.0, 0.0});
    double largest = 1e-30, worst = 0.0;
    for (const glm::dvec3& n : check) {
        const glm::dvec3 e = computeSkyIrradiance(sky, n);
        const glm::dvec3 err = glm::abs(evaluate(n, result) - e);
        largest = std::max({largest, e.x, e.y, e.z});
        worst = std::max({worst, err.x, err.y, err.z});
    }
    result.maxError = worst;
    result.maxRelativeError = worst / largest;
    return result;
}

SkyLobes projectSkyOntoLobes(const scene::Sky& sky)
{
    SkyLobes result;
    if (sky.kind == scene::Sky::Kind::None)
        return result;
    if (sky.kind == scene::Sky::Kind::Srbf) {
        if (!(sky.sharpness > 0.0f))
            throw Error("sky sharpness " + std::to_string(sky.sharpness) + " is not > 0");
        result.radiance = sky.lobes;
        result.sharpness = sky.sharpness;
        return result;
    }
    return fitSkyLobes(sky, kFitRegularisation);
}

bool isSameSky(const scene::Sky& a, const scene::Sky& b)
{
    return a.kind == b.kind && a.constant == b.constant && a.zenith == b.zenith &&
           a.horizon == b.horizon && a.ground == b.ground && a.lobes == b.lobes &&
           a.sharpness == b.sharpness;
}

} // namespace rtlab::render
