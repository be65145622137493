#pragma once
// Sampling routines of the ground truth: pure functions of uniform numbers u in [0, 1)^2, each
// with its density. Directions are in a local frame with the axis (normal, lobe axis) along +z;
// Frame maps them to world space. Densities are per steradian, per unit area, or per choice.

#include "scene/render_scene.h"
#include "scene/sky.h"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rtlab::reference {

constexpr double kPi = 3.14159265358979323846;

//! An orthonormal basis around a unit vector [Duff et al. 2017].
struct Frame {
    glm::dvec3 tangent{1.0, 0.0, 0.0};
    glm::dvec3 bitangent{0.0, 1.0, 0.0};
    glm::dvec3 normal{0.0, 0.0, 1.0};

    static Frame fromNormal(const glm::dvec3& n);
    glm::dvec3 toWorld(const glm::dvec3& local) const
    {
        return local.x * tangent + local.y * bitangent + local.z * normal;
    }
};

//! Rec. 709 luminance.
double computeLuminance(const glm::dvec3& rgb);

//! Cosine-weighted hemisphere via the concentric disk map [Shirley & Chiu 1997] lifted to the
//! hemisphere [Malley's method]; pdf = cos(theta) / pi.
glm::dvec3 sampleCosineHemisphere(const glm::dvec2& u);
//! The same for n points at once (independent samples overlap in the pipeline).
void sampleCosineHemispheres(const glm::dvec2* u, glm::dvec3* out, std::size_t n);
double pdfCosineHemisphere(double cosTheta);

//! Uniform hemisphere (z >= 0): z = u.x, pdf = 1 / (2 pi).
glm::dvec3 sampleUniformHemisphere(const glm::dvec2& u);
//! The same for n points at once.
void sampleUniformHemispheres(const glm::dvec2* u, glm::dvec3* out, std::size_t n);
double pdfUniformHemisphere();

//! Uniform sphere: z = 1 - 2 u.x (Archimedes), pdf = 1 / (4 pi).
glm::dvec3 sampleUniformSphere(const glm::dvec2& u);
double pdfUniformSphere();

//! The normalised spherical Gaussian / von Mises-Fisher lobe around +z with sharpness k > 0:
//! pdf = k / (2 pi (1 - exp(-2k))) * exp(k (cos(theta) - 1)). Exact inversion of its CDF in
//! cos(theta), in the numerically stable form of [Jakob 2012].
glm::dvec3 sampleSphericalGaussian(const glm::dvec2& u, double sharpness);
double pdfSphericalGaussian(double cosTheta, double sharpness);

//! Barycentrics (b1, b2) of a point uniformly distributed over a triangle's area
//! (b0 = 1 - b1 - b2) [Turk 1990]; the density is 1 / area.
glm::dvec2 sampleTriangleBarycentrics(const glm::dvec2& u);
double pdfTriangleArea(double area);

//! Picks index i with probability weight_i / sum(weights).
class DiscreteDistribution {
public:
    DiscreteDistribution() = default;
    //! Throws rtlab::Error for a negative or non-finite weight.
    explicit DiscreteDistribution(const std::vector<double>& weights);

    bool empty() const { return mTotal <= 0.0; }
    std::size_t size() const { return mPmf.size(); }
    double total() const { return mTotal; }
    double pmf(std::size_t i) const { return mPmf[i]; }
    //! Index for u in [0, 1); `uRemapped` (optional) receives u rescaled to [0, 1) within the
    //! chosen interval, so one number can drive both the choice and a further sample.
    std::size_t sample(double u, double* uRemapped = nullptr) const;

private:
    std::vector<double> mPmf;
    std::vector<double> mCdf; //!< mCdf[i] = sum of pmf below i; size() + 1 entries
    //! mGuide[b]: the interval of u = b / mGuide.size() (a guide table [Chen & Asau 1974]): the
    //! search starts there and walks a step or two, the same index as a binary search.
    std::vector<std::uint32_t> mGuide;
    double mTotal = 0.0;
};

//! Point lights picked by emitted power 4 pi * luminance(intensity).
DiscreteDistribution buildPointLightDistribution(const std::vector<scene::PointLight>& lights);

//! Directions distributed like the SRBF sky: a mixture of the 16 spherical-Gaussian lobes with
//! weights luminance(peak) * integrateSphericalGaussian(sharpness).
class SkyLobeSampler {
public:
    SkyLobeSampler() = default;
    explicit SkyLobeSampler(const scene::Sky& sky);

    bool active() const { return !mLobes.empty(); }
    glm::dvec3 sample(const glm::dvec2& u) const;  //!< world space, unit length
    double pdf(const glm::dvec3& direction) const; //!< per steradian
    //! pdf(direction), and in `radiance` the sky's radiance there (scene::Sky::radiance, the same
    //! bits), the lobes' 16 exponentials computed once for both: a path that escapes to the sky
    //! needs both, and the exponentials were a fifth of the `full` estimator's time.
    double evaluate(const glm::dvec3& direction, const scene::Sky& sky, glm::dvec3& radiance) const;

private:
    //! The mixture's pdf from the lobes' values (scene::evaluateSkyLobes).
    double sumPdf(const double values[scene::kConeDirectionCount]) const;

    DiscreteDistribution mLobes;
    std::vector<Frame> mFrames;
    std::array<double, scene::kConeDirectionCount> mPmf{}; //!< each lobe's pick probability
    double mSharpness = 0.0;
    double mExpm1 = 0.0;     //!< expm1(-2 k), shared by every lobe's sample
    double mNormalise = 0.0; //!< k / (-2 pi expm1(-2 k)), every lobe's pdf factor
};

} // namespace rtlab::reference
