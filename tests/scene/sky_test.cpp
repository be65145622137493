// The 16 cone directions are a spherical 5-design; sky radiance and lobe integrals.

#include "scene/sky.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

using namespace rtlab::scene;

namespace {

// Exact integral of x^a y^b z^c over the unit sphere [Folland 2001, "How to integrate a
// polynomial over a sphere"]: 0 if any exponent is odd, else 2 G(a') G(b') G(c') / G(a'+b'+c'),
// with G the gamma function and a' = (a+1)/2.
double integrateMonomial(int a, int b, int c)
{
    if (a % 2 || b % 2 || c % 2)
        return 0.0;
    const double ha = (a + 1) / 2.0, hb = (b + 1) / 2.0, hc = (c + 1) / 2.0;
    return 2.0 * std::tgamma(ha) * std::tgamma(hb) * std::tgamma(hc) / std::tgamma(ha + hb + hc);
}

double quadratureOfMonomial(int a, int b, int c)
{
    double sum = 0.0;
    for (const auto& d : getConeDirections())
        sum += std::pow(d.x, a) * std::pow(d.y, b) * std::pow(d.z, c);
    return sum * getConeQuadratureWeight();
}

} // namespace

TEST(ConeDirections, AreUnitAndDistinct)
{
    const auto& dirs = getConeDirections();
    for (std::size_t i = 0; i < dirs.size(); ++i) {
        EXPECT_NEAR(glm::length(dirs[i]), 1.0, 1e-15);
        for (std::size_t j = 0; j < i; ++j)
            EXPECT_LT(glm::dot(dirs[i], dirs[j]), 0.95) << i << " " << j;
    }
}

TEST(ConeDirections, IntegrateEveryPolynomialOfDegreeFiveExactly)
{
    // The weights sum to 4 pi and every monomial of degree 1..5 is integrated exactly. The
    // tolerance 1e-12 is float64 round-off of 16 terms of magnitude <= 4 pi / 16.
    EXPECT_NEAR(16 * getConeQuadratureWeight(), 4.0 * glm::pi<double>(), 1e-14);
    for (int degree = 0; degree <= getConeDesignStrength(); ++degree)
        for (int a = 0; a <= degree; ++a)
            for (int b = 0; a + b <= degree; ++b) {
                const int c = degree - a - b;
                EXPECT_NEAR(quadratureOfMonomial(a, b, c), integrateMonomial(a, b, c), 1e-12)
                    << "x^" << a << " y^" << b << " z^" << c;
            }
}

TEST(ConeDirections, StrengthIsExactlyFive)
{
    // No 16-point set integrates all degree-6 polynomials; the design must miss some by a
    // visible margin, so the reported strength is not an understatement of an accident.
    double worst = 0.0;
    for (int a = 0; a <= 6; ++a)
        for (int b = 0; a + b <= 6; ++b)
            worst = std::max(worst, std::abs(quadratureOfMonomial(a, b, 6 - a - b) -
                                             integrateMonomial(a, b, 6 - a - b)));
    EXPECT_GT(worst, 1e-3);
}

TEST(Sky, SphericalGaussianIntegralMatchesQuadrature)
{
    // Midpoint rule in cos(theta) (the lobe only depends on it): 2 pi * integral of
    // exp(k (u - 1)) du over [-1, 1].
    for (double k : {0.01, 1.0, 4.0, 40.0}) {
        const int n = 200000;
        double sum = 0.0;
        for (int i = 0; i < n; ++i) {
            const double u = -1.0 + (i + 0.5) * 2.0 / n;
            sum += std::exp(k * (u - 1.0));
        }
        const double numeric = 2.0 * glm::pi<double>() * sum * 2.0 / n;
        EXPECT_NEAR(integrateSphericalGaussian(k), numeric, 1e-6 * numeric) << k;
    }
}

TEST(Sky, RadianceOfEachKind)
{
    Sky sky;
    EXPECT_EQ(sky.radiance({0, 1, 0}), glm::vec3(0.0f));
    EXPECT_FALSE(sky.emits());

    sky.kind = Sky::Kind::Constant;
    sky.constant = glm::vec3(0.5f);
    EXPECT_EQ(sky.radiance({1, 0, 0}), glm::vec3(0.5f));

    sky.kind = Sky::Kind::Gradient;
    sky.zenith = glm::vec3(1.0f);
    sky.horizon = glm::vec3(0.0f);
    sky.ground = glm::vec3(0.25f);
    EXPECT_EQ(sky.radiance({0, 1, 0}), glm::vec3(1.0f));
    EXPECT_NEAR(sky.radiance(glm::normalize(glm::dvec3(1, 1, 0))).x, std::sqrt(0.5), 1e-6);
    EXPECT_EQ(sky.radiance({0, -1, 0}), glm::vec3(0.25f));

    sky.kind = Sky::Kind::Srbf;
    sky.lobes.fill(glm::vec3(0.0f));
    sky.lobes[3] = glm::vec3(2.0f);
    EXPECT_NEAR(sky.radiance(getConeDirections()[3]).x, 2.0, 1e-6);  // peak on the axis
    EXPECT_TRUE(sky.emits());
}

// The lobes' exponential is libm's to 1 ulp: the first omitted Taylor term is below a twentieth
// of an ulp; the 1 is added last, so that sum rounds by at most half an ulp, and r's rounding and
// the small tail's add under 0.8 more, and libm's own is about half an ulp: a difference under 2
// ulp within one binade is at most 1.
// In the subnormals the result is rounded twice (to a normal, then by the exact 2^-64 into the
// subnormals), so it may be one least subnormal off libm's.
TEST(Sky, ExpNonPositiveIsLibmsToOneUlp)
{
    int checked = 0;
    for (double x = -750.0; x <= 1.0; x += 0.000731) {
        const double expected = std::exp(x), got = computeExpNonPositive(x);
        ASSERT_TRUE(std::isfinite(got)) << x;
        ASSERT_GE(got, 0.0) << x;
        const double ulp = std::nextafter(expected, 2.0 * expected + 1.0) - expected;
        if (expected >= 0x1p-1022)
            ASSERT_LE(std::abs(got - expected), ulp) << "x = " << x;
        else
            ASSERT_LE(std::abs(got - expected),
                      4e-16 * expected + std::numeric_limits<double>::denorm_min())
                << "x = " << x;
        ++checked;
    }
    EXPECT_GT(checked, 1000000);
    EXPECT_EQ(computeExpNonPositive(0.0), 1.0);
    EXPECT_EQ(computeExpNonPositive(-746.0), 0.0);
    EXPECT_EQ(computeExpNonPositive(-1e300), 0.0);
    EXPECT_EQ(computeExpNonPositive(-std::numeric_limits<double>::infinity()), 0.0);
}

// Whichever vector width the CPU gives evaluateSkyLobes, every lobe is computeExpNonPositive's
// bits, also for sharpness so large or small that the exponent leaves the exponential's range;
// so are the widths this CPU does not pick (1, 2 and, with AVX2, 4 lanes).
TEST(Sky, LobesAreTheScalarExponentialToTheBit)
{
    const double sharpnesses[] = {1e-30, 0.01, 3.0, 4.0, 50.0, 1e4, 3.4e38};
    for (int j = 0; j < 2000; ++j) {
        const double z = 1.0 - 2.0 * (j + 0.5) / 2000.0, phi = 2.399963229728653 * j;
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const glm::dvec3 d(r * std::cos(phi), z, r * std::sin(phi));
        for (const double k : sharpnesses) {
            double values[kConeDirectionCount];
            evaluateSkyLobes(d, k, values);
            for (int i = 0; i < kConeDirectionCount; ++i) {
                const glm::dvec3& a = getConeDirections()[i];
                const double expected =
                    computeExpNonPositive(k * ((d.x * a.x + d.y * a.y + d.z * a.z) - 1.0));
                ASSERT_EQ(std::bit_cast<std::uint64_t>(values[i]),
                          std::bit_cast<std::uint64_t>(expected))
                    << "direction " << j << ", sharpness " << k << ", lobe " << i;
                ASSERT_LE(values[i], std::exp(1e-12 * k) * (1.0 + 1e-15));
            }
            for (const int lanes : {1, 2, 4}) {
                double other[kConeDirectionCount];
                if (!evaluateSkyLobesInLanes(lanes, d, k, other)) {
                    ASSERT_EQ(lanes, 4) << "1 and 2 lanes exist everywhere";
                    continue;
                }
                for (int i = 0; i < kConeDirectionCount; ++i)
                    ASSERT_EQ(std::bit_cast<std::uint64_t>(other[i]),
                              std::bit_cast<std::uint64_t>(values[i]))
                        << lanes << " lanes, direction " << j << ", sharpness " << k << ", lobe "
                        << i;
            }
        }
    }
}
