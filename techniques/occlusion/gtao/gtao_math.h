#pragma once
// The per-slice closed forms of GTAO and the fixed sample sequences, shared by the C++ estimator
// (gtao_cpu.cpp) and its tests. shaders/gtao.comp holds the GLSL twins with the same formulas.
//
// Slice parametrisation [Jimenez et al. 2016, Alg. 1]: a slice is the plane through the pixel's
// point p that contains the view vector v (unit, p -> camera) and a unit direction s orthogonal
// to v. A direction in it is w(theta) = sin(theta) s + cos(theta) v, theta signed (theta > 0 on
// the +s side). Over slice angles phi in [0, pi) and theta in (-pi, pi] these cover the sphere with
// dw = |sin(theta)| dtheta dphi. The normal projected into the slice is
// n_p = (n.s) s + (n.v) v = |n_p| (sin(gamma) s + cos(gamma) v), so n.w = |n_p| cos(theta - gamma),
// and the cosine-weighted visibility is
//   A = (1/pi) Int_0^pi |n_p| Int_{h1}^{h2} cos(theta - gamma) |sin(theta)| dtheta dphi,
// with h1 <= 0 <= h2 the horizons of the two sides clamped to the normal's hemisphere
// [gamma - pi/2, gamma + pi/2].

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

namespace rtlab::occlusion::gtao {

// Bitwise agreement with the shader. The sample positions, the radius test and the horizon
// cosines decide which depth samples count, which is discontinuous (a sample at the radius is in
// or out), so the C++ and GLSL versions compute them with the same IEEE operations in the same
// order: explicit dot/cross/length below, no fused multiply-add (the shader marks these values
// `precise`, this code is built with -ffp-contract=off), no driver transcendental functions
// (their accuracy varies between drivers): polynomials with the same float coefficients, printed
// to 9 significant digits so that every compiler parses them to the same float.

inline float dot3(const glm::vec3& a, const glm::vec3& b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

inline float length3(const glm::vec3& a)
{
    return std::sqrt(dot3(a, a));
}

inline glm::vec3 cross3(const glm::vec3& a, const glm::vec3& b)
{
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

inline float length2(const glm::vec2& a)
{
    return std::sqrt(a.x * a.x + a.y * a.y);
}

//! (cos(phi), sin(phi)) for phi in [0, pi]: Taylor polynomials of sin and cos of
//! x = phi - pi/2 in [-pi/2, pi/2] to degrees 11 and 12 (|error| <= 6e-8 + float rounding).
inline glm::vec2 computeCosSin(float phi)
{
    const float x = phi - 1.57079637f;
    const float x2 = x * x;
    float sinPoly = -2.50521079e-08f;
    sinPoly = sinPoly * x2 + 2.75573188e-06f;
    sinPoly = sinPoly * x2 - 0.000198412701f;
    sinPoly = sinPoly * x2 + 0.00833333377f;
    sinPoly = sinPoly * x2 - 0.166666672f;
    sinPoly = sinPoly * x2 + 1.0f;
    float cosPoly = 2.08767559e-09f;
    cosPoly = cosPoly * x2 - 2.755732e-07f;
    cosPoly = cosPoly * x2 + 2.48015876e-05f;
    cosPoly = cosPoly * x2 - 0.00138888892f;
    cosPoly = cosPoly * x2 + 0.0416666679f;
    cosPoly = cosPoly * x2 - 0.5f;
    cosPoly = cosPoly * x2 + 1.0f;
    return {-(x * sinPoly), cosPoly}; // cos(phi) = -sin(x), sin(phi) = cos(x)
}

//! acos(x) for x in [-1, 1] to about 1e-7 rad: the polynomial of Abramowitz & Stegun 4.4.46
//! (|error| <= 2e-8 in exact arithmetic), acos(x) = sqrt(1 - x) P(x) on [0, 1] and
//! pi - acos(-x) below. GPU drivers' own acos can be far less exact (llvmpipe: ~5e-5 rad).
inline float computeAcos(float x)
{
    const float a = std::fabs(x);
    float poly = -0.0012624911f;
    poly = poly * a + 0.0066700899f;
    poly = poly * a - 0.0170881264f;
    poly = poly * a + 0.0308918804f;
    poly = poly * a - 0.0501743034f;
    poly = poly * a + 0.0889789909f;
    poly = poly * a - 0.214598805f;
    poly = poly * a + 1.57079625f;
    const float r = std::sqrt(1.0f - a) * poly;
    return x >= 0.0f ? r : 3.14159274f - r;
}

//! Int_0^h sin(t) cos(t - gamma) dt for signed h (the |sin| of the measure is folded in: for
//! h < 0 it equals Int_h^0 |sin(t)| cos(t - gamma) dt). [Jimenez et al. 2016, inner integral]
//!   a(h) = (-cos(2h - gamma) + cos(gamma) + 2 h sin(gamma)) / 4
inline float integrateArc(float h, float gamma)
{
    return 0.25f * (-std::cos(2.0f * h - gamma) + std::cos(gamma) + 2.0f * h * std::sin(gamma));
}

//! The s component of the cosine-weighted direction integral over one side,
//! Int_0^h |sin t| sin(t) cos(t - gamma) dt with the sign of h folded in like integrateArc:
//!   (8 sin(gamma) - sin(3h - gamma) + 6 sin(h - gamma) - 3 sin(h + gamma)) / 12
inline float integrateBentS(float h, float gamma)
{
    return (8.0f * std::sin(gamma) - std::sin(3.0f * h - gamma) + 6.0f * std::sin(h - gamma) -
            3.0f * std::sin(h + gamma)) /
           12.0f;
}

//! The v component, Int_0^h |sin t| cos(t) cos(t - gamma) dt (sign of h folded in):
//!   (4 cos(gamma) - cos(3h - gamma) - 3 cos(h + gamma)) / 12
inline float integrateBentV(float h, float gamma)
{
    return (4.0f * std::cos(gamma) - std::cos(3.0f * h - gamma) - 3.0f * std::cos(h + gamma)) /
           12.0f;
}

//! a(gamma - pi/2) + a(gamma + pi/2): the whole hemisphere of one slice.
inline float integrateFullSlice(float gamma)
{
    return std::cos(gamma) + gamma * std::sin(gamma);
}

//! 4x4 ordered-dither (Bayer) matrix: the per-pixel slice rotation in 16ths of a slice step.
inline constexpr std::array<std::uint32_t, 16> kBayer4x4 = {0, 8,  2, 10, 12, 4, 14, 6,
                                                            3, 11, 1, 9,  15, 7, 13, 5};

//! Temporal slice rotations of [Jimenez et al. 2016] (60, 300, 180, 240, 120, 0 degrees of a
//! full turn), as fractions of one rotation period; frame f uses entry f mod 6.
inline constexpr std::array<float, 6> kTemporalRotations = {1.0f / 6.0f, 5.0f / 6.0f, 3.0f / 6.0f,
                                                            4.0f / 6.0f, 2.0f / 6.0f, 0.0f};

//! Temporal step offsets of [Jimenez et al. 2016] (0, 1/2, 1/4, 3/4); frame f uses f mod 4.
inline constexpr std::array<float, 4> kTemporalStepOffsets = {0.0f, 0.5f, 0.25f, 0.75f};

//! Rotation of pixel (x, y) in [0, 1), in units of one slice step (pi / slices): the 4x4
//! pattern spreads 16 rotations over a tile, the temporal entry interleaves 6 frames, so a tile
//! over 6 frames sees 96 distinct slice directions per slice.
inline float computeSliceRotation(int x, int y, float temporalRotation)
{
    const std::uint32_t index = (std::uint32_t(y) & 3u) * 4u + (std::uint32_t(x) & 3u);
    return (float(kBayer4x4[index]) + temporalRotation) * 0.0625f;
}

//! Offset of the first step of pixel (x, y) in [0, 1), in units of one step: 4 spatial values
//! along diagonals times 4 temporal ones.
inline float computeStepJitter(int x, int y, float temporalStepOffset)
{
    return (float(std::uint32_t(y - x) & 3u) + temporalStepOffset) * 0.25f;
}

} // namespace rtlab::occlusion::gtao
