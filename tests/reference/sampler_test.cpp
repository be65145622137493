// Chi-square goodness-of-fit of every sampling routine of the reference, and the normalisation
// of every density. Each test draws 10^6 samples from a fixed-seed generator, bins them, and
// compares with expected counts integrated from the density; bins expecting fewer than 5 are
// pooled. Significance: alpha = 0.01 for the whole suite, Sidak-corrected over its
// kChiSquareTests tests: alpha_i = 1 - (1 - 0.01)^(1/kChiSquareTests).
#include "reference/samplers.h"

#include "core/error.h"
#include "test_scenes.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <vector>

namespace rtlab::reference {
namespace {

constexpr int kChiSquareTests = 8; // every CHI_SQUARE_ test below counts once
constexpr int kSamples = 1000000;
const double kAlpha = 1.0 - std::pow(1.0 - 0.01, 1.0 / kChiSquareTests);

//! Uniform numbers in [0, 1) with 53 random bits, reproducible across standard libraries.
class UniformSource {
public:
    explicit UniformSource(std::uint64_t seed) : mEngine(seed) {}
    double next() { return double(mEngine() >> 11) * 0x1.0p-53; }
    glm::dvec2 next2D()
    {
        const double a = next();
        return {a, next()};
    }

private:
    std::mt19937_64 mEngine;
};

struct ChiSquareOutcome {
    double statistic = 0.0;
    int dof = 0;
    double pValue = 1.0;
};

//! Pools bins with expected < 5 into one (kept whenever it expects anything) and returns the
//! statistic and its p-value; samples where the density is zero fail outright.
ChiSquareOutcome computeChiSquare(const std::vector<double>& observed,
                                  const std::vector<double>& expected)
{
    ChiSquareOutcome out;
    double pooledObserved = 0.0, pooledExpected = 0.0;
    int bins = 0;
    for (std::size_t i = 0; i < observed.size(); ++i) {
        if (expected[i] < 5.0) {
            pooledObserved += observed[i];
            pooledExpected += expected[i];
            continue;
        }
        out.statistic += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
        ++bins;
    }
    if (pooledExpected > 0.0) {
        out.statistic +=
            (pooledObserved - pooledExpected) * (pooledObserved - pooledExpected) / pooledExpected;
        ++bins;
    } else if (pooledObserved > 0.0 && pooledExpected == 0.0) {
        out.statistic = std::numeric_limits<double>::infinity(); // samples where pdf = 0
    }
    out.dof = bins - 1;
    out.pValue = test::computeGammaQ(0.5 * out.dof, 0.5 * out.statistic);
    return out;
}

//! Directions binned on an equal-area grid in (z = cos(theta), phi): `zBins` equal steps of z
//! over [zLow, 1] plus one bin for z < zLow, `phiBins` steps of phi. Expected counts integrate
//! the density (a function of the unit direction) over each bin by 8 x 8 Gauss-Legendre points.
struct DirectionBins {
    int zBins = 40;
    int phiBins = 80;
    double zLow = -1.0;

    int count() const { return (zBins + 1) * phiBins; }
    int getBin(const glm::dvec3& d) const
    {
        double phi = std::atan2(d.y, d.x);
        if (phi < 0.0)
            phi += 2.0 * kPi;
        const int ip = std::min(phiBins - 1, int(phi / (2.0 * kPi) * phiBins));
        const int iz =
            d.z < zLow ? 0 : 1 + std::min(zBins - 1, int((d.z - zLow) / (1.0 - zLow) * zBins));
        return iz * phiBins + ip;
    }
    std::vector<double> integrate(const std::function<double(const glm::dvec3&)>& pdf) const
    {
        std::vector<double> nodes, weights;
        test::getGaussLegendre(8, nodes, weights);
        std::vector<double> p(count(), 0.0);
        const double dPhi = 2.0 * kPi / phiBins;
        for (int iz = 0; iz <= zBins; ++iz) {
            const double z0 = iz == 0 ? -1.0 : zLow + (iz - 1) * (1.0 - zLow) / zBins;
            const double z1 = iz == 0 ? zLow : zLow + iz * (1.0 - zLow) / zBins;
            if (z1 <= z0)
                continue;
            // Panels of at most 0.01 in z, so that sharp lobes are integrated accurately.
            const int panels = std::max(1, int(std::ceil((z1 - z0) / 0.01)));
            const double dz = (z1 - z0) / panels;
            for (int ip = 0; ip < phiBins; ++ip) {
                double sum = 0.0;
                for (int panel = 0; panel < panels; ++panel) {
                    for (int a = 0; a < 8; ++a) {
                        const double z = z0 + (panel + 0.5 * (nodes[a] + 1.0)) * dz;
                        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
                        for (int b = 0; b < 8; ++b) {
                            const double phi = (ip + 0.5 * (nodes[b] + 1.0)) * dPhi;
                            sum += weights[a] * weights[b] *
                                   pdf(glm::dvec3(r * std::cos(phi), r * std::sin(phi), z));
                        }
                    }
                }
                // dw = dz dphi on the sphere.
                p[iz * phiBins + ip] = sum * 0.25 * dz * dPhi;
            }
        }
        return p;
    }
};

ChiSquareOutcome testDirections(const DirectionBins& bins,
                                const std::function<glm::dvec3(const glm::dvec2&)>& sample,
                                const std::function<double(const glm::dvec3&)>& pdf,
                                std::uint64_t seed, double* totalProbability)
{
    UniformSource source(seed);
    std::vector<double> observed(bins.count(), 0.0);
    for (int i = 0; i < kSamples; ++i) {
        const glm::dvec3 d = sample(source.next2D());
        EXPECT_NEAR(glm::length(d), 1.0, 1e-9);
        observed[bins.getBin(d)] += 1.0;
    }
    std::vector<double> expected = bins.integrate(pdf);
    *totalProbability = 0.0;
    for (double& e : expected) {
        *totalProbability += e;
        e *= kSamples;
    }
    return computeChiSquare(observed, expected);
}

#define EXPECT_CHI_SQUARE_PASSES(outcome)                                                          \
    do {                                                                                           \
        std::printf("    chi2 = %.1f, dof = %d, p = %.4f (alpha_i = %.6f)\n", (outcome).statistic, \
                    (outcome).dof, (outcome).pValue, kAlpha);                                      \
        EXPECT_GT((outcome).pValue, kAlpha)                                                        \
            << "chi2 = " << (outcome).statistic << ", dof = " << (outcome).dof;                    \
    } while (false)

TEST(ReferenceSamplers, CosineHemisphereChiSquare)
{
    DirectionBins bins;
    double total = 0.0;
    const auto outcome = testDirections(
        bins, sampleCosineHemisphere, [](const glm::dvec3& d) { return pdfCosineHemisphere(d.z); },
        1, &total);
    EXPECT_NEAR(total, 1.0, 1e-9); // the density integrates to 1 over the sphere
    EXPECT_GT(outcome.dof, 1000);
    EXPECT_CHI_SQUARE_PASSES(outcome);
}

// The concentric map evaluates cos and sin by series on [-pi/4, pi/4]: the directions must be
// those of the map with libm's cos and sin, to a few ulps: 1e-15 in x and y; z = sqrt(1 - x^2 -
// y^2) turns a difference dx into dz = -(x dx + y dy) / z near the rim, so z dz is bounded.
TEST(ReferenceSamplers, CosineHemisphereEqualsTheConcentricMapWithLibm)
{
    const auto concentric = [](const glm::dvec2& u) {
        const double a = 2.0 * u.x - 1.0, b = 2.0 * u.y - 1.0;
        if (a == 0.0 && b == 0.0)
            return glm::dvec3(0.0, 0.0, 1.0);
        const bool first = std::abs(a) > std::abs(b);
        const double r = first ? a : b;
        const double phi = first ? (kPi / 4.0) * (b / a) : kPi / 2.0 - (kPi / 4.0) * (a / b);
        const double x = r * std::cos(phi), y = r * std::sin(phi);
        return glm::dvec3(x, y, std::sqrt(std::max(0.0, 1.0 - x * x - y * y)));
    };
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<glm::dvec2> us = {{0.5, 0.5}, {0.0, 0.0}, {1.0, 1.0}, {0.0, 1.0}, {0.75, 0.75},
                                  {0.5, 1.0}, {1.0, 0.5}, {0.5, 0.0}, {0.999999, 0.5000001}};
    for (int i = 0; i < 200000; ++i)
        us.emplace_back(unit(rng), unit(rng));
    double worst = 0.0;
    for (const glm::dvec2& u : us) {
        const glm::dvec3 d = sampleCosineHemisphere(u), e = concentric(u);
        worst = std::max({worst, std::abs(d.x - e.x), std::abs(d.y - e.y), std::abs(d.z - e.z) * e.z});
    }
    EXPECT_LT(worst, 1e-15);
}

// The azimuths 2 pi u of the uniform samplers come from a quarter-turn reduction and the same
// series, not libm's sincos: within 1e-15 of libm at every u, including the quarter-turn ties.
TEST(ReferenceSamplers, AzimuthsEqualLibms)
{
    std::mt19937_64 rng(6);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<double> us = {0.0,   0.125, 0.25,  0.375, 0.5,
                              0.625, 0.75,  0.875, 1.0,   0x1.fffffffffffffp-1};
    for (double u : std::vector<double>(us))
        us.insert(us.end(), {std::nextafter(u, -1.0), std::nextafter(u, 2.0)});
    for (int i = 0; i < 200000; ++i)
        us.push_back(unit(rng));
    double worst = 0.0;
    for (const double v : us) {
        if (!(v >= 0.0 && v <= 1.0))
            continue;
        const double phi = 2.0 * kPi * v;
        const glm::dvec3 d = sampleUniformSphere({0.5, v}); // z = 0: the unit circle
        worst = std::max({worst, std::abs(d.x - std::cos(phi)), std::abs(d.y - std::sin(phi))});
        const glm::dvec3 h = sampleUniformHemisphere({0.0, v});
        worst = std::max({worst, std::abs(h.x - std::cos(phi)), std::abs(h.y - std::sin(phi))});
    }
    EXPECT_LT(worst, 1e-15);
}

TEST(ReferenceSamplers, UniformHemisphereChiSquare)
{
    DirectionBins bins;
    double total = 0.0;
    const auto outcome = testDirections(
        bins, sampleUniformHemisphere,
        [](const glm::dvec3& d) { return d.z >= 0.0 ? pdfUniformHemisphere() : 0.0; }, 2, &total);
    EXPECT_NEAR(total, 1.0, 1e-9);
    EXPECT_CHI_SQUARE_PASSES(outcome);
}

TEST(ReferenceSamplers, UniformSphereChiSquare)
{
    DirectionBins bins;
    double total = 0.0;
    const auto outcome = testDirections(
        bins, sampleUniformSphere, [](const glm::dvec3&) { return pdfUniformSphere(); }, 3, &total);
    EXPECT_NEAR(total, 1.0, 1e-12);
    EXPECT_CHI_SQUARE_PASSES(outcome);
}

TEST(ReferenceSamplers, SphericalGaussianBroadChiSquare)
{
    const double k = 4.0; // the sky's default sharpness
    DirectionBins bins;
    double total = 0.0;
    const auto outcome = testDirections(
        bins, [&](const glm::dvec2& u) { return sampleSphericalGaussian(u, k); },
        [&](const glm::dvec3& d) { return pdfSphericalGaussian(d.z, k); }, 4, &total);
    EXPECT_NEAR(total, 1.0, 1e-9);
    EXPECT_CHI_SQUARE_PASSES(outcome);
}

TEST(ReferenceSamplers, SphericalGaussianSharpChiSquare)
{
    // k = 200: 99.9% of the mass within 15 degrees; bins over z in [0.95, 1] resolve the lobe.
    const double k = 200.0;
    DirectionBins bins;
    bins.zBins = 50;
    bins.phiBins = 32;
    bins.zLow = 0.95;
    double total = 0.0;
    const auto outcome = testDirections(
        bins, [&](const glm::dvec2& u) { return sampleSphericalGaussian(u, k); },
        [&](const glm::dvec3& d) { return pdfSphericalGaussian(d.z, k); }, 5, &total);
    EXPECT_NEAR(total, 1.0, 1e-9);
    EXPECT_GT(outcome.dof, 1000);
    EXPECT_CHI_SQUARE_PASSES(outcome);
}

TEST(ReferenceSamplers, SrbfSkyLobesChiSquare)
{
    scene::Sky sky;
    sky.kind = scene::Sky::Kind::Srbf;
    sky.sharpness = 6.0f;
    for (int i = 0; i < scene::kConeDirectionCount; ++i)
        sky.lobes[i] = glm::vec3(float(i % 5), 0.5f * float(i % 3), 0.2f); // lobe 0 is off
    const SkyLobeSampler sampler(sky);
    ASSERT_TRUE(sampler.active());
    DirectionBins bins;
    double total = 0.0;
    const auto outcome = testDirections(
        bins, [&](const glm::dvec2& u) { return sampler.sample(u); },
        [&](const glm::dvec3& d) { return sampler.pdf(d); }, 6, &total);
    EXPECT_NEAR(total, 1.0, 1e-7);
    EXPECT_CHI_SQUARE_PASSES(outcome);
}

TEST(ReferenceSamplers, PointLightPickChiSquare)
{
    std::vector<scene::PointLight> lights;
    for (int i = 0; i < 12; ++i)
        lights.push_back({glm::vec3(float(i)),
                          glm::vec3(float(i % 4), float(i % 3), 1.0f) * float(i == 5 ? 0 : 1)});
    const DiscreteDistribution pick = buildPointLightDistribution(lights);
    ASSERT_EQ(pick.size(), lights.size());
    double pmfSum = 0.0;
    std::vector<double> expected;
    for (std::size_t i = 0; i < lights.size(); ++i) {
        const double power = 4.0 * kPi * computeLuminance(glm::dvec3(lights[i].intensity));
        EXPECT_NEAR(pick.pmf(i), power / pick.total(), 1e-15);
        pmfSum += pick.pmf(i);
        expected.push_back(pick.pmf(i) * kSamples);
    }
    EXPECT_NEAR(pmfSum, 1.0, 1e-12);
    UniformSource source(7);
    std::vector<double> observed(lights.size(), 0.0);
    for (int i = 0; i < kSamples; ++i) {
        double remapped = -1.0;
        observed[pick.sample(source.next(), &remapped)] += 1.0;
        ASSERT_GE(remapped, 0.0);
        ASSERT_LT(remapped, 1.0);
    }
    EXPECT_EQ(observed[5], 0.0); // a light without power is never picked
    const auto outcome = computeChiSquare(observed, expected);
    EXPECT_EQ(outcome.dof, 10);
    EXPECT_CHI_SQUARE_PASSES(outcome);
}

TEST(ReferenceSamplers, TriangleAreaChiSquare)
{
    // Uniform over the area <=> (b1, b2) uniform over the simplex b1 + b2 <= 1 (affine maps keep
    // area ratios). 32 x 32 grid: cells inside the simplex expect 2 h^2 N, cut ones h^2 N.
    const int n = 32;
    const double h = 1.0 / n;
    std::vector<double> expected(n * n, 0.0);
    double total = 0.0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const double area = i + j + 2 <= n ? h * h : (i + j + 1 == n ? 0.5 * h * h : 0.0);
            expected[i * n + j] = 2.0 * area * kSamples; // density 2 = 1 / simplex area
            total += 2.0 * area;
        }
    EXPECT_NEAR(total, 1.0, 1e-12);
    EXPECT_DOUBLE_EQ(pdfTriangleArea(0.25), 4.0);
    UniformSource source(8);
    std::vector<double> observed(n * n, 0.0);
    for (int s = 0; s < kSamples; ++s) {
        const glm::dvec2 b = sampleTriangleBarycentrics(source.next2D());
        ASSERT_GE(b.x, 0.0);
        ASSERT_GE(b.y, 0.0);
        ASSERT_LE(b.x + b.y, 1.0 + 1e-12);
        observed[std::min(n - 1, int(b.x * n)) * n + std::min(n - 1, int(b.y * n))] += 1.0;
    }
    const auto outcome = computeChiSquare(observed, expected);
    EXPECT_CHI_SQUARE_PASSES(outcome);
}

TEST(ReferenceSamplers, ChiSquareRejectsASlightlyWrongDensity)
{
    // Power check (not one of the kChiSquareTests): lobe samples of sharpness 4 tested against the
    // density of sharpness 4.1 must be rejected at the same significance.
    DirectionBins bins;
    double total = 0.0;
    const auto outcome = testDirections(
        bins, [](const glm::dvec2& u) { return sampleSphericalGaussian(u, 4.0); },
        [](const glm::dvec3& d) { return pdfSphericalGaussian(d.z, 4.1); }, 10, &total);
    EXPECT_NEAR(total, 1.0, 1e-9);
    EXPECT_LT(outcome.pValue, kAlpha) << "chi2 = " << outcome.statistic;
}

TEST(ReferenceSamplers, DensitiesMatchClosedForms)
{
    EXPECT_DOUBLE_EQ(pdfCosineHemisphere(1.0), 1.0 / kPi);
    EXPECT_DOUBLE_EQ(pdfCosineHemisphere(-0.5), 0.0);
    EXPECT_DOUBLE_EQ(pdfUniformHemisphere(), 0.5 / kPi);
    EXPECT_DOUBLE_EQ(pdfUniformSphere(), 0.25 / kPi);
    // SG density = lobe / its integral (sky.h's closed form).
    for (double k : {0.01, 1.0, 4.0, 50.0, 1000.0})
        for (double z : {-1.0, 0.0, 0.7, 1.0})
            EXPECT_NEAR(pdfSphericalGaussian(z, k) * scene::integrateSphericalGaussian(k),
                        std::exp(k * (z - 1.0)), 1e-12 * std::max(1.0, k));
    // Extreme uniform numbers stay on the sphere, and the sharpest lobe at its axis.
    for (double u : {0.0, 1e-300, 0.5, 1.0 - 1e-16}) {
        EXPECT_NEAR(glm::length(sampleSphericalGaussian({u, 0.3}, 1e4)), 1.0, 1e-12);
        EXPECT_NEAR(glm::length(sampleSphericalGaussian({u, 0.3}, 1e-6)), 1.0, 1e-12);
    }
}

TEST(ReferenceSamplers, FrameIsOrthonormal)
{
    UniformSource source(9);
    for (int i = 0; i < 1000; ++i) {
        const glm::dvec3 n = sampleUniformSphere(source.next2D());
        const Frame f = Frame::fromNormal(n);
        EXPECT_NEAR(glm::dot(f.tangent, f.bitangent), 0.0, 1e-12);
        EXPECT_NEAR(glm::dot(f.tangent, n), 0.0, 1e-12);
        EXPECT_NEAR(glm::dot(f.bitangent, n), 0.0, 1e-12);
        EXPECT_NEAR(glm::length(f.tangent), 1.0, 1e-12);
        EXPECT_NEAR(glm::dot(glm::cross(f.tangent, f.bitangent), n), 1.0, 1e-12); // right-handed
    }
}

TEST(ReferenceSamplers, DiscreteDistributionRejectsNegativeWeights)
{
    EXPECT_THROW(DiscreteDistribution({1.0, -1.0}), Error);
    EXPECT_TRUE(DiscreteDistribution({0.0, 0.0}).empty());
}

//! The index a binary search over the cumulative sums picks, the sums formed as the distribution
//! forms them (its pinned ends included): the definition the guide table must reproduce.
std::size_t pickByBinarySearch(const std::vector<double>& weights, double u)
{
    double total = 0.0;
    for (double w : weights)
        total += w;
    std::vector<double> cdf(weights.size() + 1, 0.0);
    double sum = 0.0;
    for (std::size_t i = 0; i < weights.size(); ++i) {
        sum += weights[i];
        cdf[i + 1] = sum / total;
    }
    for (std::size_t i = weights.size();
         i > 0 && (i == weights.size() || weights[i] / total == 0.0); --i)
        cdf[i] = 1.0;
    const auto it = std::upper_bound(cdf.begin() + 1, cdf.end(), u);
    return std::min(std::size_t(it - (cdf.begin() + 1)), weights.size() - 1);
}

TEST(ReferenceSamplers, DiscreteDistributionGuideTablePicksWhatABinarySearchPicks)
{
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<std::vector<double>> cases = {{1.0},
                                              {1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0},
                                              {0.0, 0.0, 5.0, 0.0},
                                              {3.0, 0.0, 0.0},
                                              {1e-300, 1.0, 1e-300},
                                              {1e6, 1e-9, 1e-9, 1e-9, 1e6}};
    std::vector<double> random(1000);
    for (double& w : random)
        w = uniform(rng) < 0.3 ? 0.0 : std::pow(uniform(rng), 4.0);
    cases.push_back(random);
    std::vector<double> skewed(257, 1e-6);
    skewed[100] = 1.0;
    cases.push_back(skewed);
    int checked = 0;
    for (const std::vector<double>& weights : cases) {
        const DiscreteDistribution d(weights);
        std::vector<double> us;
        for (int i = 0; i < 2000; ++i)
            us.push_back(uniform(rng));
        // Bucket ends and the cumulative sums, with their neighbours: where a rounded u * n or a
        // walk of the wrong length would show.
        const double n = double(weights.size());
        double sum = 0.0, total = 0.0;
        for (double w : weights)
            total += w;
        for (std::size_t b = 0; b <= weights.size(); ++b) {
            const double edge = double(b) / n;
            const double cdf = sum / total;
            for (double v : {edge, cdf})
                for (double x : {std::nextafter(v, -1.0), v, std::nextafter(v, 2.0)})
                    if (x >= 0.0 && x < 1.0)
                        us.push_back(x);
            if (b < weights.size())
                sum += weights[b];
        }
        us.push_back(0.0);
        us.push_back(0x1.fffffffffffffp-1);
        for (double u : us) {
            const std::size_t expected = pickByBinarySearch(weights, u);
            double remapped = -1.0;
            ASSERT_EQ(d.sample(u, &remapped), expected)
                << "u " << u << ", " << weights.size() << " weights";
            EXPECT_GT(d.pmf(expected), 0.0) << "u " << u;
            EXPECT_TRUE(remapped >= 0.0 && remapped < 1.0) << "u " << u;
            ++checked;
        }
    }
    EXPECT_GT(checked, 16000);
}

} // namespace
} // namespace rtlab::reference
