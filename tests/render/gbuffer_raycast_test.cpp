// The G-buffer against a CPU ray cast of the same RenderScene through the same pixel samples
// (double precision, rays built from the camera's parameters, not its matrices), at several
// sizes and jitters. Compared on interior pixels: those whose samples one pixel away in all
// eight directions hit the same object (or all miss). Also checks the frame matrices against
// the reference rays.
//
// Tolerances (see gbuffer_pass_test.cpp): 1e-5 relative to the camera distance for float32
// interpolation, plus the rasteriser's vertex snap (2^-subPixelPrecisionBits px) times the
// larger change of the quantity to a neighbouring sample in x and in y.

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <ostream>
#include <vector>

#include "render/frame_matrices.h"
#include "render_test_support.h"

namespace rtlab::render::test {
namespace {

constexpr double kVaryingRel = 1e-5;

SceneBuilder buildTestScene()
{
    SceneBuilder b;
    const std::uint32_t floor = b.addMaterial({0.6f, 0.6f, 0.6f});
    const std::uint32_t red = b.addMaterial({0.8f, 0.1f, 0.1f});
    const std::uint32_t lamp = b.addMaterial({0.9f, 0.9f, 0.8f}, {5.0f, 4.5f, 3.0f});
    const std::uint32_t blue = b.addMaterial({0.1f, 0.2f, 0.7f});
    b.addQuad({-6, -1, 6}, {6, -1, 6}, {6, -1, -12}, {-6, -1, -12}, floor);
    b.addBox({-1.3f, -0.4f, -2.5f}, {0.5f, 0.6f, 0.5f}, 0.5f, red);
    b.addSphere({0.6f, -0.1f, -2.0f}, 0.7f, 32, 16, lamp);
    // A tilted checkerboard wall behind (shared vertices between two materials).
    b.addCheckerGrid({-3.0f, -1.0f, -5.5f}, {6.0f, 0.0f, 1.0f}, {0.0f, 3.5f, -0.8f}, 8, blue, red);
    return b;
}

scene::Camera makeSceneCamera()
{
    scene::Camera c;
    c.position = {0.3f, 0.9f, 2.0f};
    c.target = {0.0f, -0.3f, -2.0f};
    c.up = {0.0f, 1.0f, 0.0f};
    c.verticalFovDegrees = 55.0f;
    c.nearPlane = 0.1f;
    c.farPlane = 50.0f;
    return c;
}

// What the samples one pixel away in each of the eight directions tell about a pixel.
struct Neighbourhood {
    bool interior = true;         // all hit the centre's object, or all miss like the centre
    bool sameMaterial = true;     // all have the centre's material
    bool normalContinuous = true; // no normal differs from the centre's by more than 0.5
    double depthChange = 0.0;     // larger change to a neighbour in x plus that in y
    double positionChange = 0.0;
    double normalChange = 0.0;
};

Neighbourhood inspectNeighbourhood(const SceneBuilder& b, const scene::Camera& camera, int w, int h,
                                   glm::dvec2 sample, const CpuSample& centre)
{
    Neighbourhood n;
    double depth[2] = {0, 0}, position[2] = {0, 0}, normal[2] = {0, 0};
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            if (dx == 0 && dy == 0)
                continue;
            const CpuSample s = castSample(b, camera, w, h, sample + glm::dvec2(dx, dy));
            if (s.hit != centre.hit || s.object != centre.object) {
                n.interior = false;
                continue;
            }
            if (!s.hit)
                continue;
            n.sameMaterial = n.sameMaterial && s.material == centre.material;
            n.normalContinuous = n.normalContinuous && glm::length(s.normal - centre.normal) <= 0.5;
            if (dx != 0 && dy != 0)
                continue;
            const int axis = dx != 0 ? 0 : 1;
            depth[axis] = std::max(depth[axis], std::abs(s.depth - centre.depth));
            position[axis] = std::max(position[axis], glm::length(s.position - centre.position));
            normal[axis] = std::max(normal[axis], glm::length(s.normal - centre.normal));
        }
    }
    n.depthChange = depth[0] + depth[1];
    n.positionChange = position[0] + position[1];
    n.normalChange = normal[0] + normal[1];
    return n;
}

struct Case {
    int width;
    int height;
    glm::vec2 jitter;
    int minComparedHits; // interior surface pixels the case must reach (few in tiny images)
};

void PrintTo(const Case& c, std::ostream* out)
{
    *out << c.width << "x" << c.height << " jitter (" << c.jitter.x << ", " << c.jitter.y << ")";
}

class GBufferRayCastTest : public RenderTest, public ::testing::WithParamInterface<Case> {};

TEST_P(GBufferRayCastTest, InteriorPixelsMatchTheCpuRayCast)
{
    const Case c = GetParam();
    const SceneBuilder b = buildTestScene();
    const scene::Camera camera = makeSceneCamera();
    getPass().setScene(b.getScene());
    const scene::GBuffer g = getPass().render(camera, c.width, c.height, c.jitter);
    ASSERT_EQ(g.width, c.width);
    ASSERT_EQ(g.height, c.height);
    const double snap = getSnapPixels();
    const glm::dvec3 eye(camera.position);

    int interior = 0, hits = 0;
    for (int y = 0; y < c.height; ++y) {
        for (int x = 0; x < c.width; ++x) {
            const glm::dvec2 sample(x + 0.5 + c.jitter.x, y + 0.5 + c.jitter.y);
            const CpuSample cpu = castSample(b, camera, c.width, c.height, sample);
            const Neighbourhood n = inspectNeighbourhood(b, camera, c.width, c.height, sample, cpu);
            if (!n.interior)
                continue;
            ++interior;
            ASSERT_EQ(g.hasSurface(x, y), cpu.hit) << x << "," << y;
            if (!cpu.hit)
                continue;
            ++hits;
            const double distance = glm::length(cpu.position - eye);
            const double depthTol = kVaryingRel * distance + snap * n.depthChange;
            EXPECT_NEAR(g.depth.at(x, y), cpu.depth, depthTol) << x << "," << y;
            const double positionTol = kVaryingRel * distance + snap * n.positionChange;
            EXPECT_LE(glm::length(glm::dvec3(g.position.at(x, y)) - cpu.position), positionTol)
                << x << "," << y;
            if (n.sameMaterial) {
                const scene::Material& m = b.getScene().materials[cpu.material];
                EXPECT_EQ(g.materialId.at(x, y), cpu.material) << x << "," << y;
                EXPECT_EQ(g.albedo.at(x, y), m.albedo) << x << "," << y;
                EXPECT_EQ(g.emission.at(x, y), m.emission) << x << "," << y;
            }
            if (n.normalContinuous) {
                const double normalTol = kVaryingRel + snap * n.normalChange;
                EXPECT_LE(glm::length(glm::dvec3(g.normal.at(x, y)) - cpu.normal), normalTol)
                    << x << "," << y;
            }
        }
    }
    // The comparison is not vacuous: enough surface pixels were compared.
    EXPECT_GE(hits, c.minComparedHits) << interior << " interior pixels";
}

INSTANTIATE_TEST_SUITE_P(
    Sizes, GBufferRayCastTest,
    ::testing::Values(Case{96, 64, {0.0f, 0.0f}, 4000}, Case{96, 64, {0.5f, -0.25f}, 4000},
                      Case{17, 9, {0.3f, -0.2f}, 40}, Case{33, 7, {0.0f, 0.45f}, 40},
                      Case{41, 11, {0.0f, 0.0f}, 100}, Case{5, 15, {-0.4f, 0.0f}, 30}),
    [](const ::testing::TestParamInfo<Case>& info) {
        return std::to_string(info.param.width) + "x" + std::to_string(info.param.height) + "_" +
               std::to_string(info.index);
    });

TEST(FrameMatricesTest, JitteredSampleRaysProjectOntoPixelCentres)
{
    const scene::Camera camera = makeSceneCamera();
    for (const glm::ivec2 size : {glm::ivec2(17, 9), glm::ivec2(1, 1), glm::ivec2(1280, 720)}) {
        for (const glm::vec2 jitter :
             {glm::vec2(0.0f), glm::vec2(0.5f, 0.0f), glm::vec2(-0.25f, 0.375f)}) {
            const FrameMatrices m = computeFrameMatrices(camera, size.x, size.y, jitter);
            for (const glm::ivec2 pixel : {glm::ivec2(0, 0), size - 1, size / 2}) {
                const glm::dvec2 sample(pixel.x + 0.5 + jitter.x, pixel.y + 0.5 + jitter.y);
                const glm::dvec3 dir = computeReferenceRayDirection(camera, size.x, size.y, sample);
                const glm::dvec3 world = glm::dvec3(camera.position) + 3.0 * dir; // depth 3
                const glm::vec4 clip = m.projection * m.view * glm::vec4(glm::vec3(world), 1.0f);
                const glm::dvec3 ndc = glm::dvec3(clip) / double(clip.w);
                // The sample's point lands on the pixel centre of the jittered raster.
                EXPECT_NEAR((ndc.x + 1.0) / 2.0 * size.x, pixel.x + 0.5, 1e-4 * size.x);
                EXPECT_NEAR((ndc.y + 1.0) / 2.0 * size.y, pixel.y + 0.5, 1e-4 * size.y);
                EXPECT_NEAR(clip.w, 3.0, 1e-5); // clip w is the linear depth
                EXPECT_GT(ndc.z, 0.0);
                EXPECT_LT(ndc.z, 1.0);
                // The unjittered ray helper agrees with the reference rays.
                const glm::dvec3 helper(computePixelRayDirection(camera, size.x, size.y, sample));
                EXPECT_LT(glm::length(glm::normalize(helper) - glm::normalize(dir)), 1e-6);
            }
            EXPECT_LT(glm::length(glm::dvec3(m.viewForward) -
                                  glm::normalize(glm::dvec3(camera.target - camera.position))),
                      1e-6);
        }
    }
}

// Dense variant of the test scene: finer spheres, for timing.
SceneBuilder buildDenseScene()
{
    SceneBuilder b = buildTestScene();
    const std::uint32_t m = b.addMaterial({0.4f, 0.7f, 0.4f});
    for (int i = 0; i < 4; ++i)
        b.addSphere({-2.0f + 1.3f * float(i), 0.8f, -4.0f}, 0.5f, 180, 90, m);
    return b;
}

double findMedian(std::vector<double> values)
{
    std::sort(values.begin(), values.end());
    return values[values.size() / 2];
}

TEST_F(RenderTest, GpuTimeOfTheDrawAt1280x720)
{
    if (!getContext().hasGpuTimestamps())
        GTEST_SKIP() << "the device has no timestamps";
    const scene::Camera camera = makeSceneCamera();
    // Empty (the render pass only clears), the test scene, and its dense variant.
    for (const int kind : {0, 1, 2}) {
        const SceneBuilder b = kind == 0   ? SceneBuilder()
                               : kind == 1 ? buildTestScene()
                                           : buildDenseScene();
        getPass().setScene(b.getScene());
        getPass().draw(camera, 1280, 720); // warm-up: first use of the pipeline and target
        std::vector<double> ms;
        for (int i = 0; i < 5; ++i) {
            getPass().draw(camera, 1280, 720, {0.25f * float(i % 2), 0.0f});
            const std::optional<double> t = getPass().getLastGpuMs();
            ASSERT_TRUE(t.has_value());
            EXPECT_GT(*t, 0.0);
            EXPECT_TRUE(std::isfinite(*t));
            ms.push_back(*t);
        }
        const double median = findMedian(ms);
        std::cout << "gbuffer draw at 1280x720, " << b.getScene().triangleCount()
                  << " triangles on " << getContext().getDeviceInfo().name << ": median " << median
                  << " ms (min " << *std::min_element(ms.begin(), ms.end()) << ", max "
                  << *std::max_element(ms.begin(), ms.end()) << ")\n";
        const char* names[] = {"gpu_ms_empty", "gpu_ms", "gpu_ms_dense"};
        RecordProperty(names[kind], std::to_string(median));
    }
}

} // namespace
} // namespace rtlab::render::test
