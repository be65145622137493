#include "scene/sky.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#if defined(__x86_64__)
#include <immintrin.h>
#elif defined(__SSE2__)
#include <emmintrin.h>
#endif

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

namespace {

// computeExpNonPositive's constants. exp(x) = 2^n exp(r), n = round(x / ln 2), r = x - n ln 2 in
// [-ln2/2, ln2/2], with ln 2 in two parts so that n * ln2Hi is exact for |n| < 2^11 [Cody & Waite
// 1980, "Software Manual for the Elementary Functions"]. exp(r) by its Taylor series to r^13: the
// first omitted term is below 4e-18 on that interval, under a twentieth of an ulp of the result.
constexpr double kLog2E = 1.4426950408889634;
constexpr double kLn2Hi = 6.93147180369123816490e-01; // 0x3fe62e42fee00000: 32 low bits zero
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kShifter = 0x1.8p52; // adding it rounds to an integer held in the low bits
// Below -746, exp is under half the least subnormal and rounds to 0, as libm's does.
constexpr double kExpLowest = -746.0;
constexpr double kExpHighest = 1.0;
constexpr double kTaylor[14] = {1.0,
                                1.0,
                                1.0 / 2,
                                1.0 / 6,
                                1.0 / 24,
                                1.0 / 120,
                                1.0 / 720,
                                1.0 / 5040,
                                1.0 / 40320,
                                1.0 / 362880,
                                1.0 / 3628800,
                                1.0 / 39916800,
                                1.0 / 479001600,
                                1.0 / 6227020800.0};
// 2^(n + 64) from its exponent bits (n sits in the low bits of `shifted`; n + 64 >= -1012, a
// normal), then the exact factor 2^-64, which rounds into the subnormals where exp does.
constexpr std::int64_t kExponentBias = 1023 + 64 - std::bit_cast<std::int64_t>(kShifter);
constexpr double kUnscale = 0x1p-64;

} // namespace

double computeExpNonPositive(double x)
{
    // Each step as evaluateSkyLobes's two-lane one takes it, so that both give the same bits.
    const double low = x > kExpLowest ? x : kExpLowest;
    const double clamped = low < kExpHighest ? low : kExpHighest;
    const double shifted = clamped * kLog2E + kShifter;
    const double n = shifted - kShifter;
    const double r = (clamped - n * kLn2Hi) - n * kLn2Lo;
    double p = kTaylor[13];
    for (int i = 12; i >= 0; --i)
        p = p * r + kTaylor[i];
    const std::int64_t exponent = std::bit_cast<std::int64_t>(shifted) + kExponentBias;
    return p * std::bit_cast<double>(std::uint64_t(exponent) << 52) * kUnscale;
}

namespace {

// The cone directions by coordinate, two lobes per SSE2 register.
struct ConeAxes {
    alignas(16) double x[kConeDirectionCount];
    alignas(16) double y[kConeDirectionCount];
    alignas(16) double z[kConeDirectionCount];
    ConeAxes()
    {
        for (int i = 0; i < kConeDirectionCount; ++i) {
            x[i] = kConeDirections[i].x;
            y[i] = kConeDirections[i].y;
            z[i] = kConeDirections[i].z;
        }
    }
};
const ConeAxes kConeAxes;

} // namespace

#if defined(__x86_64__)
namespace {

// Four lobes at a time where the CPU has AVX2 (chosen at run time: the build targets baseline
// x86-64). Every lane takes computeExpNonPositive's steps, so the bits are the same as SSE2's.
__attribute__((target("avx2"))) void evaluateSkyLobesAvx2(const glm::dvec3& toSky, double sharpness,
                                                          double values[kConeDirectionCount])
{
    const __m256d dx = _mm256_set1_pd(toSky.x), dy = _mm256_set1_pd(toSky.y),
                  dz = _mm256_set1_pd(toSky.z);
    const __m256d k = _mm256_set1_pd(sharpness), one = _mm256_set1_pd(1.0);
    const __m256d shifter = _mm256_set1_pd(kShifter);
    for (int i = 0; i < kConeDirectionCount; i += 4) {
        // glm::dot's order of operations: x, then y, then z (no fused multiply-adds).
        const __m256d cosine =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, _mm256_load_pd(kConeAxes.x + i)),
                                        _mm256_mul_pd(dy, _mm256_load_pd(kConeAxes.y + i))),
                          _mm256_mul_pd(dz, _mm256_load_pd(kConeAxes.z + i)));
        const __m256d x = _mm256_mul_pd(k, _mm256_sub_pd(cosine, one));
        const __m256d clamped = _mm256_min_pd(_mm256_max_pd(x, _mm256_set1_pd(kExpLowest)),
                                              _mm256_set1_pd(kExpHighest));
        const __m256d shifted =
            _mm256_add_pd(_mm256_mul_pd(clamped, _mm256_set1_pd(kLog2E)), shifter);
        const __m256d n = _mm256_sub_pd(shifted, shifter);
        const __m256d r =
            _mm256_sub_pd(_mm256_sub_pd(clamped, _mm256_mul_pd(n, _mm256_set1_pd(kLn2Hi))),
                          _mm256_mul_pd(n, _mm256_set1_pd(kLn2Lo)));
        __m256d p = _mm256_set1_pd(kTaylor[13]);
        for (int t = 12; t >= 0; --t)
            p = _mm256_add_pd(_mm256_mul_pd(p, r), _mm256_set1_pd(kTaylor[t]));
        const __m256i exponent =
            _mm256_add_epi64(_mm256_castpd_si256(shifted), _mm256_set1_epi64x(kExponentBias));
        const __m256d scale = _mm256_castsi256_pd(_mm256_slli_epi64(exponent, 52));
        _mm256_storeu_pd(values + i,
                         _mm256_mul_pd(_mm256_mul_pd(p, scale), _mm256_set1_pd(kUnscale)));
    }
}

const bool kHasAvx2 = __builtin_cpu_supports("avx2");

} // namespace
#endif

void evaluateSkyLobes(const glm::dvec3& toSky, double sharpness, double values[kConeDirectionCount])
{
#if defined(__x86_64__)
    if (kHasAvx2) {
        evaluateSkyLobesAvx2(toSky, sharpness, values);
        return;
    }
#endif
#if defined(__SSE2__)
    // Two lobes at a time; the compiler keeps a scalar loop (a libm call would stop it anyway).
    const __m128d dx = _mm_set1_pd(toSky.x), dy = _mm_set1_pd(toSky.y), dz = _mm_set1_pd(toSky.z);
    const __m128d k = _mm_set1_pd(sharpness), one = _mm_set1_pd(1.0);
    const __m128d shifter = _mm_set1_pd(kShifter);
    for (int i = 0; i < kConeDirectionCount; i += 2) {
        // glm::dot's order of operations: x, then y, then z.
        const __m128d cosine = _mm_add_pd(_mm_add_pd(_mm_mul_pd(dx, _mm_load_pd(kConeAxes.x + i)),
                                                     _mm_mul_pd(dy, _mm_load_pd(kConeAxes.y + i))),
                                          _mm_mul_pd(dz, _mm_load_pd(kConeAxes.z + i)));
        const __m128d x = _mm_mul_pd(k, _mm_sub_pd(cosine, one));
        const __m128d clamped =
            _mm_min_pd(_mm_max_pd(x, _mm_set1_pd(kExpLowest)), _mm_set1_pd(kExpHighest));
        const __m128d shifted = _mm_add_pd(_mm_mul_pd(clamped, _mm_set1_pd(kLog2E)), shifter);
        const __m128d n = _mm_sub_pd(shifted, shifter);
        const __m128d r = _mm_sub_pd(_mm_sub_pd(clamped, _mm_mul_pd(n, _mm_set1_pd(kLn2Hi))),
                                     _mm_mul_pd(n, _mm_set1_pd(kLn2Lo)));
        __m128d p = _mm_set1_pd(kTaylor[13]);
        for (int t = 12; t >= 0; --t)
            p = _mm_add_pd(_mm_mul_pd(p, r), _mm_set1_pd(kTaylor[t]));
        const __m128i exponent =
            _mm_add_epi64(_mm_castpd_si128(shifted), _mm_set1_epi64x(kExponentBias));
        const __m128d scale = _mm_castsi128_pd(_mm_slli_epi64(exponent, 52));
        _mm_storeu_pd(values + i, _mm_mul_pd(_mm_mul_pd(p, scale), _mm_set1_pd(kUnscale)));
    }
#else
    for (int i = 0; i < kConeDirectionCount; ++i) {
        const double cosine =
            toSky.x * kConeAxes.x[i] + toSky.y * kConeAxes.y[i] + toSky.z * kConeAxes.z[i];
        values[i] = computeExpNonPositive(sharpness * (cosine - 1.0));
    }
#endif
}

glm::vec3 Sky::sumLobes(const double values[kConeDirectionCount]) const
{
    glm::dvec3 sum(0.0);
    for (int i = 0; i < kConeDirectionCount; ++i)
        sum += glm::dvec3(lobes[i]) * values[i];
    return glm::vec3(sum);
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
        double values[kConeDirectionCount];
        evaluateSkyLobes(toSky, double(sharpness), values);
        return sumLobes(values);
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
