// Direct lighting against closed forms, and the bookkeeping full = emission + direct + indirect.
#include "reference/reference.h"
#include "reference/samplers.h"

#include "test_scenes.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace rtlab::reference {
namespace {

constexpr double kPiD = 3.14159265358979323846;
const glm::vec3 kAlbedo(0.8f, 0.6f, 0.4f);

//! Points on the floor y = 0 over [-1, 1]^2 facing up.
scene::GBuffer makeFloorPoints(int size)
{
    return test::makePointGBuffer(
        size, size,
        [size](int x, int y, glm::vec3& p, glm::vec3& n) {
            p = glm::vec3(-1.0f + 2.0f * (float(x) + 0.5f) / float(size), 0.0f,
                          -1.0f + 2.0f * (float(y) + 0.5f) / float(size));
            n = glm::vec3(0, 1, 0);
            return true;
        },
        kAlbedo);
}

ReferenceSettings makeLightSettings(Quantity q)
{
    ReferenceSettings s = test::makeSettings(q);
    s.targetStdErr = 0.0;
    s.targetRelStdErr = 0.003;
    s.batchSize = 64;
    s.maxSamples = 8192;
    s.seed = 3;
    return s;
}

TEST(ReferenceDirect, PointLightsWithShadowsAreExact)
{
    // L = albedo / pi * I cos(theta) / d^2 from the ray origin (eps above the floor); a small
    // occluder at y = 0.5 shadows the points whose segment to the light crosses it. Two lights
    // are evaluated every sample, so there is no noise at all.
    scene::RenderScene s;
    const auto m = test::addMaterial(s, glm::vec3(0.5f));
    test::addQuad(s, {-5, 0, -5}, {0, 0, 10}, {10, 0, 0}, m);
    test::addQuad(s, {-0.3f, 0.5f, -0.2f}, {0.4f, 0, 0}, {0, 0, 0.3f}, m);
    s.pointLights.push_back({glm::vec3(0.3f, 1.0f, -0.2f), glm::vec3(2.0f, 1.0f, 0.5f)});
    s.pointLights.push_back({glm::vec3(-0.6f, 1.5f, 0.8f), glm::vec3(1.0f, 1.0f, 3.0f)});
    const auto g = makeFloorPoints(16);
    const ReferenceResult r = computeReference(s, g, makeLightSettings(Quantity::Direct));
    const double eps = r.stats.rayEpsilon;
    int shadowed = 0, lit = 0;
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 16; ++x) {
            const glm::dvec3 o = glm::dvec3(g.position.at(x, y)) + glm::dvec3(0, eps, 0);
            glm::dvec3 expected(0.0);
            bool nearEdge = false;
            for (const auto& light : s.pointLights) {
                const glm::dvec3 toLight = glm::dvec3(light.position) - o;
                // Where the segment crosses y = 0.5, and whether that is inside the occluder.
                const glm::dvec3 cross = o + toLight * ((0.5 - o.y) / toLight.y);
                const double dx = std::min(cross.x + 0.3, 0.1 - cross.x);
                const double dz = std::min(cross.z + 0.2, 0.1 - cross.z);
                const bool inside = dx > 0.0 && dz > 0.0;
                nearEdge |= std::abs(std::min(dx, dz)) < 1e-3 && (dx > -1e-3 && dz > -1e-3);
                if (inside) {
                    ++shadowed;
                    continue;
                }
                ++lit;
                const double d2 = glm::dot(toLight, toLight);
                expected += glm::dvec3(light.intensity) * (toLight.y / std::sqrt(d2) / d2);
            }
            if (nearEdge)
                continue;
            expected *= glm::dvec3(kAlbedo) / kPiD;
            for (int c = 0; c < 3; ++c) {
                EXPECT_EQ(r.radianceStdErr.at(x, y)[c], 0.0f);
                EXPECT_NEAR(r.radiance.at(x, y)[c], expected[c], 1e-6 * std::max(1.0, expected[c]))
                    << "(" << x << ", " << y << ")";
            }
        }
    }
    EXPECT_GT(shadowed, 10); // the occluder does cast a shadow on the grid
    EXPECT_GT(lit, 300);
}

TEST(ReferenceDirect, ManyPointLightsPickedByPower)
{
    // 12 lights (more than are evaluated every sample): one picked by power per sample.
    scene::RenderScene s;
    const auto m = test::addMaterial(s, glm::vec3(0.5f));
    test::addQuad(s, {-5, 0, -5}, {0, 0, 10}, {10, 0, 0}, m);
    for (int i = 0; i < 12; ++i)
        s.pointLights.push_back({glm::vec3(std::cos(i * 0.5), 0.5f + 0.1f * i, std::sin(i * 0.7)),
                                 glm::vec3(0.2f + 0.1f * (i % 4), 0.5f, 0.1f * (i % 3))});
    const auto g = makeFloorPoints(8);
    const ReferenceResult r = computeReference(s, g, makeLightSettings(Quantity::Direct));
    const double eps = r.stats.rayEpsilon;
    for (int y = 0; y < 8; ++y) {
        for (int x = 0; x < 8; ++x) {
            const glm::dvec3 o = glm::dvec3(g.position.at(x, y)) + glm::dvec3(0, eps, 0);
            glm::dvec3 expected(0.0);
            for (const auto& light : s.pointLights) {
                const glm::dvec3 toLight = glm::dvec3(light.position) - o;
                const double d2 = glm::dot(toLight, toLight);
                expected += glm::dvec3(light.intensity) * (toLight.y / std::sqrt(d2) / d2);
            }
            expected *= glm::dvec3(kAlbedo) / kPiD;
            for (int c = 0; c < 3; ++c)
                EXPECT_LE(std::abs(r.radiance.at(x, y)[c] - expected[c]),
                          4.0 * r.radianceStdErr.at(x, y)[c] + 1e-6 * expected[c])
                    << "(" << x << ", " << y << ")";
        }
    }
}

TEST(ReferenceDirect, ConstantSkyOverAnOpenFloor)
{
    // Every cosine ray escapes: E = pi L_sky exactly, with no variance; nothing to bounce off,
    // so full = Le + direct.
    scene::RenderScene s;
    const auto m = test::addMaterial(s, glm::vec3(0.5f));
    test::addQuad(s, {-5, 0, -5}, {0, 0, 10}, {10, 0, 0}, m);
    s.sky.kind = scene::Sky::Kind::Constant;
    s.sky.constant = glm::vec3(0.7f, 0.8f, 1.2f);
    const auto g = makeFloorPoints(8);
    const ReferenceResult direct = computeReference(s, g, makeLightSettings(Quantity::Direct));
    const ReferenceResult full = computeReference(s, g, makeLightSettings(Quantity::Full));
    for (std::size_t i = 0; i < direct.radiance.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(direct.radiance.pixels[i][c], kAlbedo[c] * s.sky.constant[c], 1e-6);
            EXPECT_NEAR(direct.irradiance.pixels[i][c], kPiD * s.sky.constant[c], 1e-5);
            EXPECT_EQ(direct.radianceStdErr.pixels[i][c], 0.0f);
            EXPECT_EQ(full.radiance.pixels[i][c], direct.radiance.pixels[i][c]);
        }
    }
}

TEST(ReferenceDirect, SrbfSkyMatchesQuadrature)
{
    // Points with assorted normals in open space (the only triangle, 1 x 1 at 1000 units,
    // subtends < 1e-6 sr): E = Int_H L_sky(w) cos dw by 64 x 128 Gauss-Legendre points.
    scene::RenderScene s;
    const auto m = test::addMaterial(s, glm::vec3(0.5f));
    test::addQuad(s, {1000, -1000, 1000}, {1, 0, 0}, {0, 0, 1}, m);
    s.sky.kind = scene::Sky::Kind::Srbf;
    s.sky.sharpness = 8.0f;
    for (int i = 0; i < scene::kConeDirectionCount; ++i)
        s.sky.lobes[i] = glm::vec3(0.2f + float(i % 4), 0.5f * float(i % 3), i == 3 ? 6.0f : 0.3f);
    std::vector<glm::vec3> normals;
    const auto g = test::makePointGBuffer(
        6, 6,
        [&](int x, int y, glm::vec3& p, glm::vec3& n) {
            const double z = -1.0 + (y + 0.5) / 3.0, phi = 2.0 * kPiD * (x + 0.3) / 6.0;
            const double r = std::sqrt(1.0 - z * z);
            p = glm::vec3(float(x), float(y), 0.0f);
            n = glm::vec3(float(r * std::cos(phi)), float(z), float(r * std::sin(phi)));
            return true;
        },
        kAlbedo);
    ReferenceSettings settings = makeLightSettings(Quantity::Direct);
    const ReferenceResult res = computeReference(s, g, settings);

    std::vector<double> zn, zw, pn, pw;
    test::getGaussLegendre(64, zn, zw);
    test::getGaussLegendre(128, pn, pw);
    for (int y = 0; y < 6; ++y) {
        for (int x = 0; x < 6; ++x) {
            const glm::dvec3 n = glm::normalize(glm::dvec3(g.normal.at(x, y)));
            const Frame f = Frame::fromNormal(n);
            glm::dvec3 e(0.0);
            for (std::size_t a = 0; a < zn.size(); ++a) {
                const double z = 0.5 * (zn[a] + 1.0), r = std::sqrt(1.0 - z * z);
                for (std::size_t b = 0; b < pn.size(); ++b) {
                    const double phi = kPiD * (pn[b] + 1.0);
                    const glm::dvec3 w = f.toWorld({r * std::cos(phi), r * std::sin(phi), z});
                    e += glm::dvec3(s.sky.radiance(w)) * (z * 0.5 * zw[a] * kPiD * pw[b]);
                }
            }
            for (int c = 0; c < 3; ++c) {
                const double expected = kAlbedo[c] / kPiD * e[c];
                EXPECT_LE(std::abs(res.radiance.at(x, y)[c] - expected),
                          4.0 * res.radianceStdErr.at(x, y)[c] + 1e-5 * expected)
                    << "(" << x << ", " << y << ") channel " << c;
            }
        }
    }
}

//! Form factor from a point to a parallel rectangle a x b with one corner straight above it at
//! height h [Howell, catalogue of configuration factors, B-3]; E = pi Le F for a Lambertian
//! emitter of radiance Le.
double getCornerFormFactor(double a, double b, double h)
{
    const double x = a / h, y = b / h;
    const double sx = std::sqrt(1.0 + x * x), sy = std::sqrt(1.0 + y * y);
    return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) / (2.0 * kPiD);
}

TEST(ReferenceDirect, EmissiveSquareMatchesTheFormFactor)
{
    // A 1 x 1 emitter at height 1 over [-0.5, 0.5]^2; points beneath it at (px, 0, pz): four
    // corner rectangles. The ray offset lowers h by eps: allowed as 3 eps / h relative.
    scene::RenderScene s;
    const glm::vec3 le(3.0f, 2.0f, 1.0f);
    const auto lamp = test::addMaterial(s, glm::vec3(0.0f), le);
    test::addQuad(s, {-0.5f, 1.0f, -0.5f}, {1, 0, 0}, {0, 0, 1}, lamp);
    const auto g = test::makePointGBuffer(
        6, 6,
        [](int x, int y, glm::vec3& p, glm::vec3& n) {
            p = glm::vec3(-0.4f + 0.16f * float(x), 0.0f, -0.4f + 0.16f * float(y));
            n = glm::vec3(0, 1, 0);
            return true;
        },
        kAlbedo);
    const ReferenceResult r = computeReference(s, g, makeLightSettings(Quantity::Direct));
    const double h = 1.0;
    for (int y = 0; y < 6; ++y) {
        for (int x = 0; x < 6; ++x) {
            const double px = g.position.at(x, y).x, pz = g.position.at(x, y).z;
            const double f = getCornerFormFactor(0.5 - px, 0.5 - pz, h) +
                             getCornerFormFactor(px + 0.5, 0.5 - pz, h) +
                             getCornerFormFactor(0.5 - px, pz + 0.5, h) +
                             getCornerFormFactor(px + 0.5, pz + 0.5, h);
            for (int c = 0; c < 3; ++c) {
                const double expected = kAlbedo[c] * le[c] * f; // albedo / pi * pi Le F
                EXPECT_LE(std::abs(r.radiance.at(x, y)[c] - expected),
                          4.0 * r.radianceStdErr.at(x, y)[c] + 3.0 * r.stats.rayEpsilon * expected)
                    << "(" << x << ", " << y << ") channel " << c;
            }
        }
    }
}

TEST(ReferenceLight, FullIsEmissionPlusDirectPlusIndirect)
{
    // In the room (point light, emissive patch, SRBF sky through an opening), the three
    // estimates are independent: |full - Le - direct - indirect| <= 4 sqrt(se_f^2 + se_d^2 +
    // se_i^2).
    const auto room = test::makeRoomScene();
    const auto g = test::makeRoomGBuffer(room, 12, 12);
    ReferenceSettings s = makeLightSettings(Quantity::Full);
    s.targetRelStdErr = 0.02;
    s.targetStdErr = 0.002;
    s.maxSamples = 2048;
    const ReferenceResult full = computeReference(room, g, s);
    s.quantity = Quantity::Direct;
    const ReferenceResult direct = computeReference(room, g, s);
    s.quantity = Quantity::Indirect;
    const ReferenceResult indirect = computeReference(room, g, s);
    double indirectShare = 0.0;
    int surface = 0;
    for (std::size_t i = 0; i < full.radiance.size(); ++i) {
        if (g.materialId.pixels[i] == scene::kNoMaterial)
            continue;
        ++surface;
        for (int c = 0; c < 3; ++c) {
            const double sum = g.emission.pixels[i][c] + direct.radiance.pixels[i][c] +
                               indirect.radiance.pixels[i][c];
            const double se = std::sqrt(std::pow(full.radianceStdErr.pixels[i][c], 2.0) +
                                        std::pow(direct.radianceStdErr.pixels[i][c], 2.0) +
                                        std::pow(indirect.radianceStdErr.pixels[i][c], 2.0));
            EXPECT_LE(std::abs(full.radiance.pixels[i][c] - sum), 4.0 * se + 1e-6) << i << " " << c;
            indirectShare += indirect.radiance.pixels[i][c] / std::max(1e-6, sum);
        }
    }
    EXPECT_GT(surface, 100);
    indirectShare /= 3.0 * surface;
    EXPECT_GT(indirectShare, 0.05); // the room does bounce light around
    std::printf("    room: %d surface pixels, indirect share %.3f, %.0f / %.0f / %.0f samples per "
                "pixel (full / direct / indirect), %llu rays in %.2f s for full\n",
                surface, indirectShare, full.stats.meanSamples, direct.stats.meanSamples,
                indirect.stats.meanSamples, (unsigned long long)full.stats.rayCount,
                full.stats.seconds);
}

} // namespace
} // namespace rtlab::reference
