// The 16 cone directions are a spherical 5-design; sky radiance and lobe integrals.

#include "scene/sky.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <gtest/gtest.h>

#include <cmath>

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
