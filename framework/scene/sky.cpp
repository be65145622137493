#include "scene/sky.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::scene {

// A spherical 5-design of 16 points: the equal-weight rule (4*pi/16) * sum f(d_i) integrates every
// polynomial of degree <= 5 over the sphere exactly. Designs of 16 points and strength 5 exist
// [Hardin & Sloane 1996, "McLaren's improved snub cube and other new spherical designs"]; these
// coordinates were found by minimising sum_{l=1..5} sum_{i,j} P_l(d_i . d_j), which is zero exactly
// for a 5-design [Delsarte, Goethals & Seidel 1977], then polished by Gauss-Newton on the monomial
// moments in extended precision. sky_test.cpp checks the quadrature to 1e-12.
static const std::array<glm::dvec3, kConeDirectionCount> kConeDirections = {{
    {0.52474002316880962, 0.85120293265610045, -0.01007350596620967},
    {-0.27026365787087744, -0.64447261474211771, 0.71527100044788006},
    {-0.79456186233213450, -0.60613868213941453, 0.03559978850476407},
    {-0.57782444109589254, 0.14089865846115527, 0.80390701161021486},
    {0.49733946615936411, -0.82633280051626157, 0.26424904577173212},
    {-0.95586419919699336, 0.28780681653428427, 0.05908357682039434},
    {0.47490504959422167, -0.14726113813587515, 0.86762857898114246},
    {0.11606182423743419, 0.62734803956900987, 0.77004161589072507},
    {0.95566731420557076, 0.16605156533682328, 0.24316015752647802},
    {-0.27485633861673549, 0.63354412518532629, -0.72323981815533501},
    {-0.69034050202445837, -0.10576248446350728, -0.71571243397381687},
    {0.09937362819280251, -0.37432441696962744, -0.92195776089805065},
    {-0.37777507422881347, 0.92346396130620868, 0.06708431605121710},
    {-0.10298653449294273, -0.94049434898330483, -0.32382735098135787},
    {0.83629980726644272, -0.38493797732423138, -0.39041693864334356},
    {0.54008549703420233, 0.39940836422543178, -0.74079728298643445},
}};

const std::array<glm::dvec3, kConeDirectionCount>& getConeDirections()
{
    return kConeDirections;
}

double getConeQuadratureWeight()
{
    return 4.0 * glm::pi<double>() / double(kConeDirectionCount);
}

int getConeDesignStrength()
{
    return 5;
}

double integrateSphericalGaussian(double sharpness)
{
    // integral of exp(k (cos t - 1)) over the sphere = 2 pi (1 - exp(-2k)) / k; expm1 keeps it
    // accurate for small k, where it tends to 4 pi.
    return -2.0 * glm::pi<double>() * std::expm1(-2.0 * sharpness) / sharpness;
}

glm::vec3 Sky::radiance(const glm::dvec3& toSky) const
{
    switch (kind) {
    case Kind::None:
        return glm::vec3(0.0f);
    case Kind::Constant:
        return constant;
    case Kind::Gradient: {
        if (toSky.y < 0.0)
            return ground;
        return glm::mix(horizon, zenith, float(std::min(1.0, toSky.y)));
    }
    case Kind::Srbf: {
        glm::dvec3 sum(0.0);
        for (int i = 0; i < kConeDirectionCount; ++i)
            sum += glm::dvec3(lobes[i]) *
                   std::exp(double(sharpness) * (glm::dot(toSky, kConeDirections[i]) - 1.0));
        return glm::vec3(sum);
    }
    }
    return glm::vec3(0.0f);
}

bool Sky::emits() const
{
    switch (kind) {
    case Kind::None: return false;
    case Kind::Constant: return glm::dot(constant, constant) > 0.0f;
    case Kind::Gradient:
        return glm::dot(zenith, zenith) + glm::dot(horizon, horizon) + glm::dot(ground, ground) > 0.0f;
    case Kind::Srbf:
        return std::any_of(lobes.begin(), lobes.end(), [](const glm::vec3& l) { return glm::dot(l, l) > 0.0f; });
    }
    return false;
}

} // namespace rtlab::scene
