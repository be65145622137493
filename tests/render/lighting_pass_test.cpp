// The shadow and lighting passes against closed forms, brute-force quadrature and the Embree
// ground truth: an unshadowed floor, the umbra of a box, the sky through its 16 lobes with and
// without visibility, tonemapping, a Cornell box with a point light, degenerate lights, and the
// per-light bookkeeping of the shadow maps.
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
#include <cstring>
#include <limits>
#include <vector>

#include "core/error.h"
#include "reference/reference.h"
#include "render/image_transfer.h"
#include "render/lighting_pass.h"
#include "render/shadow_pass.h"
#include "render/sky_irradiance.h"
#include "render_test_support.h"
#include "scene/procedural.h"

namespace rtlab::render::test {
namespace {

constexpr double kPi = glm::pi<double>();
const glm::vec3 kAlbedo(0.8f, 0.6f, 0.4f);

scene::Camera makeCamera(glm::vec3 position, glm::vec3 target)
{
    scene::Camera c;
    c.position = position;
    c.target = target;
    c.up = {0.0f, 1.0f, 0.0f};
    c.verticalFovDegrees = 60.0f;
    c.nearPlane = 0.05f;
    c.farPlane = 100.0f;
    return c;
}

// A floor y = 0 over [-h, h]^2 facing up.
void addFloor(SceneBuilder& b, float h, std::uint32_t material)
{
    b.addQuad({-h, 0, h}, {h, 0, h}, {h, 0, -h}, {-h, 0, -h}, material);
}

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

class LightingPassTest : public RenderTest {
protected:
    void SetUp() override
    {
        RenderTest::SetUp();
        if (HasFatalFailure())
            return;
        ShadowPassOptions shadowOptions;
        shadowOptions.compiler = getCompiler().getOptions();
        mShadows.emplace(getContext(), shadowOptions);
        LightingPassOptions lightingOptions;
        lightingOptions.compiler = getCompiler().getOptions();
        mLighting.emplace(getContext(), lightingOptions);
    }
    void TearDown() override
    {
        mLighting.reset();
        mShadows.reset();
        RenderTest::TearDown();
    }

    ShadowPass& getShadows() { return *mShadows; }
    LightingPass& getLighting() { return *mLighting; }

    //! G-buffer, shadow maps and lighting of one frame; returns the CPU G-buffer.
    scene::GBuffer drawFrame(const scene::RenderScene& s, const scene::Camera& camera, int w, int h,
                             LightingInputs inputs = {})
    {
        getPass().setScene(s);
        getPass().draw(camera, w, h);
        getShadows().render(s);
        inputs.gbuffer = &getPass().getTarget();
        inputs.camera = camera;
        if (inputs.shadows == nullptr)
            inputs.shadows = &getShadows();
        getLighting().draw(s, inputs);
        return getPass().readBack();
    }

private:
    std::optional<ShadowPass> mShadows;
    std::optional<LightingPass> mLighting;
};

class ShadowPassTest : public LightingPassTest {};

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

TEST_F(ShadowPassTest, FacesStoreTheDistanceToAnEnclosingBox)
{
    // A light at the centre of an axis-aligned cube of half size a: the texel at face
    // coordinates (s, t) sees the wall at distance a * sqrt(1 + s^2 + t^2).
    SceneBuilder b;
    const float a = 0.5f;
    b.addBox({1.0f, 2.0f, 3.0f}, glm::vec3(a), 0.0f, b.addMaterial(kAlbedo));
    scene::RenderScene s = b.getScene();
    s.pointLights.push_back({{1.0f, 2.0f, 3.0f}, glm::vec3(1.0f)});
    getShadows().render(s);
    const int n = getShadows().getFaceSize();
    EXPECT_EQ(n, 256);
    for (int face = 0; face < kCubeFaceCount; ++face) {
        const Image<float> map = getShadows().readBackFace(0, face);
        for (const glm::ivec2 texel : {glm::ivec2(0, 0), glm::ivec2(n / 2, n / 2),
                                       glm::ivec2(n - 1, 7), glm::ivec2(31, n - 2)}) {
            const glm::vec2 st = (glm::vec2(texel) + 0.5f) / float(n) * 2.0f - 1.0f;
            const double expected = a * std::sqrt(1.0 + st.x * st.x + st.y * st.y);
            // 1e-5 relative: float32 interpolation of the light-relative position.
            EXPECT_NEAR(map.at(texel.x, texel.y), expected, 1e-5 * expected)
                << "face " << face << " texel " << texel.x << "," << texel.y;
        }
        // The face mapping and its inverse agree.
        const glm::vec3 dir = computeCubeFaceDirection(face, {0.3f, -0.7f});
        EXPECT_EQ(computeCubeFace(dir), face);
        const glm::vec2 st = computeCubeFaceCoords(dir, face);
        EXPECT_NEAR(st.x, 0.3f, 1e-6f);
        EXPECT_NEAR(st.y, -0.7f, 1e-6f);
    }
}

TEST_F(ShadowPassTest, RendersOnlyTheChosenLights)
{
    SceneBuilder b;
    addFloor(b, 2.0f, b.addMaterial(kAlbedo));
    scene::RenderScene s = b.getScene();
    s.pointLights.push_back({{0.0f, 1.0f, 0.0f}, glm::vec3(1.0f)});
    s.pointLights.push_back({{0.5f, 2.0f, 0.0f}, glm::vec3(1.0f)});
    getShadows().render(s);
    ASSERT_EQ(getShadows().getLightCount(), 2u);
    const Image<float> before = getShadows().readBackFace(0, 3); // -y: the floor below light 0

    // Light 0 moves but only light 1 is re-rendered: light 0 keeps its old map and position.
    s.pointLights[0].position.y = 1.5f;
    const std::size_t chosen[] = {1};
    const gpu::RunResult r = getShadows().render(s, chosen);
    EXPECT_EQ(r.commands.size(), 2u * kCubeFaceCount); // a draw and a copy per face
    EXPECT_TRUE(r.sumGpuMs(ShadowPass::kDrawLabel).has_value() || !getContext().hasGpuTimestamps());
    EXPECT_EQ(getShadows().getLightState(0).renderCount, 1u);
    EXPECT_EQ(getShadows().getLightState(1).renderCount, 2u);
    EXPECT_EQ(getShadows().getLightState(0).position.y, 1.0f);
    EXPECT_EQ(getShadows().readBackFace(0, 3).pixels, before.pixels);

    // Re-rendering light 0 updates its map (the floor is now 1.5 away below it).
    const std::size_t first[] = {0};
    getShadows().render(s, first);
    const int n = getShadows().getFaceSize();
    EXPECT_NEAR(getShadows().readBackFace(0, 3).at(n / 2, n / 2), 1.5f, 1e-3f);
    const std::size_t bad[] = {2};
    EXPECT_THROW(getShadows().render(s, bad), Error);

    // A third light reallocates the atlas and renders every light.
    s.pointLights.push_back({{-0.5f, 1.0f, 0.5f}, glm::vec3(1.0f)});
    getShadows().render(s, first);
    EXPECT_EQ(getShadows().getLightCount(), 3u);
    for (std::size_t i = 0; i < 3; ++i)
        EXPECT_TRUE(getShadows().getLightState(i).rendered) << i;
}

TEST_F(ShadowPassTest, AnAtlasTheCallerOwnsHoldsTheSameMapsAsTheOwnOne)
{
    // The frame graph owns the atlas (pipeline/compose.h): a pass rendering into it must give
    // bit for bit the maps of a pass with its own atlas; an atlas too small for the scene's
    // lights, or of another kind, is refused.
    SceneBuilder b;
    const std::uint32_t m = b.addMaterial(kAlbedo);
    addFloor(b, 2.0f, m);
    b.addBox({-0.5f, 0.3f, 0.2f}, {0.3f, 0.3f, 0.3f}, 0.4f, m);
    scene::RenderScene s = b.getScene();
    s.pointLights.push_back({{0.0f, 1.2f, 0.0f}, glm::vec3(1.0f)});
    s.pointLights.push_back({{1.0f, 0.8f, -0.6f}, glm::vec3(1.0f)});
    ShadowPassOptions options;
    options.compiler = getCompiler().getOptions();
    options.faceSize = 32;
    ShadowPass own(getContext(), options);
    own.render(s);
    const gpu::Image atlas =
        getContext().createImage(ShadowPass::makeAtlasDesc(options.faceSize, 2));
    ShadowPass external(getContext(), options);
    external.useAtlas(atlas);
    external.render(s);
    EXPECT_EQ(&external.getAtlas(), &atlas);
    for (std::size_t light = 0; light < 2; ++light)
        for (int face = 0; face < kCubeFaceCount; ++face) {
            const Image<float> a = own.readBackFace(light, face);
            const Image<float> c = external.readBackFace(light, face);
            ASSERT_EQ(a.pixels.size(), c.pixels.size());
            EXPECT_EQ(std::memcmp(a.pixels.data(), c.pixels.data(), a.pixels.size() * sizeof(float)),
                      0)
                << "light " << light << " face " << face;
        }
    const gpu::Image small = getContext().createImage(ShadowPass::makeAtlasDesc(options.faceSize, 1));
    ShadowPass tooSmall(getContext(), options);
    tooSmall.useAtlas(small);
    EXPECT_THROW(tooSmall.render(s), Error);
    const gpu::Image wrongSize = getContext().createImage(ShadowPass::makeAtlasDesc(16, 2));
    EXPECT_THROW(tooSmall.useAtlas(wrongSize), Error);
}

TEST(ShadowFaces, ABoxInsideOneFacesPyramidTouchesThatFaceOnly)
{
    const glm::vec3 light(1.0f, 2.0f, 3.0f);
    const glm::vec3 half(0.5f);
    // Centred on each face's axis at distance 2.5: every point has that major axis.
    for (int face = 0; face < kCubeFaceCount; ++face) {
        const glm::vec3 centre = light + 2.5f * computeCubeFaceDirection(face, {0.0f, 0.0f});
        EXPECT_EQ(computeCubeFacesTouching(light, centre - half, centre + half), 1u << face)
            << "face " << face;
    }
    // Across the +x / +y edge: both, and none of the opposite faces.
    const std::uint8_t edge = computeCubeFacesTouching(light, light + glm::vec3(1.5f, 1.5f, -0.1f),
                                                       light + glm::vec3(2.5f, 2.5f, 0.1f));
    EXPECT_EQ(edge & 0x0F, 0x05) << "+x and +y, not -x or -y: " << int(edge);
    // The light inside the box or on its boundary: every face.
    EXPECT_EQ(computeCubeFacesTouching(light, light - half, light + half), kAllCubeFaces);
    EXPECT_EQ(computeCubeFacesTouching(light, light, light + half), kAllCubeFaces);
    // An empty box: none.
    EXPECT_EQ(computeCubeFacesTouching(light, light + half, light - half), 0u);
    EXPECT_EQ(computeCubeFacesTouching(light, {4, 0, 0}, {5, 0, -1}), 0u);
}

TEST(ShadowFaces, NeverMissesAFaceThatSeesAPointOfTheBox)
{
    // Random boxes around a light, random points in them: the face of every point is in the
    // mask (conservative), checked for 2000 boxes x 64 points.
    std::uint64_t state = 12345;
    auto next = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return float((state >> 40) & 0xFFFFFF) / float(0x1000000);
    };
    const glm::vec3 light(0.25f, -0.5f, 1.0f);
    int partial = 0;
    for (int box = 0; box < 2000; ++box) {
        const glm::vec3 centre =
            light + glm::vec3(next() - 0.5f, next() - 0.5f, next() - 0.5f) * 8.0f;
        const glm::vec3 half = glm::vec3(next(), next(), next()) * 0.7f;
        const std::uint8_t mask = computeCubeFacesTouching(light, centre - half, centre + half);
        partial += mask != kAllCubeFaces ? 1 : 0;
        for (int i = 0; i < 64; ++i) {
            const glm::vec3 p = centre + (glm::vec3(next(), next(), next()) * 2.0f - 1.0f) * half;
            if (p == light)
                continue;
            const int face = computeCubeFace(p - light);
            ASSERT_TRUE(mask & (1u << face))
                << "box " << box << " point " << i << " face " << face << " mask " << int(mask);
        }
    }
    EXPECT_GT(partial, 1000) << "most boxes miss some face";
}

TEST_F(ShadowPassTest, RenderingTheFacesAChangeTouchesGivesTheFullRendering)
{
    // A floor, a still box and a small box beside light 0 on its +x side. The small box moves;
    // the faces computeCubeFacesTouching reports for the box of its old and new triangles are
    // re-rendered, the others kept. Every face of both lights must equal, bit for bit, a full
    // rendering of the new scene by a second pass. The scene's bounds stay the same (the floor
    // and the still box set them), so the planes do too.
    const glm::vec3 half(0.1f);
    auto makeScene = [&](glm::vec3 smallBox) {
        SceneBuilder b;
        const std::uint32_t m = b.addMaterial(kAlbedo);
        addFloor(b, 2.0f, m);
        b.addBox({-1.0f, 0.5f, -1.0f}, {0.3f, 0.5f, 0.3f}, 0.3f, m);
        b.addBox(smallBox, half, 0.0f, m);
        scene::RenderScene s = b.getScene();
        s.pointLights.push_back({{0.0f, 0.6f, 0.0f}, glm::vec3(1.0f)});
        s.pointLights.push_back({{1.2f, 1.8f, 1.5f}, glm::vec3(1.0f)});
        return s;
    };
    const glm::vec3 before(0.6f, 0.6f, 0.0f), after(0.6f, 0.6f, 0.15f);
    const scene::RenderScene s0 = makeScene(before);
    const scene::RenderScene s1 = makeScene(after);
    getShadows().render(s0);
    const Image<float> oldPlusX = getShadows().readBackFace(0, 0);

    const glm::vec3 changedMin = glm::min(before, after) - half;
    const glm::vec3 changedMax = glm::max(before, after) + half;
    std::vector<std::uint8_t> masks;
    for (const scene::PointLight& l : s1.pointLights)
        masks.push_back(computeCubeFacesTouching(l.position, changedMin, changedMax));
    EXPECT_EQ(masks[0], 0x01) << "the small box lies in light 0's +x pyramid";
    const gpu::RunResult r = getShadows().renderFaces(s1, masks);
    std::size_t drawn = 0;
    for (std::size_t light = 0; light < 2; ++light) {
        const ShadowLightState& state = getShadows().getLightState(light);
        EXPECT_EQ(state.lastFaceMask, masks[light]) << light;
        for (int face = 0; face < kCubeFaceCount; ++face) {
            const bool chosen = (masks[light] & (1u << face)) != 0;
            EXPECT_EQ(state.faceRenderCounts[std::size_t(face)], chosen ? 2u : 1u)
                << "light " << light << " face " << face;
            drawn += chosen ? 1 : 0;
        }
    }
    EXPECT_LT(drawn, 2u * kCubeFaceCount);
    EXPECT_EQ(r.commands.size(), 2 * drawn); // a draw and a copy per face
    EXPECT_NE(getShadows().readBackFace(0, 0).pixels, oldPlusX.pixels)
        << "the move changes face +x of light 0";

    ShadowPassOptions options;
    options.compiler = getCompiler().getOptions();
    ShadowPass fresh(getContext(), options);
    fresh.render(s1);
    for (std::size_t light = 0; light < 2; ++light) {
        EXPECT_EQ(getShadows().getLightState(light).nearPlane,
                  fresh.getLightState(light).nearPlane);
        EXPECT_EQ(getShadows().getLightState(light).farPlane, fresh.getLightState(light).farPlane);
        for (int face = 0; face < kCubeFaceCount; ++face) {
            const Image<float> kept = getShadows().readBackFace(light, face);
            const Image<float> full = fresh.readBackFace(light, face);
            ASSERT_EQ(kept.pixels.size(), full.pixels.size());
            EXPECT_EQ(std::memcmp(kept.pixels.data(), full.pixels.data(),
                                  kept.pixels.size() * sizeof(float)),
                      0)
                << "light " << light << " face " << face;
        }
    }

    // A partial mask of a light that moved is widened to every face: one projection per cube.
    scene::RenderScene s2 = s1;
    s2.pointLights[0].position.y += 0.1f;
    const std::uint8_t one[] = {0x01, 0x00};
    getShadows().renderFaces(s2, one);
    EXPECT_EQ(getShadows().getLightState(0).lastFaceMask, kAllCubeFaces);
    EXPECT_EQ(getShadows().getLightState(1).lastFaceMask, 0u);
    const std::uint8_t wrongCount[] = {0x01};
    EXPECT_THROW(getShadows().renderFaces(s2, wrongCount), Error);
    const std::uint8_t badBits[] = {0x40, 0x00};
    EXPECT_THROW(getShadows().renderFaces(s2, badBits), Error);
}

} // namespace
} // namespace rtlab::render::test
