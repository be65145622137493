#pragma once
// The sky as the lighting pass uses it: 16 spherical-Gaussian lobes on the Tomorrow Children's
// 16 cone directions, and per lobe its irradiance as a function of the angle between the normal
// and the lobe's axis, precomputed on the CPU.
// Seed: shared/seeds/000_3da000e866ebc485.txt, "Sky lighting: represent as 16 SRBFs ... aligned
// to the 16 directions that we will cone trace in".
//
// Lobe k: G_k(w) = exp(s (w . a_k - 1)), a_k = scene::getConeDirections()[k], s the sky's
// sharpness (shared by all lobes). Its irradiance on a surface with unit normal n,
//   I_k(n) = Int_S2 G_k(w) max(0, n . w) dw,
// depends only on c = n . a_k, so one table I(c) serves all 16 lobes. It is computed by
// numerical integration: with w = (sqrt(1 - mu^2) cos phi, sqrt(1 - mu^2) sin phi, mu) about
// a_k, the phi integral of max(0, A cos phi + B) (A = sqrt(1 - c^2) sqrt(1 - mu^2), B = c mu)
// is closed-form (2 pi B if B >= A, 0 if B <= -A, else 2 (B phi0 + A sin phi0) with
// phi0 = acos(-B / A)), and the remaining integral over mu is composite Simpson on the pieces
// between the kinks mu = +-sqrt(1 - c^2) (relative error below 1e-6; sky_irradiance tests
// compare with a 2D brute-force quadrature).
//
// The sky irradiance with per-lobe visibility V_k is then E = Sum_k V_k L_k I(n . a_k).
// Kind::Srbf skies use their own lobes L_k. Constant and gradient skies are projected onto 16
// lobe radiances (sharpness 4) by a least-squares fit of their irradiance over 256 normals,
// regularised toward L_k0 = L(a_k) (4 pi / 16) / Int G (the lobe that carries its cone's share
// of the sky) because the lobes' irradiances are nearly linearly dependent (irradiance is
// almost band-limited to spherical-harmonic degree 2: 9 dimensions for 16 lobes). The fit's
// largest irradiance error over 1024 other normals and the poles is reported in SkyLobes (about
// 3e-4 of the largest irradiance for a constant sky, 1.5e-3 for a gradient sky). The fitted L_k
// may be negative.

#include "scene/sky.h"

#include <glm/vec3.hpp>

#include <array>
#include <vector>

namespace rtlab::render {

//! I(c) = Int G(w) max(0, n . w) dw for a lobe of sharpness `sharpness` (> 0) whose axis makes
//! cosine `cosAngle` (clamped to [-1, 1]) with the normal n.
double computeLobeIrradiance(double sharpness, double cosAngle);

//! I(c_i) at c_i = -1 + 2 i / (size - 1), i = 0..size-1 (size >= 2).
std::vector<float> computeLobeIrradianceTable(double sharpness, int size);

//! The sky's irradiance on a surface with unit normal `n`, without occlusion: Sum_k L_k I(n.a_k)
//! for Kind::Srbf, pi * constant for Kind::Constant, the integral of the gradient (numerical)
//! for Kind::Gradient, 0 for Kind::None.
glm::dvec3 computeSkyIrradiance(const scene::Sky& sky, const glm::dvec3& n);

//! The 16 lobes that stand for a sky.
struct SkyLobes {
    std::array<glm::vec3, scene::kConeDirectionCount> radiance{}; //!< L_k, peak radiance
    float sharpness = 4.0f;                                       //!< s of every lobe
    double maxError = 0.0;         //!< of the fitted irradiance, any channel (0 for Srbf, None)
    double maxRelativeError = 0.0; //!< maxError / the largest irradiance of any normal, channel
};

//! The lobes of a sky: its own for Kind::Srbf, a fit for Constant and Gradient (see above),
//! zero for None.
SkyLobes projectSkyOntoLobes(const scene::Sky& sky);

//! Whether two skies are the same (every field that changes the radiance).
bool isSameSky(const scene::Sky& a, const scene::Sky& b);

} // namespace rtlab::render
