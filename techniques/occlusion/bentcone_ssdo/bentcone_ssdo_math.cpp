#include "bentcone_ssdo_math.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace rtlab::bentcone_ssdo {

double computeRadicalInverse(unsigned index, unsigned base)
{
    double inverse = 0.0;
    double digitWeight = 1.0 / base;
    while (index > 0) {
        inverse += double(index % base) * digitWeight;
        index /= base;
        digitWeight /= base;
    }
    return inverse;
}

std::vector<glm::vec4> makeSamplePattern(int count)
{
    count = std::clamp(count, kMinSamples, kMaxSamples);
    std::vector<glm::vec4> pattern(static_cast<std::size_t>(count));
    // Distances: P(u <= s) = s^3, the radius law of a uniform point in the ball, stratified:
    // sample k takes stratum rank(k) of N, the rank of k's base-3 radical inverse among those of
    // 0..N-1 (a permutation that decorrelates distance from elevation and azimuth).
    std::vector<int> order(static_cast<std::size_t>(count));
    for (int k = 0; k < count; ++k)
        order[std::size_t(k)] = k;
    std::sort(order.begin(), order.end(), [](int i, int j) {
        return computeRadicalInverse(unsigned(i), 3) < computeRadicalInverse(unsigned(j), 3);
    });
    std::vector<int> rank(static_cast<std::size_t>(count));
    for (int r = 0; r < count; ++r)
        rank[std::size_t(order[std::size_t(r)])] = r;
    auto computeDistance = [&](int k) {
        return float(std::cbrt((rank[std::size_t(k)] + 0.5) / count));
    };
    // [Klehm et al. 2011]: samples in the normal-oriented hemisphere of radius r.
    // Directions are cosine-distributed (Malley's method: a uniform point on the unit disk lifted
    // to the hemisphere), so an unweighted sum over unoccluded samples integrates
    // V(w) cos(theta) dw / pi: the cosine weight is carried by the distribution. Samples come in
    // antipodal pairs (azimuths phi and phi + pi at one elevation) whose tangential parts cancel
    // exactly, so that an unoccluded pixel's bent normal is its normal.
    const int pairCount = count / 2;
    for (int j = 0; j < pairCount; ++j) {
        const double diskRadius2 = (j + 0.5) / pairCount;
        const double phi = std::numbers::pi * computeRadicalInverse(unsigned(j), 2);
        const double diskRadius = std::sqrt(diskRadius2);
        const float x = float(diskRadius * std::cos(phi));
        const float y = float(diskRadius * std::sin(phi));
        const float z = float(std::sqrt(1.0 - diskRadius2));
        pattern[std::size_t(2 * j)] = glm::vec4(x, y, z, computeDistance(2 * j));
        pattern[std::size_t(2 * j + 1)] = glm::vec4(-x, -y, z, computeDistance(2 * j + 1));
    }
    if (count % 2 == 1) // the unpaired sample looks along the normal
        pattern[std::size_t(count - 1)] = glm::vec4(0.0f, 0.0f, 1.0f, computeDistance(count - 1));
    return pattern;
}

int getCellRank(int x, int y)
{
    static constexpr int kBayer[kCellSide][kCellSide] = {
        {0, 8, 2, 10}, {12, 4, 14, 6}, {3, 11, 1, 9}, {15, 7, 13, 5}};
    return kBayer[y & (kCellSide - 1)][x & (kCellSide - 1)];
}

int getCellIndex(int x, int y)
{
    return (y & (kCellSide - 1)) * kCellSide + (x & (kCellSide - 1));
}

double getFrameTurn(int frameIndex)
{
    // 40503 / 65536 = 0.61803 ~ the golden ratio's fraction: successive frames fill the circle
    // evenly. Unsigned arithmetic wraps, so negative and huge indices are fine.
    const std::uint32_t fixed = (std::uint32_t(frameIndex) * 40503u) & 0xffffu;
    return double(fixed) / 65536.0;
}

std::array<glm::vec2, kCellCount> makeCellRotations(int frameIndex)
{
    std::array<glm::vec2, kCellCount> rotations{};
    const double frameTurn = getFrameTurn(frameIndex);
    for (int y = 0; y < kCellSide; ++y) {
        for (int x = 0; x < kCellSide; ++x) {
            const double turn = (getCellRank(x, y) + 0.5) / kCellCount + frameTurn;
            const double angle = 2.0 * std::numbers::pi * turn;
            rotations[std::size_t(getCellIndex(x, y))] =
                glm::vec2(float(std::cos(angle)), float(std::sin(angle)));
        }
    }
    return rotations;
}

glm::vec4 evaluateShBasis(const glm::vec3& w)
{
    return {kShY00, kShY1 * w.y, kShY1 * w.z, kShY1 * w.x};
}

float reconstructSh(const glm::vec4& sh, const glm::vec3& w)
{
    return glm::dot(sh, evaluateShBasis(w));
}

float computeAperture(float visibleFraction)
{
    return std::asin(std::sqrt(std::clamp(visibleFraction, 0.0f, 1.0f)));
}

BentCone convertShToBentCone(const glm::vec4& sh, const glm::vec3& normal)
{
    // [Tomorrow Children talk, "Screen Space Directional Occlusion"]: 2-band SH of the
    // visibility, "easy to convert into a visibility cone". L00 of V cos is
    // Y00 * Int V cos dw = Y00 * pi * A; L1 is Y1 * Int V cos w dw with components (y, z, x).
    BentCone cone;
    cone.visibleFraction = std::clamp(sh.x / (kPi * kShY00), 0.0f, 1.0f);
    const glm::vec3 l1(sh.w, sh.y, sh.z);
    const float length2 = glm::dot(l1, l1);
    cone.axis = length2 > 0.0f ? l1 / std::sqrt(length2) : normal;
    cone.aperture = computeAperture(cone.visibleFraction);
    return cone;
}

Cap makeCap(double angle)
{
    const double half = 0.5 * angle;
    return {float(angle), float(std::cos(angle)), float(std::sin(angle)),
            float(2.0 * std::sin(half) * std::sin(half))};
}

Cap makeApertureCap(double visibleFraction)
{
    const double a = std::clamp(visibleFraction, 0.0, 1.0);
    const double sine = std::sqrt(a);
    const double cosine = std::sqrt(1.0 - a);
    return {float(std::atan2(sine, cosine)), float(cosine), float(sine), float(a / (1.0 + cosine))};
}

Cap getDirectionCap()
{
    // cos = 7/8, sin = sqrt(15)/8, versine = 1/8 exactly.
    return {float(std::acos(0.875)), kConeCosHalfAngle, float(std::sqrt(15.0) / 8.0), 0.125f};
}

Cap getHemisphereCap()
{
    return {0.5f * kPi, 0.0f, 1.0f, 1.0f};
}

std::vector<glm::vec4> makeApertureTable(int sampleCount)
{
    sampleCount = std::clamp(sampleCount, kMinSamples, kMaxSamples);
    std::vector<glm::vec4> table(static_cast<std::size_t>(sampleCount + 1));
    for (int c = 0; c <= sampleCount; ++c) {
        const Cap cap = makeApertureCap(double(c) / sampleCount);
        table[std::size_t(c)] = glm::vec4(cap.angle, cap.cosine, cap.sine, cap.versine);
    }
    return table;
}

float intersectCaps(float cosD, float sinD, const Cap& a, const Cap& b, ConeIntersection mode)
{
    const float smallerCap = 2.0f * kPi * std::min(a.versine, b.versine);
    // Containment: d <= |a - b|, i.e. cos d >= cos(a - b); separation: cos d <= cos(a + b).
    // Both tested on accurately formed differences: (1 - cos d) - (1 - cos(a - b)) and
    // (1 + cos d) - (1 + cos(a + b)), with 1 -+ cos x = sin^2 x / (1 +- cos x) where it cancels.
    const float oneMinusCosD = cosD > 0.0f ? sinD * sinD / (1.0f + cosD) : 1.0f - cosD;
    const float onePlusCosD = cosD < 0.0f ? sinD * sinD / (1.0f - cosD) : 1.0f + cosD;
    const float sinDifference = a.sine * b.cosine - a.cosine * b.sine;
    const float cosDifference = a.cosine * b.cosine + a.sine * b.sine;
    const float oneMinusCosDifference = sinDifference * sinDifference / (1.0f + cosDifference);
    const float sinSum = a.sine * b.cosine + a.cosine * b.sine;
    const float cosSum = a.cosine * b.cosine - a.sine * b.sine;
    const float onePlusCosSum = cosSum < 0.0f ? sinSum * sinSum / (1.0f - cosSum) : 1.0f + cosSum;
    const float inner = oneMinusCosD - oneMinusCosDifference; // cos(a - b) - cos d
    const float outer = onePlusCosD - onePlusCosSum;          // cos d - cos(a + b)
    if (inner <= 0.0f)
        return smallerCap; // the smaller cap lies inside the larger one
    if (outer <= 0.0f)
        return 0.0f; // disjoint
    if (mode == ConeIntersection::Smoothstep) {
        // [Oat & Sander 2007]: the smaller cap's solid angle times a smoothstep from containment
        // (d = |a - b|) to separation (d = a + b).
        const float d = std::atan2(sinD, cosD);
        const float lo = std::abs(a.angle - b.angle);
        const float hi = a.angle + b.angle;
        const float x = std::clamp(1.0f - (d - lo) / (hi - lo), 0.0f, 1.0f);
        return smallerCap * (x * x * (3.0f - 2.0f * x));
    }
    // [Mazonka 2012, Sec. 4] (Gauss-Bonnet on the lens): Omega = 2 (pi - gamma - cos(a) beta_A
    // - cos(b) beta_B) = 2 (va beta_A + vb beta_B - E), E = beta_A + beta_B + gamma - pi the
    // excess of the triangle (axis A, axis B, boundary crossing P). Its Gram determinant
    // (A.(B x P))^2 = (cos(a - b) - cos d)(cos d - cos(a + b)) gives every angle by atan2:
    // tan beta_A = r / (cos b - cos a cos d), tan beta_B = r / (cos a - cos b cos d), and
    // tan(E / 2) = r / (1 + cos a + cos b + cos d) [Van Oosterom & Strackee 1983].
    const float r = std::sqrt(inner * outer);
    const float betaA = std::atan2(r, (a.versine - b.versine) + a.cosine * oneMinusCosD);
    const float betaB = std::atan2(r, (b.versine - a.versine) + b.cosine * oneMinusCosD);
    const float excess = 2.0f * std::atan2(r, (onePlusCosD + a.cosine) + b.cosine);
    const float omega = 2.0f * ((a.versine * betaA + b.versine * betaB) - excess);
    return std::clamp(omega, 0.0f, smallerCap);
}

float intersectCaps(float d, float a, float b, ConeIntersection mode)
{
    return intersectCaps(float(std::cos(double(d))), float(std::abs(std::sin(double(d)))),
                         makeCap(a), makeCap(b), mode);
}

float computeConeVisibility(const glm::vec3& direction, const glm::vec3& axis, const Cap& bent,
                            const glm::vec3& normal, ConeIntersection mode)
{
    // [Tomorrow Children talk]: "intersect the visibility cone with cones for each of the
    // directions we trace" (16 of them, 4 pi / 16 sr each).
    const Cap cone = getDirectionCap();
    const Cap hemisphere = getHemisphereCap();
    const float coneArea = 2.0f * kPi * cone.versine;
    const glm::vec3 crossN = glm::cross(direction, normal);
    const float aboveSurface =
        intersectCaps(glm::dot(direction, normal), glm::length(crossN), cone, hemisphere, mode);
    if (aboveSurface <= 0.0f)
        return 0.0f;
    const glm::vec3 crossB = glm::cross(direction, axis);
    const float inBent =
        intersectCaps(glm::dot(direction, axis), glm::length(crossB), cone, bent, mode);
    return std::clamp(std::min(inBent, aboveSurface) / coneArea, 0.0f, 1.0f);
}

} // namespace rtlab::bentcone_ssdo
