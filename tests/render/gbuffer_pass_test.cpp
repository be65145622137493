// The G-buffer pass against analytic expectations: a quad filling the view, silhouettes of a
// box, sub-pixel jitter, per-triangle materials, viewer-facing normals, tiny and odd sizes,
// repeatability, empty scenes and GPU timing.
//
// Tolerances. Attributes that are constant over a triangle (depth and position.z of a plane
// facing the camera, its normal) come out of clipping and perspective-correct interpolation
// within a few float32 roundings: 16 ulp (2e-6 relative). Attributes that vary across the screen
// may in addition move with the vertices, which the rasteriser snaps to 2^-subPixelPrecisionBits
// of a pixel: they get 1e-5 relative to the camera distance (float32 interpolation of
// camera-relative positions) plus that snap times their change per pixel in x and y.

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "core/error.h"
#include "render_test_support.h"

namespace rtlab::render::test {
namespace {

constexpr double kConstantRel = 2e-6;
constexpr double kVaryingRel = 1e-5;
constexpr float kInf = std::numeric_limits<float>::infinity();

scene::Camera makeCamera()
{
    scene::Camera c;
    c.position = {0.0f, 0.0f, 0.0f};
    c.target = {0.0f, 0.0f, -1.0f};
    c.up = {0.0f, 1.0f, 0.0f};
    c.verticalFovDegrees = 60.0f;
    c.nearPlane = 0.05f;
    c.farPlane = 100.0f;
    return c;
}

// The world point at view depth `depth` seen through pixel coordinates `pixel`.
glm::dvec3 findWorldAt(const scene::Camera& camera, int w, int h, glm::dvec2 pixel, double depth)
{
    // The reference direction has a forward component of exactly 1.
    return glm::dvec3(camera.position) + depth * computeReferenceRayDirection(camera, w, h, pixel);
}

// Intersection of the ray through `pixel` with the plane through `point` with normal `n`.
glm::dvec3 intersectPlane(const scene::Camera& camera, int w, int h, glm::dvec2 pixel,
                          glm::dvec3 point, glm::dvec3 n)
{
    const glm::dvec3 origin(camera.position);
    const glm::dvec3 dir = computeReferenceRayDirection(camera, w, h, pixel);
    const double t = glm::dot(point - origin, n) / glm::dot(dir, n);
    return origin + t * dir;
}

void expectSky(const scene::GBuffer& g, int x, int y)
{
    EXPECT_EQ(g.materialId.at(x, y), scene::kNoMaterial) << x << "," << y;
    EXPECT_EQ(g.depth.at(x, y), kInf) << x << "," << y;
    EXPECT_EQ(g.position.at(x, y), glm::vec3(0.0f)) << x << "," << y;
    EXPECT_EQ(g.normal.at(x, y), glm::vec3(0.0f)) << x << "," << y;
    EXPECT_EQ(g.albedo.at(x, y), glm::vec3(0.0f)) << x << "," << y;
    EXPECT_EQ(g.emission.at(x, y), glm::vec3(0.0f)) << x << "," << y;
}

class GBufferPassTest : public RenderTest {};

TEST_F(GBufferPassTest, QuadFillingTheViewHasItsDepthPositionNormalAndMaterialEverywhere)
{
    constexpr int kW = 64, kH = 40;
    const float d = 3.7f;
    SceneBuilder b;
    b.addMaterial({0.9f, 0.9f, 0.9f});
    const std::uint32_t m = b.addMaterial({0.25f, 0.5f, 0.75f}, {1.5f, 0.0f, 0.125f});
    b.addQuad({-40, -40, -d}, {40, -40, -d}, {40, 40, -d}, {-40, 40, -d}, m);
    const scene::Camera camera = makeCamera();
    getPass().setScene(b.getScene());
    const scene::GBuffer g = getPass().render(camera, kW, kH);

    ASSERT_EQ(g.width, kW);
    ASSERT_EQ(g.height, kH);
    const double footprint = 2.0 * d * std::tan(glm::radians(30.0)) / kH; // world units/pixel
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            ASSERT_EQ(g.materialId.at(x, y), m) << x << "," << y;
            EXPECT_EQ(g.albedo.at(x, y), glm::vec3(0.25f, 0.5f, 0.75f));
            EXPECT_EQ(g.emission.at(x, y), glm::vec3(1.5f, 0.0f, 0.125f));
            EXPECT_NEAR(g.depth.at(x, y), d, kConstantRel * d) << x << "," << y;
            const glm::vec3 p = g.position.at(x, y);
            EXPECT_NEAR(p.z, -d, kConstantRel * d) << x << "," << y;
            const glm::dvec3 expected = findWorldAt(camera, kW, kH, {x + 0.5, y + 0.5}, d);
            const double tol = kVaryingRel * d + 2.0 * getSnapPixels() * footprint;
            EXPECT_NEAR(p.x, expected.x, tol) << x << "," << y;
            EXPECT_NEAR(p.y, expected.y, tol) << x << "," << y;
            const glm::vec3 n = g.normal.at(x, y);
            EXPECT_NEAR(n.x, 0.0, kConstantRel) << x << "," << y;
            EXPECT_NEAR(n.y, 0.0, kConstantRel) << x << "," << y;
            EXPECT_NEAR(n.z, 1.0, kConstantRel) << x << "," << y;
        }
    }
    EXPECT_EQ(g.camera.position, camera.position);
    EXPECT_EQ(g.jitter, glm::vec2(0.0f));
}

// Renders a box whose front face covers the pixel-coordinate rectangle [left, right] x [top,
// bottom] and checks every pixel, and that the silhouette lies within half a pixel of the edges.
// The box contains the view axis, so its sides hide behind the front face.
void checkBoxSilhouette(GBufferPass& pass, int w, int h, double left, double right, double top,
                        double bottom)
{
    const float d = 2.5f;
    const scene::Camera camera = makeCamera();
    const glm::dvec3 topLeft = findWorldAt(camera, w, h, {left, top}, d);
    const glm::dvec3 bottomRight = findWorldAt(camera, w, h, {right, bottom}, d);
    SceneBuilder b;
    const std::uint32_t m = b.addMaterial({0.3f, 0.6f, 0.1f});
    const glm::vec3 half(float((bottomRight.x - topLeft.x) / 2),
                         float((topLeft.y - bottomRight.y) / 2), 0.5f);
    const glm::vec3 center(float((bottomRight.x + topLeft.x) / 2),
                           float((topLeft.y + bottomRight.y) / 2), -d - 0.5f);
    b.addBox(center, half, 0.0f, m);
    pass.setScene(b.getScene());
    const scene::GBuffer g = pass.render(camera, w, h);
    ASSERT_EQ(g.width, w);
    ASSERT_EQ(g.height, h);

    int failures = 0; // stop reporting after a few on large images
    for (int y = 0; y < h && failures < 20; ++y) {
        int first = -1, last = -1;
        for (int x = 0; x < w && failures < 20; ++x) {
            const double cx = x + 0.5, cy = y + 0.5;
            const bool inside = cx > left && cx < right && cy > top && cy < bottom;
            if (!inside) {
                const bool sky =
                    g.materialId.at(x, y) == scene::kNoMaterial && g.depth.at(x, y) == kInf &&
                    g.position.at(x, y) == glm::vec3(0.0f) &&
                    g.normal.at(x, y) == glm::vec3(0.0f) && g.albedo.at(x, y) == glm::vec3(0.0f) &&
                    g.emission.at(x, y) == glm::vec3(0.0f);
                if (!sky) {
                    ++failures;
                    expectSky(g, x, y);
                }
                continue;
            }
            const bool ok = g.materialId.at(x, y) == m &&
                            std::abs(g.depth.at(x, y) - d) <= kConstantRel * d &&
                            std::abs(g.normal.at(x, y).z - 1.0f) <= kConstantRel;
            if (!ok) {
                ++failures;
                ADD_FAILURE() << "pixel " << x << "," << y << ": material " << g.materialId.at(x, y)
                              << ", depth " << g.depth.at(x, y) << ", normal z "
                              << g.normal.at(x, y).z;
            }
            if (g.materialId.at(x, y) == m) {
                last = x;
                if (first < 0)
                    first = x;
            }
        }
        if (y + 0.5 > top && y + 0.5 < bottom) {
            // The boundary between uncovered and covered columns within half a pixel of the
            // projected edge.
            EXPECT_LE(std::abs(first - left), 0.5) << "row " << y;
            EXPECT_LE(std::abs(last + 1 - right), 0.5) << "row " << y;
        }
    }
    for (int x = 0; x < w; ++x) {
        int first = -1, last = -1;
        for (int y = 0; y < h; ++y) {
            if (g.materialId.at(x, y) == m) {
                last = y;
                if (first < 0)
                    first = y;
            }
        }
        if (x + 0.5 > left && x + 0.5 < right) {
            EXPECT_LE(std::abs(first - top), 0.5) << "column " << x;
            EXPECT_LE(std::abs(last + 1 - bottom), 0.5) << "column " << x;
        }
    }
}

TEST_F(GBufferPassTest, BoxSilhouetteLandsOnItsProjectedPixelEdges)
{
    checkBoxSilhouette(getPass(), 64, 48, 17.3, 45.6, 11.2, 35.7);
}

TEST_F(GBufferPassTest, BoxSilhouetteAt4K)
{
    checkBoxSilhouette(getPass(), 3840, 2160, 1037.3, 2911.6, 611.2, 1733.7);
}

TEST_F(GBufferPassTest, JitterMovesTheSamplesByExactlyTheGivenFractionOfAPixel)
{
    constexpr int kW = 48, kH = 32;
    const double edgeX = 20.75, edgeY = 10.75; // pixel coordinates of the two edges
    const float d = 2.0f;
    const scene::Camera camera = makeCamera();
    const double worldX = findWorldAt(camera, kW, kH, {edgeX, 0.5}, d).x;
    const double worldY = findWorldAt(camera, kW, kH, {0.5, edgeY}, d).y;

    // Right of edgeX: coverage of column 20 flips when its sample moves by more than 0.25 px.
    SceneBuilder right;
    const std::uint32_t m = right.addMaterial({0.5f, 0.5f, 0.5f});
    const auto x0 = float(worldX);
    right.addQuad({x0, -40, -d}, {40, -40, -d}, {40, 40, -d}, {x0, 40, -d}, m);
    getPass().setScene(right.getScene());
    for (const float jx : {0.0f, 0.5f, -0.5f, 0.375f, -0.125f}) {
        const scene::GBuffer g = getPass().render(camera, kW, kH, {jx, 0.0f});
        EXPECT_EQ(g.jitter, glm::vec2(jx, 0.0f));
        for (int y = 0; y < kH; ++y) {
            for (int x = 0; x < kW; ++x) {
                const bool covered = x + 0.5 + jx > edgeX;
                EXPECT_EQ(g.hasSurface(x, y), covered)
                    << "jitter " << jx << " at " << x << "," << y;
            }
        }
        EXPECT_EQ(g.hasSurface(20, 5), jx > 0.25f) << "jitter " << jx;
    }

    // Below edgeY (smaller world y): rows move the same way with vertical jitter.
    SceneBuilder below;
    const std::uint32_t m2 = below.addMaterial({0.5f, 0.5f, 0.5f});
    const auto y0 = float(worldY);
    below.addQuad({-40, -40, -d}, {40, -40, -d}, {40, y0, -d}, {-40, y0, -d}, m2);
    getPass().setScene(below.getScene());
    for (const float jy : {0.0f, 0.5f, -0.5f, 0.375f}) {
        const scene::GBuffer g = getPass().render(camera, kW, kH, {0.0f, jy});
        for (int y = 0; y < kH; ++y) {
            for (int x = 0; x < kW; ++x) {
                const bool covered = y + 0.5 + jy > edgeY;
                EXPECT_EQ(g.hasSurface(x, y), covered)
                    << "jitter " << jy << " at " << x << "," << y;
            }
        }
    }
}

TEST_F(GBufferPassTest, JitteredPositionsOnASlantedPlaneMatchTheMovedRays)
{
    constexpr int kW = 40, kH = 30;
    const scene::Camera camera = makeCamera();
    // Tilted by about 25 degrees: every pixel's ray meets it well inside the quad.
    const glm::dvec3 point(0.0, 0.0, -4.0);
    const glm::dvec3 n = glm::normalize(glm::dvec3(0.4, 0.2, 0.9));
    const glm::dvec3 u = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), n));
    const glm::dvec3 v = glm::cross(n, u);
    auto corner = [&](double su, double sv) { return glm::vec3(point + 20.0 * (su * u + sv * v)); };
    SceneBuilder b;
    const std::uint32_t m = b.addMaterial({0.5f, 0.5f, 0.5f});
    b.addQuad(corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1), m);
    getPass().setScene(b.getScene());

    for (const glm::vec2 jitter :
         {glm::vec2(0.0f), glm::vec2(0.5f, 0.0f), glm::vec2(0.0f, 0.5f), glm::vec2(-0.3f, 0.4f)}) {
        const scene::GBuffer g = getPass().render(camera, kW, kH, jitter);
        for (int y = 0; y < kH; ++y) {
            for (int x = 0; x < kW; ++x) {
                const glm::dvec2 s(x + 0.5 + jitter.x, y + 0.5 + jitter.y);
                const glm::dvec3 expected = intersectPlane(camera, kW, kH, s, point, n);
                const glm::dvec3 dx =
                    intersectPlane(camera, kW, kH, s + glm::dvec2(1, 0), point, n);
                const glm::dvec3 dy =
                    intersectPlane(camera, kW, kH, s + glm::dvec2(0, 1), point, n);
                const double tol =
                    kVaryingRel * glm::length(expected) +
                    getSnapPixels() * (glm::length(dx - expected) + glm::length(dy - expected));
                ASSERT_TRUE(g.hasSurface(x, y));
                const double error = glm::length(glm::dvec3(g.position.at(x, y)) - expected);
                EXPECT_LE(error, tol)
                    << "jitter " << jitter.x << "," << jitter.y << " at " << x << "," << y;
                const double depth = -expected.z; // camera looks down -z from the origin
                EXPECT_NEAR(g.depth.at(x, y), depth, tol) << x << "," << y;
                if (jitter != glm::vec2(0.0f)) {
                    // The test can tell: the unjittered sample is far outside the tolerance.
                    const glm::dvec3 unjittered =
                        intersectPlane(camera, kW, kH, {x + 0.5, y + 0.5}, point, n);
                    EXPECT_GT(glm::length(unjittered - expected), 10.0 * tol);
                }
            }
        }
    }
}

TEST_F(GBufferPassTest, EachTriangleGetsItsOwnMaterial)
{
    constexpr int kW = 50, kH = 30;
    const float d = 3.0f;
    SceneBuilder b;
    const std::uint32_t lower = b.addMaterial({0.1f, 0.2f, 0.3f}, {0.0f, 0.0f, 0.0f});
    const std::uint32_t upper = b.addMaterial({0.7f, 0.6f, 0.5f}, {2.0f, 1.0f, 0.5f});
    // Triangle (a, b, c) lies where world y < x, triangle (a, c, d) where y > x.
    b.addQuad({-40, -40, -d}, {40, -40, -d}, {40, 40, -d}, {-40, 40, -d}, lower, upper);
    const scene::Camera camera = makeCamera();
    getPass().setScene(b.getScene());
    const scene::GBuffer g = getPass().render(camera, kW, kH);
    const double footprint = 2.0 * d * std::tan(glm::radians(30.0)) / kH;
    int counts[2] = {0, 0};
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            const glm::dvec3 p = findWorldAt(camera, kW, kH, {x + 0.5, y + 0.5}, d);
            const double distance = (p.x - p.y) / std::sqrt(2.0) / footprint; // pixels
            if (std::abs(distance) < 0.5)
                continue;
            const bool isLower = distance > 0;
            const scene::Material& m = b.getScene().materials[isLower ? lower : upper];
            EXPECT_EQ(g.materialId.at(x, y), isLower ? lower : upper) << x << "," << y;
            EXPECT_EQ(g.albedo.at(x, y), m.albedo) << x << "," << y;
            EXPECT_EQ(g.emission.at(x, y), m.emission) << x << "," << y;
            ++counts[isLower ? 0 : 1];
        }
    }
    EXPECT_GT(counts[0], 300);
    EXPECT_GT(counts[1], 300);
}

TEST_F(GBufferPassTest, NormalsFaceTheViewerOnSurfacesSeenFromBehind)
{
    constexpr int kW = 16, kH = 12;
    const float d = 2.0f;
    SceneBuilder b;
    const std::uint32_t m = b.addMaterial({0.5f, 0.5f, 0.5f});
    // Counter-clockwise seen from -z: its front (and vertex normals (0, 0, -1)) face away.
    b.addQuad({-40, -40, -d}, {-40, 40, -d}, {40, 40, -d}, {40, -40, -d}, m);
    ASSERT_EQ(b.getScene().normals[0], glm::vec3(0.0f, 0.0f, -1.0f));
    getPass().setScene(b.getScene());
    const scene::GBuffer g = getPass().render(makeCamera(), kW, kH);
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            EXPECT_NEAR(g.normal.at(x, y).z, 1.0f, kConstantRel) << x << "," << y;
            EXPECT_NEAR(g.depth.at(x, y), d, kConstantRel * d) << x << "," << y;
        }
    }
}

TEST_F(GBufferPassTest, OnePixelImageSamplesTheCentreRay)
{
    const scene::Camera camera = makeCamera();
    const glm::dvec3 point(0.2, -0.1, -3.0);
    const glm::dvec3 n = glm::normalize(glm::dvec3(-0.5, 0.2, 1.0));
    const glm::dvec3 u = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), n));
    const glm::dvec3 v = glm::cross(n, u);
    auto corner = [&](double su, double sv) { return glm::vec3(point + 10.0 * (su * u + sv * v)); };
    SceneBuilder b;
    const std::uint32_t m = b.addMaterial({0.5f, 0.5f, 0.5f}, {0.0f, 1.0f, 0.0f});
    b.addQuad(corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1), m);
    getPass().setScene(b.getScene());
    for (const glm::vec2 jitter : {glm::vec2(0.0f), glm::vec2(0.25f, -0.4f)}) {
        const scene::GBuffer g = getPass().render(camera, 1, 1, jitter);
        ASSERT_EQ(g.width, 1);
        ASSERT_EQ(g.height, 1);
        ASSERT_EQ(g.materialId.at(0, 0), m);
        const glm::dvec2 s(0.5 + jitter.x, 0.5 + jitter.y);
        const glm::dvec3 expected = intersectPlane(camera, 1, 1, s, point, n);
        const glm::dvec3 dx = intersectPlane(camera, 1, 1, s + glm::dvec2(1, 0), point, n);
        const glm::dvec3 dy = intersectPlane(camera, 1, 1, s + glm::dvec2(0, 1), point, n);
        const double tol =
            kVaryingRel * glm::length(expected) +
            getSnapPixels() * (glm::length(dx - expected) + glm::length(dy - expected));
        EXPECT_LE(glm::length(glm::dvec3(g.position.at(0, 0)) - expected), tol);
        EXPECT_NEAR(g.depth.at(0, 0), -expected.z, tol);
        EXPECT_NEAR(glm::dot(glm::dvec3(g.normal.at(0, 0)), n), 1.0, kConstantRel);
        EXPECT_EQ(g.emission.at(0, 0), glm::vec3(0.0f, 1.0f, 0.0f));
    }
}

bool isBitwiseEqual(const scene::GBuffer& a, const scene::GBuffer& b)
{
    auto same = [](const auto& x, const auto& y) {
        return x.width == y.width && x.height == y.height &&
               std::memcmp(x.pixels.data(), y.pixels.data(),
                           x.pixels.size() * sizeof(x.pixels[0])) == 0;
    };
    return same(a.depth, b.depth) && same(a.position, b.position) && same(a.normal, b.normal) &&
           same(a.albedo, b.albedo) && same(a.emission, b.emission) &&
           same(a.materialId, b.materialId) && a.view == b.view && a.projection == b.projection;
}

TEST_F(GBufferPassTest, RepeatedFramesAreBitwiseIdentical)
{
    SceneBuilder b;
    const std::uint32_t grey = b.addMaterial({0.5f, 0.5f, 0.5f});
    const std::uint32_t red = b.addMaterial({0.8f, 0.1f, 0.1f}, {0.2f, 0.0f, 0.0f});
    b.addQuad({-5, -1, 5}, {5, -1, 5}, {5, -1, -15}, {-5, -1, -15}, grey);
    b.addSphere({0.3f, 0.0f, -3.0f}, 0.8f, 24, 12, red);
    b.addBox({-1.2f, -0.5f, -4.0f}, {0.4f, 0.5f, 0.4f}, 0.6f, grey);
    scene::Camera camera = makeCamera();
    camera.position = {0.2f, 0.6f, 1.0f};
    camera.target = {0.0f, -0.2f, -3.0f};
    getPass().setScene(b.getScene());
    const glm::vec2 jitter(0.125f, -0.375f);
    const scene::GBuffer first = getPass().render(camera, 37, 23, jitter);
    const scene::GBuffer again = getPass().render(camera, 37, 23, jitter);
    getPass().render(camera, 64, 64); // another size and jitter in between
    const scene::GBuffer later = getPass().render(camera, 37, 23, jitter);
    EXPECT_TRUE(isBitwiseEqual(first, again));
    EXPECT_TRUE(isBitwiseEqual(first, later));
    int hits = 0;
    for (std::uint32_t id : first.materialId.pixels)
        hits += id != scene::kNoMaterial;
    EXPECT_GT(hits, 200); // the frame shows the scene
}

TEST_F(GBufferPassTest, DrawingIntoATargetTheCallerOwnsGivesTheSameFrame)
{
    // The frame graph owns the G-buffer's attachments (pipeline/frame_start.h): a draw into them
    // must give bit for bit the frame of the pass's own target, and read back from them.
    SceneBuilder b;
    const std::uint32_t grey = b.addMaterial({0.5f, 0.5f, 0.5f});
    b.addQuad({-5, -1, 5}, {5, -1, 5}, {5, -1, -15}, {-5, -1, -15}, grey);
    b.addSphere({0.3f, 0.0f, -3.0f}, 0.8f, 24, 12, grey);
    const scene::Camera camera = makeCamera();
    getPass().setScene(b.getScene());
    const scene::GBuffer own = getPass().render(camera, 29, 17);
    const gpu::RenderTarget target =
        getContext().createRenderTarget(GBufferPass::makeTargetDesc(29, 17));
    getPass().draw(target, camera);
    EXPECT_EQ(&getPass().getTarget(), &target);
    EXPECT_TRUE(isBitwiseEqual(own, getPass().readBack()));
    // A render target of another kind is refused.
    gpu::RenderTargetDesc other;
    other.width = 29;
    other.height = 17;
    other.colors.push_back({});
    const gpu::RenderTarget wrong = getContext().createRenderTarget(other);
    EXPECT_THROW(getPass().draw(wrong, camera), Error);
    EXPECT_THROW(GBufferPass::makeTargetDesc(0, 4), Error);
}

TEST_F(GBufferPassTest, EmptySceneIsAllSky)
{
    getPass().setScene(scene::RenderScene{});
    const scene::GBuffer g = getPass().render(makeCamera(), 9, 7);
    for (int y = 0; y < 7; ++y)
        for (int x = 0; x < 9; ++x)
            expectSky(g, x, y);
}

TEST_F(GBufferPassTest, MisuseIsReported)
{
    EXPECT_FALSE(getPass().hasScene());
    EXPECT_THROW(getPass().draw(makeCamera(), 4, 4), Error);
    EXPECT_THROW(getPass().readBack(), Error);
    scene::RenderScene bad;
    bad.positions = {{0, 0, 0}};
    EXPECT_THROW(getPass().setScene(bad), Error); // no normal for the position
    getPass().setScene(scene::RenderScene{});
    EXPECT_THROW(getPass().draw(makeCamera(), 0, 4), Error);
}

TEST_F(GBufferPassTest, DrawHasAPositiveFiniteGpuTime)
{
    if (!getContext().hasGpuTimestamps())
        GTEST_SKIP() << "the device has no timestamps";
    SceneBuilder b;
    const std::uint32_t m = b.addMaterial({0.5f, 0.5f, 0.5f});
    b.addSphere({0.0f, 0.0f, -3.0f}, 1.0f, 32, 16, m);
    getPass().setScene(b.getScene());
    const gpu::RunResult run = getPass().draw(makeCamera(), 96, 64);
    ASSERT_EQ(run.commands.size(), 1u);
    EXPECT_EQ(run.commands[0].label, GBufferPass::kDrawLabel);
    const std::optional<double> ms = getPass().getLastGpuMs();
    ASSERT_TRUE(ms.has_value());
    EXPECT_GT(*ms, 0.0);
    EXPECT_TRUE(std::isfinite(*ms));
    EXPECT_EQ(ms, run.sumGpuMs(GBufferPass::kDrawLabel));
}

} // namespace
} // namespace rtlab::render::test
