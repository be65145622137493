#include "scene/sky.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

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

// The lane types below never cross a call (their functions are always inlined): GCC's note that
// an AVX vector's calling convention differs without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace {

// exp(x) = 2^n exp(r), n = round(x / ln 2), r = x - n ln 2 in [-ln2/2, ln2/2], with ln 2 in two
// parts so that n * ln2Hi is exact for |n| < 2^11 [Cody & Waite 1980, "Software Manual for the
// Elementary Functions"]. exp(r) by its Taylor series to r^13: the first omitted term is below
// 4e-18 on that interval, under a twentieth of an ulp of the result.
constexpr double kLog2E = 1.4426950408889634;
constexpr double kLn2Hi = 6.93147180369123816490e-01; // 0x3fe62e42fee00000: 32 low bits zero
constexpr double kLn2Lo = 1.90821492927058770002e-10;
constexpr double kShifter = 0x1.8p52; // adding it rounds to an integer held in the low bits
// Below -746, exp is under half the least subnormal and rounds to 0, as libm's does.
constexpr double kExpLowest = -746.0;
constexpr double kExpHighest = 1.0;
// 2^(n + 64) from its exponent bits (n sits in the low bits of `shifted`; n + 64 >= -1012, a
// normal), then the exact factor 2^-64, which rounds into the subnormals where exp does.
constexpr std::int64_t kExponentBias = 1023 + 64 - std::bit_cast<std::int64_t>(kShifter);
constexpr double kUnscale = 0x1p-64;

// Lanes of doubles and of the int64s of their bits (GCC and Clang vector extensions); a width of
// 1 is the plain scalar. Every lane takes the same IEEE operations in the same order whatever
// the width, so all widths give the same bits.
// (GCC drops a vector_size that depends on a template parameter: each width is spelled out.)
using Double2 = double __attribute__((vector_size(16)));
using Double4 = double __attribute__((vector_size(32)));
using Int2 = std::int64_t __attribute__((vector_size(16)));
using Int4 = std::int64_t __attribute__((vector_size(32)));
template <int N> struct Lanes;
template <> struct Lanes<1> {
    using D = double;
    using I = std::int64_t;
};
template <> struct Lanes<2> {
    using D = Double2;
    using I = Int2;
};
template <> struct Lanes<4> {
    using D = Double4;
    using I = Int4;
};

template <class V, class S> [[gnu::always_inline]] inline V splat(S value)
{
    if constexpr (std::is_same_v<V, S>) {
        return value;
    } else {
        V v{};
        for (std::size_t i = 0; i < sizeof(V) / sizeof(S); ++i)
            v[i] = value;
        return v;
    }
}

//! exp of each lane of x; always inlined, so that it takes its caller's instruction set.
template <int N>
[[gnu::always_inline]] inline typename Lanes<N>::D computeExpLanes(typename Lanes<N>::D x)
{
    using D = typename Lanes<N>::D;
    using I = typename Lanes<N>::I;
    const D lowest = splat<D>(kExpLowest), highest = splat<D>(kExpHighest);
    const D low = x > lowest ? x : lowest; // NaN takes the lowest
    const D clamped = low < highest ? low : highest;
    const D shifted = clamped * splat<D>(kLog2E) + splat<D>(kShifter);
    const D n = shifted - splat<D>(kShifter);
    const D r = (clamped - n * splat<D>(kLn2Hi)) - n * splat<D>(kLn2Lo);
    // exp(r) = 1 + (r + r^2 Q(r)), Q by Estrin's scheme (terms in pairs, pairs of pairs: depth 4,
    // not Horner's 11). The 1 is added last, so that only that sum rounds at the result's scale:
    // at most half an ulp there, plus r's rounding and the small tail's, under 1.3 ulp in all.
    const D r2 = r * r, r4 = r2 * r2, r8 = r4 * r4;
    const auto pair = [&](double a, double b) { return splat<D>(a) + splat<D>(b) * r; };
    const D q01 = pair(1.0 / 2, 1.0 / 6), q23 = pair(1.0 / 24, 1.0 / 120);
    const D q45 = pair(1.0 / 720, 1.0 / 5040), q67 = pair(1.0 / 40320, 1.0 / 362880);
    const D q89 = pair(1.0 / 3628800, 1.0 / 39916800);
    const D q1011 = pair(1.0 / 479001600, 1.0 / 6227020800.0);
    const D q = ((q01 + q23 * r2) + (q45 + q67 * r2) * r4) + (q89 + q1011 * r2) * r8;
    const D p = splat<D>(1.0) + (r + r2 * q);
    const I exponent = std::bit_cast<I>(shifted) + splat<I>(kExponentBias);
    return p * std::bit_cast<D>(exponent << 52) * splat<D>(kUnscale);
}

} // namespace

double computeExpNonPositive(double x)
{
    return computeExpLanes<1>(x);
}

namespace {

// The cone directions by coordinate, for the lanes of evaluateSkyLobes.
struct ConeAxes {
    alignas(32) double x[kConeDirectionCount];
    alignas(32) double y[kConeDirectionCount];
    alignas(32) double z[kConeDirectionCount];
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

template <int N>
[[gnu::always_inline]] inline void evaluateSkyLobesIn(const glm::dvec3& toSky, double sharpness,
                                                      double values[kConeDirectionCount])
{
    using D = typename Lanes<N>::D;
    const D dx = splat<D>(toSky.x), dy = splat<D>(toSky.y), dz = splat<D>(toSky.z);
    const D k = splat<D>(sharpness), one = splat<D>(1.0);
    // All the lobes' lanes first, so that their exponentials overlap.
    D x[kConeDirectionCount / N];
    for (int i = 0; i < kConeDirectionCount / N; ++i) {
        D ax, ay, az;
        std::memcpy(&ax, kConeAxes.x + N * i, sizeof(D));
        std::memcpy(&ay, kConeAxes.y + N * i, sizeof(D));
        std::memcpy(&az, kConeAxes.z + N * i, sizeof(D));
        // glm::dot's order of operations: x, then y, then z (no fused multiply-adds).
        x[i] = k * ((dx * ax + dy * ay + dz * az) - one);
    }
    for (int i = 0; i < kConeDirectionCount / N; ++i) {
        const D e = computeExpLanes<N>(x[i]);
        std::memcpy(values + N * i, &e, sizeof(D));
    }
}

#if defined(__x86_64__)
// Four lobes at a time where the CPU has AVX2, chosen at run time (the build targets baseline
// x86-64, whose SSE2 takes two).
__attribute__((target("avx2"))) void evaluateSkyLobesAvx2(const glm::dvec3& toSky, double sharpness,
                                                          double values[kConeDirectionCount])
{
    evaluateSkyLobesIn<4>(toSky, sharpness, values);
}

// Read during static initialisation: __builtin_cpu_init first, as GCC asks of such callers.
const bool kHasAvx2 = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
}();
#endif

} // namespace

void evaluateSkyLobes(const glm::dvec3& toSky, double sharpness, double values[kConeDirectionCount])
{
#if defined(__x86_64__)
    if (kHasAvx2)
        return evaluateSkyLobesAvx2(toSky, sharpness, values);
#endif
    evaluateSkyLobesIn<2>(toSky, sharpness, values);
}

bool evaluateSkyLobesInLanes(int lanes, const glm::dvec3& toSky, double sharpness,
                             double values[kConeDirectionCount])
{
    switch (lanes) {
    case 1:
        evaluateSkyLobesIn<1>(toSky, sharpness, values);
        return true;
    case 2:
        evaluateSkyLobesIn<2>(toSky, sharpness, values);
        return true;
#if defined(__x86_64__)
    case 4:
        if (!kHasAvx2)
            return false;
        evaluateSkyLobesAvx2(toSky, sharpness, values);
        return true;
#endif
    default:
        return false;
    }
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
