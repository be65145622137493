#pragma once
// The math of bentcone_ssdo that the C++ path, the GPU set-up and the tests share: the sample
// pattern and its interleaved rotations, 2-band spherical harmonics of the cosine-weighted
// visibility, the bent-cone conversion, and the solid angle of two intersecting cones.
//
// Everything here is in float where the per-pixel code uses it, with the same order of
// operations as shaders/bentcone_ssdo.comp, so that both paths round alike.

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <vector>

namespace rtlab::bentcone_ssdo {

constexpr int kMinSamples = 1;
constexpr int kMaxSamples = 256;
//! Side of the interleaved rotation pattern: 4x4 pixels, 16 rotations.
constexpr int kCellSide = 4;
constexpr int kCellCount = kCellSide * kCellSide;
//! The cone tracer's fixed directions (scene/sky.h).
constexpr int kConeCount = 16;

constexpr float kPi = 3.14159265358979323846f;
//! Real SH basis constants: Y00 = 1 / (2 sqrt(pi)), Y1m = sqrt(3 / (4 pi)) * (y, z, x).
constexpr float kShY00 = 0.282095f;
constexpr float kShY1 = 0.488603f;
//! Each of the 16 cone directions stands for 4 pi / 16 sr; its cone covers that solid angle:
//! 2 pi (1 - cos a) = 4 pi / 16, so cos a = 1 - 2/16 = 7/8.
constexpr float kConeCosHalfAngle = 0.875f;

//! How the solid angle of two intersecting cones (spherical caps) is computed.
enum class ConeIntersection {
    Exact,      //!< closed form (spherical triangle of the two axes and a boundary crossing)
    Smoothstep, //!< Oat & Sander 2007 smoothstep blend between containment and separation
};

//! The fixed sample pattern in the tangent frame (z along the normal): xyz is a unit direction,
//! w in (0, 1] its distance as a fraction of the radius. Directions are cosine-distributed in
//! antipodal pairs: pair j of P = N/2 has disk radius^2 (j + 1/2) / P and azimuths
//! pi * radical-inverse-2(j) and that + pi; an odd N adds one sample along the normal. Sample k
//! has w = cbrt((rank(k) + 1/2) / N), the radius law of a uniform point in the ball stratified
//! in N strata, rank(k) the rank of k's base-3 radical inverse among those of 0..N-1.
std::vector<glm::vec4> makeSamplePattern(int count);

//! Base-b radical inverse of `index` (digits mirrored about the point).
double computeRadicalInverse(unsigned index, unsigned base);

//! Rank 0..15 of pixel (x, y) in the 4x4 Bayer (ordered dither) matrix: neighbouring pixels get
//! rotations half a turn, then a quarter turn, ... apart.
int getCellRank(int x, int y);

//! Index 0..15 of the cell of pixel (x, y) in the rotation table: (y mod 4) * 4 + (x mod 4).
int getCellIndex(int x, int y);

//! The per-frame rotation in turns, [0, 1): frameIndex times the golden ratio's fraction,
//! computed in 16-bit fixed point (40503 / 65536) so that it is exact for every frame index.
double getFrameTurn(int frameIndex);

//! (cos, sin) of the rotation about the normal of every cell for a frame: cell c turns by
//! (rank(c) + 1/2) / 16 + getFrameTurn(frameIndex) turns.
std::array<glm::vec2, kCellCount> makeCellRotations(int frameIndex);

//! The SH basis (Y00, Y1-1, Y10, Y11) at unit direction w.
glm::vec4 evaluateShBasis(const glm::vec3& w);
//! The 2-band reconstruction sum_lm c_lm Y_lm(w) of coefficients `sh` = (L00, L1-1, L10, L11).
float reconstructSh(const glm::vec4& sh, const glm::vec3& w);

//! A bent cone: unit axis, cosine-weighted visible fraction A in [0, 1] and half-angle in the
//! cosine convention sin^2(aperture) = A (reference.h).
struct BentCone {
    glm::vec3 axis{0.0f, 0.0f, 1.0f};
    float visibleFraction = 1.0f;
    float aperture = 1.57079632679f;
};

//! The cone from the coefficients of the cosine-weighted visibility V(w) max(cos theta, 0):
//! A = L00 / (pi Y00) (the integral of V cos over pi), axis = (L11, L1-1, L10) normalised (the
//! cosine-weighted mean unoccluded direction), `normal` where L1 vanishes (nothing visible).
BentCone convertShToBentCone(const glm::vec4& sh, const glm::vec3& normal);

//! Half-angle with sin^2(alpha) = visibleFraction (clamped to [0, 1]).
float computeAperture(float visibleFraction);

//! A cone about some axis (a spherical cap) by its half-angle's trigonometric values; the
//! versine 1 - cos is kept separately so that small caps keep their relative precision.
struct Cap {
    float angle = 0.0f;   //!< half-angle, radians, [0, pi/2]
    float cosine = 1.0f;  //!< cos(angle)
    float sine = 0.0f;    //!< sin(angle)
    float versine = 0.0f; //!< 1 - cos(angle); the cap's solid angle is 2 pi versine
};

//! The cap of half-angle `angle` in [0, pi/2].
Cap makeCap(double angle);
//! The bent cone's cap for visible fraction A (cosine convention: sin^2 = A), from A alone:
//! sin = sqrt(A), cos = sqrt(1 - A), versine = A / (1 + cos).
Cap makeApertureCap(double visibleFraction);
//! The cap of each of the 16 direction cones: cos = 7/8 (4 pi / 16 sr).
Cap getDirectionCap();
//! The hemisphere above a surface: half-angle pi/2.
Cap getHemisphereCap();

//! The bent cone of every visible count 0..N of an N-sample estimate: entry c is
//! (aperture, cos, sin, versine) of makeApertureCap(c / N). Computed once in double and shared
//! by both paths, so that the GPU's asin never enters the result.
std::vector<glm::vec4> makeApertureTable(int sampleCount);

//! Solid angle (sr) of the intersection of caps `a` and `b` whose axes are the angle with cosine
//! `cosD` and sine `sinD` >= 0 apart (from the dot and cross products of the axes).
//! Exact: Omega = 2 (va beta_A + vb beta_B - E) over the spherical triangle of the two axes and
//! a point where the cap boundaries cross (Gauss-Bonnet [Mazonka 2012, Sec. 4]); beta_A, beta_B
//! its angles at the axes, E its spherical excess, va, vb the versines. Written in the cosines
//! and versines only (three atan2, one sqrt, no trigonometric function), with 1 - cos and
//! 1 + cos of nearly equal or opposite angles formed from sines, so it keeps ~1e-6 sr absolute
//! and ~3e-5 relative precision in float for every pair of caps up to hemispheres.
//! Smoothstep: [Oat & Sander 2007], from the angles.
float intersectCaps(float cosD, float sinD, const Cap& a, const Cap& b, ConeIntersection mode);

//! The same with the axis angle `d` in [0, pi] and half-angles `a`, `b` in [0, pi/2].
float intersectCaps(float d, float a, float b, ConeIntersection mode);

//! Visibility in [0, 1] of the direction cone (getDirectionCap()) around unit `direction`:
//! the fraction of it inside the bent cone `bent` about unit `axis`, limited by the fraction of
//! it above the surface, min(|C n B|, |C n H|) / |C|, H the hemisphere around unit `normal`.
//! This bounds the triple intersection |C n B n H| from above and equals it when B lies in H,
//! or when C n H lies in B; directions whose cone lies wholly below the surface get 0.
float computeConeVisibility(const glm::vec3& direction, const glm::vec3& axis, const Cap& bent,
                            const glm::vec3& normal, ConeIntersection mode);

} // namespace rtlab::bentcone_ssdo
