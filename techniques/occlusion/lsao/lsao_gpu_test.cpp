// GPU tests of occlusion/lsao (lavapipe in CI, validation layer on): parity with the C++ path,
// robustness on both paths, determinism, resource reuse, several batches, and the GPU times of
// the two passes at 1280x720.

#include "lsao_cpu.h"
#include "lsao_gpu.h"
#include "lsao_test_support.h"

#include "gpu/context.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

namespace rtlab::occlusion::lsao::test {
namespace {

class LsaoGpu : public ::testing::Test {
protected:
    void SetUp() override
    {
        gpu::ContextOptions options;
        options.enableValidation = true;
        options.echoValidationMessages = true;
        mContext = std::make_unique<gpu::Context>(options);
        mLog = mContext->getValidationLog();
    }
    void TearDown() override
    {
        mContext.reset();
        EXPECT_EQ(mLog->countMessages(), 0u);
    }
    gpu::Context& getContext() { return *mContext; }

    std::unique_ptr<gpu::Context> mContext;
    std::shared_ptr<gpu::ValidationLog> mLog;
};

struct Differences {
    float ambient = 0.0f;
    float visible = 0.0f;  //!< of sin^2(aperture), the visible fraction A
    float aperture = 0.0f; //!< radians (reported only: asin(sqrt(A)) has slope 1/(2 sqrt(A(1-A))))
    float bent = 0.0f;
};

Differences compareOutputs(const plugin::OcclusionOutput& a, const plugin::OcclusionOutput& b)
{
    Differences d;
    EXPECT_EQ(a.ambient.pixels.size(), b.ambient.pixels.size());
    for (std::size_t i = 0; i < a.ambient.pixels.size(); ++i) {
        d.ambient = std::max(d.ambient, std::fabs(a.ambient.pixels[i] - b.ambient.pixels[i]));
        const float sa = std::sin(a.coneAperture.pixels[i]),
                    sb = std::sin(b.coneAperture.pixels[i]);
        d.visible = std::max(d.visible, std::fabs(sa * sa - sb * sb));
        d.aperture =
            std::max(d.aperture, std::fabs(a.coneAperture.pixels[i] - b.coneAperture.pixels[i]));
        d.bent = std::max(d.bent, glm::length(a.bentNormal.pixels[i] - b.bentNormal.pixels[i]));
    }
    return d;
}

//! Outputs in range at every pixel; the fixed values where there is no surface.
void expectValidOutput(const plugin::OcclusionOutput& out, const Image<float>& depth,
                       const Image<glm::vec3>& normal, const char* what)
{
    ASSERT_EQ(out.ambient.width, depth.width) << what;
    ASSERT_EQ(out.ambient.height, depth.height) << what;
    for (std::size_t i = 0; i < out.ambient.pixels.size(); ++i) {
        const float a = out.ambient.pixels[i];
        const float c = out.coneAperture.pixels[i];
        const glm::vec3 b = out.bentNormal.pixels[i];
        ASSERT_TRUE(a >= 0.0f && a <= 1.0f) << what << " pixel " << i << " ambient " << a;
        ASSERT_TRUE(c >= 0.0f && c <= 1.5707964f) << what << " pixel " << i << " aperture " << c;
        ASSERT_TRUE(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z)) << what;
        if (hasSurface(depth.pixels[i], normal.pixels[i])) {
            ASSERT_NEAR(glm::length(b), 1.0f, 1e-4f) << what << " pixel " << i;
        } else {
            ASSERT_EQ(a, 1.0f) << what;
            ASSERT_EQ(c, 0.0f) << what;
            ASSERT_EQ(glm::length(b), 0.0f) << what;
        }
    }
}

// Tolerances: both paths take the same discrete decisions (identical sweep buffers, checked
// below); what differs is the rounding of continuous quantities: GPU division, sqrt and
// inversesqrt are not correctly rounded (a few ulp), dot/normalize may be evaluated in another
// order. Those relative errors of ~1e-6 pass through ~36 * 4 half-slice evaluations. The
// aperture is compared as sin^2(aperture) = A, the quantity its convention defines: the angle
// itself, asin(sqrt(A)), turns a 1e-7 difference of A = 1 - 1e-7 into 3e-4 rad.
constexpr float kAmbientTolerance = 1e-4f;
constexpr float kVisibleTolerance = 1e-4f;
constexpr float kBentTolerance = 1e-4f;

TEST_F(LsaoGpu, MatchesTheCpuPathAndTheSweepBuffersAreIdentical)
{
    const GBuffer g = renderScene(makeFloorBoxScene(), 160, 120);
    const Overrides configs[] = {
        {},
        {{"falloff", std::string("smoothstep")}, {"radius", 0.3}},
        {{"jitter", false},
         {"near_field", false},
         {"directions", std::int64_t(7)},
         {"step", 3.5},
         {"line_spacing", 1.5},
         {"radius", 1e6}},
        {{"interleave", std::int64_t(1)}},
        // 20 directions over 16 classes: shares of 2 and 1 directions.
        {{"interleave", std::int64_t(4)}, {"directions", std::int64_t(20)}},
        {{"walls", false}},
        {{"walls", false}, {"falloff", std::string("smoothstep")}, {"radius", 0.3}},
        {{"gather", std::string("bilinear")}},
        {{"gather", std::string("bilinear")}, {"interleave", std::int64_t(1)}},
        {{"gather", std::string("bilinear")},
         {"walls", false},
         {"near_field", false},
         {"directions", std::int64_t(7)}},
    };
    for (int frame : {0, 3}) {
        for (const Overrides& o : configs) {
            Lsao gpuLsao = makeLsao(o);
            Lsao cpuLsao = makeLsao(o);
            plugin::OcclusionOutput gpuOut, cpuOut;
            gpuLsao.compute(g.makeInput(frame, &getContext()), gpuOut);
            cpuLsao.compute(g.makeInput(frame), cpuOut);
            expectValidOutput(gpuOut, g.depth, g.normal, "gpu");
            const Differences d = compareOutputs(gpuOut, cpuOut);
            std::printf("parity frame %d: max |d ambient| %.2g, |d sin^2 aperture| %.2g "
                        "(|d aperture| %.2g rad), |d bent| %.2g\n",
                        frame, d.ambient, d.visible, d.aperture, d.bent);
            EXPECT_LE(d.ambient, kAmbientTolerance);
            EXPECT_LE(d.visible, kVisibleTolerance);
            EXPECT_LE(d.bent, kBentTolerance);
        }
    }
    // The sweep decisions themselves: bit-identical.
    const Params params = makeLsao().getParams();
    const Layout layout = buildLayout(160, 120, g.screen, params, 2);
    ASSERT_EQ(layout.batches.size(), 1u);
    GpuRunner runner(getContext(), params);
    plugin::OcclusionOutput out;
    runner.run(layout, g.screen, params, g.depth, g.normal, out);
    const std::vector<std::uint32_t> gpuSweep = runner.downloadSweep(layout.batches[0].entryCount);
    const std::vector<std::uint32_t> cpuSweep = runSweepCpu(layout, 0, g.depth, g.normal);
    EXPECT_EQ(gpuSweep, cpuSweep);
    int found = 0;
    for (std::uint32_t id : cpuSweep)
        found += id != kNoOccluder;
    EXPECT_GT(found, 1000);
}

TEST_F(LsaoGpu, SeveralBatchesGiveTheSameResultAsOne)
{
    const GBuffer g = renderScene(makeFloorBoxScene(), 64, 48);
    const Params params = makeLsao().getParams();
    const Layout one = buildLayout(64, 48, g.screen, params, 1);
    const Layout many = buildLayout(64, 48, g.screen, params, 1, 2500);
    ASSERT_EQ(one.batches.size(), 1u);
    ASSERT_GT(many.batches.size(), 3u);
    GpuRunner runner(getContext(), params);
    plugin::OcclusionOutput a, b, c;
    runner.run(one, g.screen, params, g.depth, g.normal, a);
    runner.run(many, g.screen, params, g.depth, g.normal, b);
    computeOnCpu(many, g.screen, params, g.depth, g.normal, c);
    // Batches only store the float sums between dispatches: identical results.
    EXPECT_EQ(a.ambient.pixels, b.ambient.pixels);
    EXPECT_LE(compareOutputs(b, c).ambient, kAmbientTolerance);
}

TEST_F(LsaoGpu, IsDeterministicAndReusesItsResourcesAcrossSizes)
{
    Lsao lsao = makeLsao();
    const GBuffer big = renderScene(makeFloorBoxScene(), 80, 60);
    const GBuffer small = renderScene(makeFloorBoxScene(), 17, 9);
    plugin::OcclusionOutput first, second, third, odd;
    lsao.compute(big.makeInput(0, &getContext()), first);
    lsao.compute(big.makeInput(0, &getContext()), second);
    lsao.compute(small.makeInput(0, &getContext()), odd);
    lsao.compute(big.makeInput(0, &getContext()), third);
    EXPECT_EQ(first.ambient.pixels, second.ambient.pixels);
    EXPECT_TRUE(first.bentNormal.pixels == second.bentNormal.pixels);
    EXPECT_EQ(first.coneAperture.pixels, second.coneAperture.pixels);
    EXPECT_EQ(first.ambient.pixels, third.ambient.pixels);
    expectValidOutput(odd, small.depth, small.normal, "17x9");
}

//! A G-buffer with everything the family suite throws at techniques: depth 1e-3 .. 1e5, sky,
//! zero normals, grazing normals, discontinuities.
void makeHostileGBuffer(int w, int h, Image<float>& depth, Image<glm::vec3>& normal)
{
    const float depths[] = {1e-3f, 0.5f,   1e5f,  std::numeric_limits<float>::infinity(),
                            3.0f,  3.001f, 2e-3f, 7.0f};
    const glm::vec3 normals[] = {glm::vec3(0.0f, 0.0f, 1.0f),
                                 glm::vec3(0.0f),
                                 glm::normalize(glm::vec3(1.0f, 1.0f, 1.0f)),
                                 glm::normalize(glm::vec3(1.0f, 0.0f, 1e-3f)),
                                 glm::vec3(0.0f, 1.0f, 0.0f),
                                 glm::vec3(0.0f, 0.0f, 1e-8f),
                                 glm::normalize(glm::vec3(-0.3f, 0.2f, 0.9f))};
    depth = Image<float>(w, h);
    normal = Image<glm::vec3>(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            depth.at(x, y) = depths[(x * 7 + y * 3) % 8];
            normal.at(x, y) = normals[(x + 2 * y) % 7];
        }
    }
}

TEST_F(LsaoGpu, OutputIsValidOnHostileInputsOnBothPaths)
{
    const glm::ivec2 sizes[] = {{1, 1}, {2, 1}, {1, 3}, {17, 9}, {40, 23}};
    for (const glm::ivec2 size : sizes) {
        Image<float> depth;
        Image<glm::vec3> normal;
        makeHostileGBuffer(size.x, size.y, depth, normal);
        scene::Camera camera;
        const glm::mat4 projection =
            camera.projectionMatrix(float(size.x) / float(size.y), glm::vec2(0.4f, -0.3f), size);
        for (const double radius : {0.0, 1e-3, 1.0, 1e6}) {
            for (const char* falloff : {"linear", "smoothstep"}) {
                Lsao lsao = makeLsao({{"radius", radius}, {"falloff", std::string(falloff)}});
                plugin::OcclusionInput input;
                input.linearDepth = &depth;
                input.normal = &normal;
                input.projection = projection;
                plugin::OcclusionOutput cpu, gpu;
                lsao.compute(input, cpu);
                input.gpu = &getContext();
                lsao.compute(input, gpu);
                expectValidOutput(cpu, depth, normal, "cpu");
                expectValidOutput(gpu, depth, normal, "gpu");
                const Differences d = compareOutputs(cpu, gpu);
                EXPECT_LE(d.ambient, kAmbientTolerance) << size.x << "x" << size.y << " " << radius;
                EXPECT_LE(d.visible, kVisibleTolerance) << size.x << "x" << size.y << " " << radius;
                EXPECT_LE(d.bent, kBentTolerance) << size.x << "x" << size.y << " " << radius;
            }
        }
    }
    // Sky everywhere, and a flat plane at the extreme depths.
    for (const float z : {std::numeric_limits<float>::infinity(), 1e-3f, 1e5f}) {
        Image<float> depth(13, 7, z);
        Image<glm::vec3> normal(13, 7, z < 1e30f ? glm::vec3(0, 0, 1) : glm::vec3(0.0f));
        scene::Camera camera;
        plugin::OcclusionInput input;
        input.linearDepth = &depth;
        input.normal = &normal;
        input.projection = camera.projectionMatrix(13.0f / 7.0f);
        input.gpu = &getContext();
        plugin::OcclusionOutput out;
        makeLsao({{"radius", 1e6}}).compute(input, out);
        expectValidOutput(out, depth, normal, "uniform");
        for (float a : out.ambient.pixels)
            EXPECT_NEAR(a, 1.0f, 1e-5f) << z;
    }
}

//! A G-buffer of view-space planes: pixel (x, y) sees the nearest plane (point, normal) hit by
//! its ray from the eye; none: sky.
GBuffer makePlanesGBuffer(int w, int h, const std::vector<std::pair<glm::vec3, glm::vec3>>& planes,
                          float maxSlope = std::numeric_limits<float>::infinity())
{
    scene::Camera camera;
    camera.position = glm::vec3(0.0f);
    camera.target = glm::vec3(0.0f, 0.0f, -1.0f);
    camera.verticalFovDegrees = 60.0f;
    GBuffer g;
    g.projection = camera.projectionMatrix(float(w) / float(h), glm::vec2(0.0f), {w, h});
    g.view = camera.viewMatrix();
    g.screen = plugin::ScreenProjection::fromMatrix(g.projection, w, h);
    g.depth = Image<float>(w, h, std::numeric_limits<float>::infinity());
    g.normal = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const glm::vec3 r = g.screen.toView({x + 0.5f, y + 0.5f}, 1.0f); // depth 1
            for (std::size_t i = 0; i < planes.size(); ++i) {
                const auto& [point, n] = planes[i];
                // Plane 0 only inside |x/z|, |y/z| < maxSlope (a box face in front).
                if (i == 0 && (std::fabs(r.x) > maxSlope || std::fabs(r.y) > maxSlope))
                    continue;
                const float den = glm::dot(r, n);
                if (std::fabs(den) < 1e-8f)
                    continue;
                const float t = glm::dot(point, n) / den;
                if (t > 0.0f && t < g.depth.at(x, y)) {
                    g.depth.at(x, y) = t;
                    g.normal.at(x, y) = den > 0.0f ? -n : n;
                }
            }
        }
    }
    return g;
}

TEST_F(LsaoGpu, OutputIsValidOnTheFamilyStabilityCases)
{
    const glm::vec3 up(0, 1, 0), front(0, 0, 1);
    const std::pair<const char*, GBuffer> cases[] = {
        {"crease", makePlanesGBuffer(64, 48, {{{0, -1, 0}, up}, {{0, 0, -4}, front}})},
        {"depth step",
         makePlanesGBuffer(48, 32, {{{0, 0, -1}, front}, {{0, 0, -50}, front}}, 0.2f)},
        {"grazing",
         makePlanesGBuffer(40, 30, {{{0, -0.05f, 0}, glm::normalize(glm::vec3(0, 1, 0.02f))}})},
        {"near", makePlanesGBuffer(32, 24, {{{0, 0, -1e-3f}, front}})},
        {"far",
         makePlanesGBuffer(32, 24, {{{0, -1e4f, -1e5f}, glm::normalize(glm::vec3(0, 1, 1))}})},
    };
    for (const auto& [name, g] : cases) {
        for (const double radius : {0.0, 0.5, 1e6}) {
            Lsao lsao = makeLsao({{"radius", radius}});
            plugin::OcclusionOutput cpu, gpu;
            lsao.compute(g.makeInput(0), cpu);
            lsao.compute(g.makeInput(0, &getContext()), gpu);
            expectValidOutput(cpu, g.depth, g.normal, name);
            expectValidOutput(gpu, g.depth, g.normal, name);
            const Differences d = compareOutputs(cpu, gpu);
            EXPECT_LE(d.ambient, kAmbientTolerance) << name << " radius " << radius;
            EXPECT_LE(d.visible, kVisibleTolerance) << name << " radius " << radius;
            EXPECT_LE(d.bent, kBentTolerance) << name << " radius " << radius;
            const std::string n = name;
            if (n == "near" || n == "grazing" || n == "far") {
                // Single planes: nothing occludes them, at any incidence.
                for (float a : gpu.ambient.pixels)
                    ASSERT_NEAR(a, 1.0f, 1e-5f) << name << " radius " << radius;
            }
        }
    }
}

TEST_F(LsaoGpu, ReportsTheTimesOfItsThreePassesAt720p)
{
    const GBuffer g = renderScene(makeFloorBoxScene(), 1280, 720);
    Lsao lsao = makeLsao();
    getContext().takeRunLog();
    plugin::OcclusionOutput out;
    for (int frame = 0; frame < 2; ++frame)
        lsao.compute(g.makeInput(frame, &getContext()), out);
    const std::vector<gpu::CommandTime> log = getContext().takeRunLog();
    ASSERT_EQ(log.size(), 6u);
    const char* passes[] = {"lsao.sweep", "lsao.gather", "lsao.resolve"};
    for (std::size_t i = 0; i < log.size(); ++i) {
        EXPECT_EQ(log[i].label, passes[i % 3]);
        if (log[i].gpuMs)
            std::printf("%s: %.2f ms\n", log[i].label.c_str(), *log[i].gpuMs);
    }
    expectValidOutput(out, g.depth, g.normal, "720p");
}

} // namespace
} // namespace rtlab::occlusion::lsao::test
