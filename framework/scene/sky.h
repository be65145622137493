#pragma once
// Sky light: constant, a vertical gradient, or 16 spherical radial basis function lobes on the
// 16 fixed directions the Tomorrow Children's cone tracer uses (a spherical design: equal-weight
// quadrature that integrates low-degree polynomials on the sphere exactly).
// Seed: shared/seeds/000_3da000e866ebc485.txt, "Sky lighting: represent as 16 SRBFs".

#include <glm/vec3.hpp>

#include <array>

namespace rtlab::scene {

constexpr int kConeDirectionCount = 16;

//! The 16 fixed unit directions (a spherical design of 16 points).
const std::array<glm::dvec3, kConeDirectionCount>& getConeDirections();
//! The design's quadrature weight: every direction stands for 4*pi/16 steradians.
double getConeQuadratureWeight();
//! The polynomial degree the 16 directions integrate exactly (the design's strength t).
int getConeDesignStrength();

//! A spherical Gaussian lobe  G(w) = exp(sharpness * (dot(w, axis) - 1)), peak 1 on its axis.
//! Its integral over the sphere is 2*pi/sharpness * (1 - exp(-2*sharpness)).
double integrateSphericalGaussian(double sharpness);

//! The 16 lobes at `toSky`: values[i] = exp(sharpness * (dot(toSky, axis_i) - 1)) with the
//! axes of getConeDirections(), two lobes at a time (SSE2) with an exponential of its own: the
//! same bits as computeExpNonPositive lobe by lobe. The reference's sky pdf and Sky::radiance
//! both take their lobes from here, so that they agree to the bit.
void evaluateSkyLobes(const glm::dvec3& toSky, double sharpness,
                      double values[kConeDirectionCount]);
//! evaluateSkyLobes in `lanes` lanes (1, 2, or 4 where the CPU has AVX2); false where that width
//! is not available. For tests: every width gives the same bits.
bool evaluateSkyLobesInLanes(int lanes, const glm::dvec3& toSky, double sharpness,
                             double values[kConeDirectionCount]);
//! exp(x) for x <= 1 to within 1 ulp of libm's (subnormals and 0 as libm rounds them); for x > 1
//! it returns e. Without calls, so that evaluateSkyLobes can take it two lanes at a time.
double computeExpNonPositive(double x);

struct Sky {
    enum class Kind { None, Constant, Gradient, Srbf };
    Kind kind = Kind::None;
    glm::vec3 constant{0.0f};  //!< radiance, Kind::Constant
    glm::vec3 zenith{0.0f};    //!< radiance straight up (+y), Kind::Gradient
    glm::vec3 horizon{0.0f};   //!< radiance at the horizon; linear in dir.y between zenith and horizon
    glm::vec3 ground{0.0f};    //!< radiance for every direction below the horizon
    std::array<glm::vec3, kConeDirectionCount> lobes{};  //!< peak radiance per lobe, Kind::Srbf
    float sharpness = 4.0f;   //!< lobe sharpness (> 0); 4 overlaps neighbours smoothly

    //! Radiance arriving from direction `toSky` (unit, world space, pointing away from the scene).
    glm::vec3 radiance(const glm::dvec3& toSky) const;
    //! Kind::Srbf's radiance from its lobes' values (evaluateSkyLobes), summed in lobe order.
    glm::vec3 sumLobes(const double values[kConeDirectionCount]) const;
    bool emits() const;  //!< false for Kind::None or all-zero radiance
};

} // namespace rtlab::scene
