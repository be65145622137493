#include "reference/samplers.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace rtlab::reference {

Frame Frame::fromNormal(const glm::dvec3& n)
{
    // Branchless orthonormal basis [Duff et al. 2017, "Building an Orthonormal Basis, Revisited"].
    const double sign = std::copysign(1.0, n.z);
    const double a = -1.0 / (sign + n.z);
    const double b = n.x * n.y * a;
    Frame f;
    f.tangent = glm::dvec3(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.bitangent = glm::dvec3(b, sign + n.y * n.y * a, -n.y);
    f.normal = n;
    return f;
}

double computeLuminance(const glm::dvec3& rgb)
{
    return 0.2126 * rgb.x + 0.7152 * rgb.y + 0.0722 * rgb.z;
}

namespace {

// cos t and sin t for |t| <= pi/4 by their Taylor series to t^16 and t^15: the first omitted
// terms are below 5e-17 there, so these are the libm values to within an ulp, at the cost of a
// few multiplies (the reference's AO rays spend more time in sincos than in Embree otherwise).
void computeCosSinQuarter(double t, double& c, double& s)
{
    const double t2 = t * t;
    c = 1.0 + t2 * (-1.0 / 2 + t2 * (1.0 / 24 + t2 * (-1.0 / 720 + t2 * (1.0 / 40320 + t2 * (-1.0 / 3628800 +
        t2 * (1.0 / 479001600 + t2 * (-1.0 / 87178291200.0 + t2 * (1.0 / 20922789888000.0))))))));
    s = t * (1.0 + t2 * (-1.0 / 6 + t2 * (1.0 / 120 + t2 * (-1.0 / 5040 + t2 * (1.0 / 362880 +
        t2 * (-1.0 / 39916800 + t2 * (1.0 / 6227020800.0 + t2 * (-1.0 / 1307674368000.0))))))));
}

// cos and sin of 2 pi t for t in [0, 1] without libm's sincos: the nearest quarter turn q,
// the series above on the rest (|2 pi (t - q/4)| <= pi/4; t - q/4 is exact by Sterbenz's lemma),
// turned by q quarter turns.
void computeCosSinTurns(double t, double& c, double& s)
{
    constexpr double kShifter = 0x1.8p52; // adding it rounds to the nearest integer
    const double q = (4.0 * t + kShifter) - kShifter;
    double c0, s0;
    computeCosSinQuarter(2.0 * kPi * (t - 0.25 * q), c0, s0);
    switch (int(q) & 3) {
    case 0:
        c = c0, s = s0;
        break;
    case 1:
        c = -s0, s = c0;
        break;
    case 2:
        c = -c0, s = -s0;
        break;
    default:
        c = s0, s = -c0;
        break;
    }
}

} // namespace

glm::dvec3 sampleCosineHemisphere(const glm::dvec2& u)
{
    // Concentric map of the square onto the unit disk [Shirley & Chiu 1997] ...
    const double a = 2.0 * u.x - 1.0;
    const double b = 2.0 * u.y - 1.0;
    double x = 0.0;
    double y = 0.0;
    if (a != 0.0 || b != 0.0) {
        // phi = (pi/4)(b/a), or pi/2 - (pi/4)(a/b) whose cosine and sine swap those of (pi/4)(a/b).
        // Written as selects rather than branches: the two cases are equally likely.
        const bool first = std::abs(a) > std::abs(b);
        const double r = first ? a : b, other = first ? b : a;
        double c, s;
        computeCosSinQuarter((kPi / 4.0) * (other / r), c, s);
        x = r * (first ? c : s);
        y = r * (first ? s : c);
    }
    // ... lifted onto the hemisphere: uniform on the disk = cosine-weighted (Malley's method).
    return {x, y, std::sqrt(std::max(0.0, 1.0 - x * x - y * y))};
}

void sampleCosineHemispheres(const glm::dvec2* u, glm::dvec3* out, std::size_t n)
{
    for (std::size_t i = 0; i < n; ++i)
        out[i] = sampleCosineHemisphere(u[i]);
}

double pdfCosineHemisphere(double cosTheta)
{
    return cosTheta > 0.0 ? cosTheta / kPi : 0.0;
}

glm::dvec3 sampleUniformHemisphere(const glm::dvec2& u)
{
    const double z = u.x;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    double c, s;
    computeCosSinTurns(u.y, c, s); // azimuth 2 pi u.y
    return {r * c, r * s, z};
}

void sampleUniformHemispheres(const glm::dvec2* u, glm::dvec3* out, std::size_t n)
{
    for (std::size_t i = 0; i < n; ++i)
        out[i] = sampleUniformHemisphere(u[i]);
}

double pdfUniformHemisphere()
{
    return 1.0 / (2.0 * kPi);
}

glm::dvec3 sampleUniformSphere(const glm::dvec2& u)
{
    const double z = 1.0 - 2.0 * u.x;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    double c, s;
    computeCosSinTurns(u.y, c, s); // azimuth 2 pi u.y
    return {r * c, r * s, z};
}

double pdfUniformSphere()
{
    return 1.0 / (4.0 * kPi);
}

namespace {

// sampleSphericalGaussian with expm1(-2k) computed by the caller (once per sky, not per sample).
glm::dvec3 sampleSphericalGaussian(const glm::dvec2& u, double sharpness, double expm1MinusTwoK)
{
    // CDF in w = cos(theta): F(w) = (exp(k(w - 1)) - exp(-2k)) / (1 - exp(-2k)). Solving F(w) = 1 -
    // u gives w = 1 + log(u + (1 - u) exp(-2k)) / k [Jakob 2012, "Numerically stable sampling of
    // the von Mises Fisher distribution on S^2"]; log1p/expm1 keep it exact for small and large k.
    const double k = sharpness;
    const double oneMinusW = -std::log1p((1.0 - u.x) * expm1MinusTwoK) / k;
    const double w = std::clamp(1.0 - oneMinusW, -1.0, 1.0);
    const double sinTheta = std::sqrt(std::max(0.0, oneMinusW * (2.0 - oneMinusW)));
    double c, s;
    computeCosSinTurns(u.y, c, s); // azimuth 2 pi u.y
    return {sinTheta * c, sinTheta * s, w};
}

} // namespace

glm::dvec3 sampleSphericalGaussian(const glm::dvec2& u, double sharpness)
{
    return sampleSphericalGaussian(u, sharpness, std::expm1(-2.0 * sharpness));
}

double pdfSphericalGaussian(double cosTheta, double sharpness)
{
    const double k = sharpness;
    return k / (-2.0 * kPi * std::expm1(-2.0 * k)) * std::exp(k * (cosTheta - 1.0));
}

glm::dvec2 sampleTriangleBarycentrics(const glm::dvec2& u)
{
    // [Turk 1990]: b0 = 1 - sqrt(u1), b1 = (1 - u2) sqrt(u1), b2 = u2 sqrt(u1).
    const double s = std::sqrt(u.x);
    return {(1.0 - u.y) * s, u.y * s};
}

double pdfTriangleArea(double area)
{
    return area > 0.0 ? 1.0 / area : 0.0;
}

DiscreteDistribution::DiscreteDistribution(const std::vector<double>& weights)
{
    mPmf.resize(weights.size());
    mCdf.assign(weights.size() + 1, 0.0);
    for (std::size_t i = 0; i < weights.size(); ++i) {
        if (!(weights[i] >= 0.0) || !std::isfinite(weights[i]))
            throw Error("discrete distribution: weight " + std::to_string(i) +
                        " is negative or not finite");
        mTotal += weights[i];
    }
    if (mTotal <= 0.0)
        return;
    double sum = 0.0;
    for (std::size_t i = 0; i < weights.size(); ++i) {
        mPmf[i] = weights[i] / mTotal;
        sum += weights[i];
        mCdf[i + 1] = sum / mTotal;
    }
    // Exact end, and zero-width intervals at the end must not catch rounding: pin them to 1.
    for (std::size_t i = weights.size(); i > 0 && (i == weights.size() || mPmf[i] == 0.0); --i)
        mCdf[i] = 1.0;
    if (weights.size() > std::numeric_limits<std::uint32_t>::max())
        throw Error("discrete distribution: more than 2^32 - 1 weights");
    mGuide.resize(weights.size());
    std::size_t i = 0;
    for (std::size_t b = 0; b < mGuide.size(); ++b) {
        const double u = double(b) / double(mGuide.size());
        while (i < mPmf.size() && mCdf[i + 1] <= u)
            ++i;
        mGuide[b] = std::uint32_t(i);
    }
}

std::size_t DiscreteDistribution::sample(double u, double* uRemapped) const
{
    // The number of cdf[1..n] at or below u: the first interval [cdf[i], cdf[i+1]) containing u,
    // zero-width intervals never chosen. The guide table's entry is that count for the bucket's
    // lower end; the walk down covers a product u * n rounded up into the next bucket.
    const std::size_t n = mPmf.size();
    const double scaled = u * double(n);
    std::size_t i = scaled >= 0.0 ? mGuide[std::min(std::size_t(scaled), n - 1)] : 0;
    while (i > 0 && mCdf[i] > u)
        --i;
    while (i < n && mCdf[i + 1] <= u)
        ++i;
    i = std::min(i, n - 1);
    if (uRemapped)
        *uRemapped = std::clamp((u - mCdf[i]) / mPmf[i], 0.0, 0x1.fffffffffffffp-1);
    return i;
}

DiscreteDistribution buildPointLightDistribution(const std::vector<scene::PointLight>& lights)
{
    std::vector<double> power;
    power.reserve(lights.size());
    for (const auto& l : lights)
        power.push_back(4.0 * kPi * std::max(0.0, computeLuminance(glm::dvec3(l.intensity))));
    return DiscreteDistribution(power);
}

SkyLobeSampler::SkyLobeSampler(const scene::Sky& sky)
{
    if (sky.kind != scene::Sky::Kind::Srbf || !(sky.sharpness > 0.0f))
        return;
    mSharpness = sky.sharpness;
    mExpm1 = std::expm1(-2.0 * mSharpness);
    mNormalise = mSharpness / (-2.0 * kPi * mExpm1); // the same factor as pdfSphericalGaussian's
    const double integral = scene::integrateSphericalGaussian(mSharpness);
    std::vector<double> weights;
    for (const auto& peak : sky.lobes)
        weights.push_back(std::max(0.0, computeLuminance(glm::dvec3(peak))) * integral);
    mLobes = DiscreteDistribution(weights);
    for (const auto& axis : scene::getConeDirections())
        mFrames.push_back(Frame::fromNormal(glm::normalize(axis)));
    for (std::size_t i = 0; i < mFrames.size(); ++i)
        mPmf[i] = mLobes.pmf(i); // 0 for a black lobe: its term drops out of the pdf
    if (mLobes.empty())
        mFrames.clear();
}

glm::dvec3 SkyLobeSampler::sample(const glm::dvec2& u) const
{
    double ux = 0.0;
    const std::size_t lobe = mLobes.sample(u.x, &ux);
    return glm::normalize(mFrames[lobe].toWorld(sampleSphericalGaussian({ux, u.y}, mSharpness, mExpm1)));
}

double SkyLobeSampler::evaluate(const glm::dvec3& direction, const scene::Sky& sky,
                                glm::dvec3& radiance) const
{
    // The lobes as scene::Sky::radiance takes them (its sharpness), so that the radiance keeps its
    // bits; the cone axes agree with the sampling frames' normalised ones to an ulp.
    double values[scene::kConeDirectionCount];
    scene::evaluateSkyLobes(direction, double(sky.sharpness), values);
    radiance = glm::dvec3(sky.sumLobes(values));
    return sumPdf(values);
}

double SkyLobeSampler::pdf(const glm::dvec3& direction) const
{
    double values[scene::kConeDirectionCount];
    scene::evaluateSkyLobes(direction, mSharpness, values);
    return sumPdf(values);
}

double SkyLobeSampler::sumPdf(const double values[scene::kConeDirectionCount]) const
{
    double p = 0.0; // 0 for an inactive sampler: its pick probabilities are 0
    for (std::size_t i = 0; i < mPmf.size(); ++i)
        p += mPmf[i] * (mNormalise * values[i]);
    return p;
}

} // namespace rtlab::reference
