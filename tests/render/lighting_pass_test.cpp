// The lighting pass (with the shadow maps it reads) against closed forms, brute-force quadrature
// and the Embree ground truth: an unshadowed floor, the umbra of a box, the sky through its 16
// lobes with and without visibility, tonemapping, a Cornell box with a point light and
// degenerate lights. The shadow pass's own tests are in shadow_pass_test.cpp.
//
// Tolerances (each is stated again at its check):
//  * Point light, unshadowed: 1e-5 relative. The GPU and the CPU formula evaluate the same
//    float32 inputs (the G-buffer's position and normal); the GPU's length, division and dot
//    products add a few float32 roundings (~1e-7 each) and cos(theta) >= 0.3 on these floors, so
//    1e-5 (~80 ulp) bounds it with room for the driver's reciprocal and square-root precision.
//  * Sky: 1e-3 relative against a 512 x 1024 midpoint quadrature of Sum_k L_k G_k(w) cos(theta):
//    quadrature error < 1e-5, table interpolation (256 entries) ~1e-5, float32 sums ~1e-6.
//  * Tonemap: 1/255 (8-bit output: 0.5/255 quantisation plus float32 differences of pow).
//  * Cornell box: see the test.

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "reference/reference.h"
#include "render/image_transfer.h"
#include "lighting_test_support.h"
#include "render/sky_irradiance.h"
#include "scene/procedural.h"

namespace rtlab::render::test {
namespace {

constexpr double kPi = glm::pi<double>();

// albedo / pi * I * max(0, n.l) / d^2 in double from the G-buffer's float position and normal.
glm::dvec3 computePointLightRadiance(const scene::GBuffer& g, int x, int y,
                                     const scene::PointLight& light)
{
    const glm::dvec3 p(g.position.at(x, y));
    const glm::dvec3 n(g.normal.at(x, y));
    const glm::dvec3 toLight = glm::dvec3(light.position) - p;
    const double d2 = glm::dot(toLight, toLight);
    const double cosTheta = std::max(0.0, glm::dot(n, toLight) / std::sqrt(d2));
    return glm::dvec3(g.albedo.at(x, y)) / kPi * glm::dvec3(light.intensity) * cosTheta / d2;
}

double getMaxComponent(glm::dvec3 v)
{
    return std::max({v.x, v.y, v.z});
}

bool isFinite(glm::vec3 v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Int_{hemisphere about +y} G_k(w) cos(theta) dw by a midpoint rule in (theta, phi).
std::array<double, scene::kConeDirectionCount> integrateLobesOverUpperHemisphere(double sharpness)
{
    std::array<double, scene::kConeDirectionCount> sums{};
    constexpr int kTheta = 512, kPhi = 1024;
    const double dTheta = 0.5 * kPi / kTheta, dPhi = 2.0 * kPi / kPhi;
    for (int i = 0; i < kTheta; ++i) {
        const double theta = (i + 0.5) * dTheta;
        const double weight = std::cos(theta) * std::sin(theta) * dTheta * dPhi;
        for (int j = 0; j < kPhi; ++j) {
            const double phi = (j + 0.5) * dPhi;
            const glm::dvec3 w(std::sin(theta) * std::cos(phi), std::cos(theta),
                               std::sin(theta) * std::sin(phi));
            for (int k = 0; k < scene::kConeDirectionCount; ++k)
                sums[k] += weight *
                           std::exp(sharpness * (glm::dot(w, scene::getConeDirections()[k]) - 1.0));
        }
    }
    return sums;
}

TEST_F(LightingPassTest, UnshadowedFloorMatchesClosedFormAtEveryPixel)
{
    constexpr int kSize = 64;
    SceneBuilder b;
    addFloor(b, 2.0f, b.addMaterial(kAlbedo));
    scene::RenderScene s = b.getScene();
    s.pointLights.push_back({{0.3f, 1.0f, -0.2f}, {2.0f, 1.0f, 0.5f}});
    const scene::GBuffer g = drawFrame(s, makeCamera({0, 3, 2.5f}, {0, 0, 0}), kSize, kSize);
    const Image<glm::vec3> direct = getLighting().readBackDirect();
    const Image<glm::vec3> hdr = getLighting().readBackHdr();
    int surfaces = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            if (!g.hasSurface(x, y)) {
                EXPECT_EQ(direct.at(x, y), glm::vec3(0.0f));
                continue;
            }
            ++surfaces;
            const glm::dvec3 expected = computePointLightRadiance(g, x, y, s.pointLights[0]);
            for (int c = 0; c < 3; ++c) {
                // 1e-5 relative: float32 evaluation of the same formula (file comment).
                EXPECT_NEAR(direct.at(x, y)[c], expected[c], 1e-5 * expected[c])
                    << "pixel " << x << "," << y << " channel " << c;
                EXPECT_EQ(hdr.at(x, y)[c], direct.at(x, y)[c]) << "no emission, sky, indirect";
            }
        }
    EXPECT_GT(surfaces, kSize * kSize / 2);
    const gpu::RunResult r = getLighting().tonemap(TonemapSettings{});
    EXPECT_EQ(r.commands.size(), 1u);
}

TEST_F(LightingPassTest, BoxCastsAnUmbraAndLeavesTheRestLit)
{
    constexpr int kSize = 96;
    SceneBuilder b;
    const std::uint32_t floor = b.addMaterial(kAlbedo);
    const std::uint32_t box = b.addMaterial(glm::vec3(0.5f));
    addFloor(b, 2.0f, floor);
    const glm::vec3 boxCenter(0.0f, 1.0f, 0.0f), boxHalf(0.25f, 0.05f, 0.25f);
    b.addBox(boxCenter, boxHalf, 0.0f, box);
    scene::RenderScene s = b.getScene();
    const scene::PointLight light{{0.0f, 2.0f, 0.0f}, {3.0f, 3.0f, 3.0f}};
    s.pointLights.push_back(light);
    const scene::GBuffer g = drawFrame(s, makeCamera({0, 4, 3}, {0, 0, 0}), kSize, kSize);
    const Image<glm::vec3> direct = getLighting().readBackDirect();

    // The light is straight above the box's centre, so the shadow on the floor is the square
    // that the box's corners project to from the light (the top corners reach farthest).
    double half = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
        const glm::vec3 c =
            boxCenter +
            boxHalf * glm::vec3(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
        half = std::max(half, double(std::abs(c.x)) * light.position.y / (light.position.y - c.y));
    }
    // Margin: PCF reaches ~2 texels of 2/256 rad at the box (distance ~1) and the normal offset
    // moves the receiver by < 0.02; projected to the floor (twice as far) that is < 0.05.
    const double margin = 0.08;
    int umbra = 0, lit = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            if (!g.hasSurface(x, y) || g.materialId.at(x, y) != floor)
                continue;
            const glm::vec3 p = g.position.at(x, y);
            const double r = std::max(std::abs(p.x), std::abs(p.z));
            if (r < half - margin) {
                ++umbra;
                EXPECT_EQ(direct.at(x, y), glm::vec3(0.0f)) << "umbra pixel " << x << "," << y;
            } else if (r > half + margin) {
                ++lit;
                const glm::dvec3 expected = computePointLightRadiance(g, x, y, light);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(direct.at(x, y)[c], expected[c], 1e-5 * expected[c])
                        << "lit pixel " << x << "," << y;
            }
        }
    EXPECT_GT(umbra, 50);
    EXPECT_GT(lit, 1000);
}

TEST_F(LightingPassTest, SkyLobesMatchQuadratureAndScaleWithVisibility)
{
    constexpr int kSize = 48;
    SceneBuilder b;
    addFloor(b, 3.0f, b.addMaterial(kAlbedo));
    scene::RenderScene s = b.getScene();
    s.sky.kind = scene::Sky::Kind::Srbf;
    s.sky.sharpness = 4.0f;
    for (int k = 0; k < scene::kConeDirectionCount; ++k)
        s.sky.lobes[k] = glm::vec3(0.2f + 0.05f * k, 0.3f, 0.1f + 0.03f * float(k % 5));
    // Looking down at the floor and out over its edge, so part of the image is sky.
    const scene::Camera camera = makeCamera({0, 1.5f, 3}, {0, 0.5f, -1});
    const scene::GBuffer g = drawFrame(s, camera, kSize, kSize);
    const std::array<double, scene::kConeDirectionCount> lobeIrradiance =
        integrateLobesOverUpperHemisphere(4.0);
    auto expectSky = [&](const Image<glm::vec3>& direct, const std::vector<float>& visibility,
                         const char* what) {
        glm::dvec3 e(0.0);
        for (int k = 0; k < scene::kConeDirectionCount; ++k)
            e += double(visibility[k]) * glm::dvec3(s.sky.lobes[k]) * lobeIrradiance[k];
        const glm::dvec3 expected = glm::dvec3(kAlbedo) / kPi * e;
        int surfaces = 0;
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                if (!g.hasSurface(x, y))
                    continue;
                ++surfaces;
                for (int c = 0; c < 3; ++c)
                    // 1e-3 relative: quadrature, table and float32 errors (file comment).
                    ASSERT_NEAR(direct.at(x, y)[c], expected[c], 1e-3 * expected[c] + 1e-7)
                        << what << ": pixel " << x << "," << y << " channel " << c;
            }
        EXPECT_GT(surfaces, kSize * kSize / 4) << what;
    };

    // (a) V = 1; pixels without surface show the sky along their ray.
    expectSky(getLighting().readBackDirect(), std::vector<float>(16, 1.0f), "V = 1");
    const Image<glm::vec3> hdr = getLighting().readBackHdr();
    int skyPixels = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            if (g.hasSurface(x, y))
                continue;
            ++skyPixels;
            const glm::dvec3 dir = glm::normalize(
                computeReferenceRayDirection(camera, kSize, kSize, glm::dvec2(x + 0.5, y + 0.5)));
            const glm::vec3 expected = s.sky.radiance(dir);
            for (int c = 0; c < 3; ++c)
                // 1e-4 relative: the ray comes from a float32 inverse matrix (~1e-6 rad), and
                // the lobes change by sharpness * angle relative to themselves.
                EXPECT_NEAR(hdr.at(x, y)[c], expected[c], 1e-4 * expected[c])
                    << "sky pixel " << x << "," << y;
        }
    EXPECT_GT(skyPixels, 100);

    // (b) An ambient-occlusion image of 0.5 halves the sky light.
    const gpu::Image ao = createImageFrom(getContext(), Image<float>(kSize, kSize, 0.5f), "ao");
    LightingInputs withAo;
    withAo.ambientOcclusion = &ao;
    drawFrame(s, camera, kSize, kSize, withAo);
    EXPECT_EQ(getLighting().getLastVisibility(), SkyVisibility::AmbientOcclusion);
    expectSky(getLighting().readBackDirect(), std::vector<float>(16, 0.5f), "ao = 0.5");

    // (c) Cone visibilities: only the lobes of a subset are seen.
    std::vector<float> v(16, 0.0f);
    for (const int k : {0, 3, 5, 7, 12})
        v[k] = 1.0f;
    std::vector<Image<float>> cones;
    for (const float vk : v)
        cones.emplace_back(kSize, kSize, vk);
    std::array<gpu::Image, 4> coneImages;
    std::array<gpu::Image*, 4> coneTargets{};
    LightingInputs withCones;
    for (std::size_t g = 0; g < 4; ++g) {
        coneImages[g] =
            createImageFrom(getContext(), Image<glm::vec3>(kSize, kSize, glm::vec3(0.0f)), "cones");
        coneTargets[g] = &coneImages[g];
        withCones.coneVisibility[g] = &coneImages[g];
    }
    uploadConeVisibility(coneTargets, cones);
    drawFrame(s, camera, kSize, kSize, withCones);
    EXPECT_EQ(getLighting().getLastVisibility(), SkyVisibility::Cones);
    expectSky(getLighting().readBackDirect(), v, "cone subset");

    // Both visibility inputs at once are refused.
    LightingInputs both;
    both.ambientOcclusion = &ao;
    both.coneVisibility = withCones.coneVisibility;
    EXPECT_THROW(drawFrame(s, camera, kSize, kSize, both), Error);
    // So are some of the four cone images without the others.
    LightingInputs partial;
    partial.coneVisibility[0] = &coneImages[0];
    EXPECT_THROW(drawFrame(s, camera, kSize, kSize, partial), Error);
}

TEST_F(LightingPassTest, ConeSkyReplacesTheLobesAndTheirVisibility)
{
    // With a cone sky image (a voxel GI technique's sky and emitters through its cones) the
    // sky term is that image, exactly: direct = albedo / pi * E_cone, whatever the lobes and
    // the visibility inputs say; hdr adds emission and the indirect slot as before.
    constexpr int kSize = 32;
    SceneBuilder b;
    addFloor(b, 3.0f, b.addMaterial(kAlbedo));
    scene::RenderScene s = b.getScene();
    s.sky.kind = scene::Sky::Kind::Constant;
    s.sky.constant = glm::vec3(5.0f); // would dominate if the lobes were still added
    const scene::Camera camera = makeCamera({0, 1.5f, 3}, {0, 0.5f, -1});
    Image<glm::vec3> coneSky(kSize, kSize, glm::vec3(0.0f));
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x)
            coneSky.at(x, y) = glm::vec3(0.1f + 0.01f * float(x), 0.2f, 0.05f * float(y % 7));
    const gpu::Image coneImage = createImageFrom(getContext(), coneSky, "cone sky");
    const gpu::Image ao = createImageFrom(getContext(), Image<float>(kSize, kSize, 0.5f), "ao");
    const gpu::Image indirect =
        createImageFrom(getContext(), Image<glm::vec3>(kSize, kSize, glm::vec3(0.25f)), "indirect");
    LightingInputs in;
    in.coneSkyIrradiance = &coneImage;
    in.ambientOcclusion = &ao;
    in.indirectIrradiance = &indirect;
    const scene::GBuffer g = drawFrame(s, camera, kSize, kSize, in);
    EXPECT_TRUE(getLighting().hadConeSky());
    const Image<glm::vec3> direct = getLighting().readBackDirect();
    const Image<glm::vec3> hdr = getLighting().readBackHdr();
    int surfaces = 0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            if (!g.hasSurface(x, y))
                continue;
            ++surfaces;
            const glm::vec3 expected = kAlbedo / float(kPi) * coneSky.at(x, y);
            for (int c = 0; c < 3; ++c) {
                // float32: one product and one division.
                ASSERT_NEAR(direct.at(x, y)[c], expected[c], 1e-6f) << x << "," << y;
                ASSERT_NEAR(hdr.at(x, y)[c], expected[c] + kAlbedo[c] / float(kPi) * 0.25f, 1e-6f)
                    << x << "," << y;
            }
        }
    EXPECT_GT(surfaces, kSize * kSize / 4);
    // A cone sky of the wrong size is refused.
    const gpu::Image small = createImageFrom(getContext(), Image<glm::vec3>(8, 8, glm::vec3(0.0f)), "small");
    LightingInputs wrong;
    wrong.coneSkyIrradiance = &small;
    EXPECT_THROW(drawFrame(s, camera, kSize, kSize, wrong), Error);
    // Without it the lobes come back.
    drawFrame(s, camera, kSize, kSize);
    EXPECT_FALSE(getLighting().hadConeSky());
}

TEST_F(LightingPassTest, ConstantAndGradientSkiesAreProjectedOntoTheLobes)
{
    // The fit's own error is reported; the lit floor must match the exact irradiance within it
    // (plus 1e-4 for the table and float32).
    constexpr int kSize = 16;
    SceneBuilder b;
    addFloor(b, 3.0f, b.addMaterial(kAlbedo));
    scene::RenderScene s = b.getScene();
    scene::Sky constant;
    constant.kind = scene::Sky::Kind::Constant;
    constant.constant = {0.5f, 1.0f, 2.0f};
    scene::Sky gradient;
    gradient.kind = scene::Sky::Kind::Gradient;
    gradient.zenith = {0.2f, 0.4f, 1.0f};
    gradient.horizon = {0.8f, 0.8f, 0.9f};
    gradient.ground = {0.1f, 0.08f, 0.05f};
    for (const scene::Sky& sky : {constant, gradient}) {
        s.sky = sky;
        const scene::GBuffer g = drawFrame(s, makeCamera({0, 2, 0.5f}, {0, 0, 0}), kSize, kSize);
        const SkyLobes& lobes = getLighting().getSkyLobes();
        EXPECT_LT(lobes.maxRelativeError, 0.01);
        const glm::dvec3 e = computeSkyIrradiance(sky, {0.0, 1.0, 0.0});
        const glm::dvec3 expected = glm::dvec3(kAlbedo) / kPi * e;
        // The fit's error bound (irradiance units) plus 1e-4 for the table and float32.
        const Image<glm::vec3> direct = getLighting().readBackDirect();
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                ASSERT_TRUE(g.hasSurface(x, y));
                for (int c = 0; c < 3; ++c)
                    ASSERT_NEAR(direct.at(x, y)[c], expected[c],
                                kAlbedo[c] / kPi * (lobes.maxError + 1e-4 * e[c]))
                        << "sky kind " << int(sky.kind) << " pixel " << x << "," << y;
            }
    }
    // A constant sky's irradiance is pi L for every normal.
    EXPECT_NEAR(computeSkyIrradiance(constant, {0.6, 0.0, 0.8}).y, kPi, 1e-12);
}

TEST(LightingSky, LobeIrradianceTableMatchesQuadratureAndLimits)
{
    const double s = 4.0;
    const std::array<double, scene::kConeDirectionCount> brute =
        integrateLobesOverUpperHemisphere(s);
    for (int k = 0; k < scene::kConeDirectionCount; ++k) {
        const double c = scene::getConeDirections()[k].y; // n = +y
        // The 512 x 1024 midpoint rule converges as h^2 toward the table's Simpson integral; at
        // this size it is within ~7e-6 relative for the lobes below the horizon (small values).
        EXPECT_NEAR(computeLobeIrradiance(s, c), brute[k], 2e-5 * brute[k] + 1e-9) << "lobe " << k;
    }
    // A nearly flat lobe lights like a uniform sky of radiance 1: pi for every normal.
    EXPECT_NEAR(computeLobeIrradiance(1e-6, 0.3), kPi, 1e-4);
    // A sharp lobe that stays above the horizon: its integral 2 pi / s (1 - e^-2s) times the
    // lobe's mean cosine to the normal, c (coth(s) - 1/s).
    const double sharp = 2000.0;
    const double sharpExpected = 2.0 * kPi / sharp * 0.5 * (1.0 - 1.0 / sharp);
    EXPECT_NEAR(computeLobeIrradiance(sharp, 0.5), sharpExpected, 1e-6 * sharpExpected);
    EXPECT_NEAR(computeLobeIrradiance(sharp, -0.5), 0.0, 1e-12);
}

TEST_F(LightingPassTest, TonemapEqualsTheCpuFormula)
{
    // Values around every regime of the curves, including negative and huge ones.
    const std::vector<float> values = {0.0f, 1e-4f, 0.002f, 0.01f, 0.05f, 0.18f, 0.3f, 0.5f,
                                       0.8f, 1.0f,  1.5f,   2.0f,  4.0f,  16.0f, 1e3f, -1.0f};
    Image<glm::vec3> hdr(int(values.size()), 3);
    for (int x = 0; x < hdr.width; ++x) {
        hdr.at(x, 0) = glm::vec3(values[x]);
        hdr.at(x, 1) = glm::vec3(values[x], 0.5f * values[x], 2.0f * values[x]);
        hdr.at(x, 2) = glm::vec3(values[hdr.width - 1 - x], values[x], 0.1f);
    }
    const gpu::Image image = createImageFrom(getContext(), hdr, "hdr values");
    for (const Tonemapper op : {Tonemapper::Aces, Tonemapper::Reinhard})
        for (const float ev : {-2.0f, 0.0f, 1.5f}) {
            const TonemapSettings settings{ev, op};
            getLighting().tonemap(image, settings);
            const Image<glm::vec3> ldr = getLighting().readBackLdr();
            for (int y = 0; y < hdr.height; ++y)
                for (int x = 0; x < hdr.width; ++x) {
                    const glm::vec3 expected = computeTonemappedColor(hdr.at(x, y), settings);
                    for (int c = 0; c < 3; ++c)
                        // 1/255: 8-bit quantisation (0.5/255) plus float32 pow differences.
                        EXPECT_NEAR(ldr.at(x, y)[c], expected[c], 1.0 / 255.0)
                            << getTonemapperName(op) << " ev " << ev << " value "
                            << hdr.at(x, y)[c];
                }
        }
    // The CPU formula itself against hand-evaluated values.
    auto srgb = [](double v) {
        return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
    };
    EXPECT_NEAR(computeTonemappedColor(glm::vec3(1.0f), {0.0f, Tonemapper::Reinhard}).x, srgb(0.5),
                1e-6);
    EXPECT_NEAR(computeTonemappedColor(glm::vec3(0.5f), {1.0f, Tonemapper::Aces}).x,
                srgb(2.54 / 3.16), 1e-6); // x = 1: (2.51 + 0.03) / (2.43 + 0.59 + 0.14)
    EXPECT_EQ(computeTonemappedColor(glm::vec3(-3.0f), {}).x, 0.0f);
    EXPECT_EQ(parseTonemapper("reinhard"), Tonemapper::Reinhard);
    EXPECT_THROW(parseTonemapper("filmic"), Error);
}

TEST_F(LightingPassTest, CornellBoxWithPointLightMatchesEmbreeDirect)
{
    // cornell_box has only an emissive ceiling quad and no point light. Its emission is switched
    // off (this pass leaves emissive triangles to the indirect slot) and a point light hangs
    // 5 cm below the ceiling; the Embree reference then evaluates exactly the same light with
    // no noise (next-event estimation toward the point light, nothing else emits).
    constexpr int kSize = 64;
    const scene::Scene cornell = scene::makeProceduralScene("cornell_box");
    scene::RenderScene s = cornell.buildRenderScene(0);
    for (scene::Material& m : s.materials)
        m.emission = glm::vec3(0.0f);
    const scene::PointLight light{{0.278f, 0.498f, 0.2795f}, {0.2f, 0.18f, 0.15f}};
    s.pointLights.push_back(light);
    const scene::GBuffer g = drawFrame(s, cornell.camera, kSize, kSize);
    const Image<glm::vec3> direct = getLighting().readBackDirect();

    reference::ReferenceSettings settings;
    settings.quantity = reference::Quantity::Direct;
    settings.batchSize = 4;
    settings.maxSamples = 4;
    settings.useCache = false;
    const reference::ReferenceResult ref = reference::computeReference(s, g, settings);

    // Classify each surface pixel by the reference: lit (= the unshadowed closed form) or in
    // shadow (0). Pixels whose 3 x 3 neighbourhood is all lit or all shadowed are "interior";
    // the others lie on a shadow edge, where PCF (soft) and Embree (hard) differ by design.
    auto unshadowed = [&](int x, int y) { return computePointLightRadiance(g, x, y, light); };
    auto isLit = [&](int x, int y) {
        return double(ref.radiance.at(x, y).x) > 0.5 * unshadowed(x, y).x;
    };
    int interior = 0, mismatched = 0, edge = 0;
    double sumGpu = 0.0, sumRef = 0.0;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            if (!g.hasSurface(x, y))
                continue;
            ASSERT_TRUE(isFinite(direct.at(x, y)));
            sumGpu += direct.at(x, y).x + direct.at(x, y).y + direct.at(x, y).z;
            sumRef += ref.radiance.at(x, y).x + ref.radiance.at(x, y).y + ref.radiance.at(x, y).z;
            bool uniform = true;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int nx = x + dx, ny = y + dy;
                    if (nx < 0 || ny < 0 || nx >= kSize || ny >= kSize || !g.hasSurface(nx, ny) ||
                        isLit(nx, ny) != isLit(x, y))
                        uniform = false;
                }
            if (!uniform) {
                ++edge;
                continue;
            }
            ++interior;
            // Interior pixels: 1e-3 of the unshadowed radiance (Embree's ray offset of 1e-5 of
            // the scene size and float32 rounding are far below it).
            const double scale = getMaxComponent(unshadowed(x, y)) + 1e-9;
            const double diff = getMaxComponent(
                glm::abs(glm::dvec3(direct.at(x, y)) - glm::dvec3(ref.radiance.at(x, y))));
            if (diff > 1e-3 * scale)
                ++mismatched;
        }
    // Up to 1% of the interior pixels may differ: concave corners (floor against wall or block)
    // where a PCF tap one texel away sees the adjacent wall closer than the receiver.
    EXPECT_GT(interior, kSize * kSize / 2);
    EXPECT_LE(mismatched, interior / 100) << "of " << interior << " interior pixels";
    // Over the whole image the energy agrees within 0.5%: soft and hard shadow edges trade
    // light between the ~15% of pixels near an edge (seen: 7 of 3268 interior pixels differ,
    // sums within 0.05%, on lavapipe).
    EXPECT_NEAR(sumGpu, sumRef, 0.005 * sumRef) << edge << " edge pixels";
}

TEST_F(LightingPassTest, DegenerateLightsGiveFiniteOutput)
{
    constexpr int kSize = 32;
    SceneBuilder b;
    const std::uint32_t m = b.addMaterial(kAlbedo);
    addFloor(b, 2.0f, m);
    b.addBox({0.0f, 1.0f, 0.0f}, {0.3f, 0.3f, 0.3f}, 0.4f, m);
    scene::RenderScene s = b.getScene();
    s.sky.kind = scene::Sky::Kind::Constant;
    s.sky.constant = glm::vec3(0.2f);
    // A light inside the closed box: nothing outside it sees the light.
    s.pointLights.push_back({{0.0f, 1.0f, 0.0f}, {5.0f, 5.0f, 5.0f}});
    const scene::Camera camera = makeCamera({0, 3, 3}, {0, 0.5f, 0});
    scene::GBuffer g = drawFrame(s, camera, kSize, kSize);
    Image<glm::vec3> direct = getLighting().readBackDirect();
    Image<glm::vec3> hdr = getLighting().readBackHdr();
    const float skyOnly = float(computeSkyIrradiance(s.sky, {0, 1, 0}).x / kPi) * 0.81f;
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            ASSERT_TRUE(isFinite(hdr.at(x, y)) && isFinite(direct.at(x, y))) << x << "," << y;
            // The enclosed light adds nothing: at most the sky (albedo 0.8 / pi * pi 0.2 * 1.01).
            EXPECT_LE(direct.at(x, y).x, skyOnly) << x << "," << y;
        }

    // A light exactly at a visible surface point (d = 0 there, tiny d around it).
    const int cx = kSize / 2, cy = kSize / 2;
    ASSERT_TRUE(g.hasSurface(cx, cy));
    s.pointLights[0].position = g.position.at(cx, cy);
    g = drawFrame(s, camera, kSize, kSize);
    direct = getLighting().readBackDirect();
    hdr = getLighting().readBackHdr();
    // Bound: albedo / pi * (I / minLightDistance^2 + sky irradiance).
    const float bound = 0.8f / float(kPi) * (5.0f / (1e-3f * 1e-3f) + float(kPi) * 0.2f);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            ASSERT_TRUE(isFinite(hdr.at(x, y)) && isFinite(direct.at(x, y))) << x << "," << y;
            EXPECT_LE(direct.at(x, y).x, bound);
            EXPECT_GE(direct.at(x, y).x, 0.0f);
        }
    getLighting().tonemap(TonemapSettings{});
    for (const glm::vec3& v : getLighting().readBackLdr().pixels)
        ASSERT_TRUE(isFinite(v) && v.x >= 0.0f && v.x <= 1.0f);
}

} // namespace
} // namespace rtlab::render::test
