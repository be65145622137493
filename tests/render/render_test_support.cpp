#include "render_test_support.h"

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include <cmath>
#include <cstdlib>
#include <limits>

namespace rtlab::render::test {

std::filesystem::path getRenderTestShaderDir()
{
    if (const char* root = std::getenv("RTLAB_SOURCE_DIR"); root != nullptr && *root != '\0')
        return std::filesystem::path(root) / "tests" / "render" / "shaders";
    return std::filesystem::path(RTLAB_RENDER_TEST_SHADER_DIR);
}

std::uint32_t SceneBuilder::addMaterial(glm::vec3 albedo, glm::vec3 emission)
{
    scene::Material m;
    m.name = "material" + std::to_string(mScene.materials.size());
    m.albedo = albedo;
    m.emission = emission;
    mScene.materials.push_back(m);
    return static_cast<std::uint32_t>(mScene.materials.size() - 1);
}

std::uint32_t SceneBuilder::addVertex(glm::vec3 position, glm::vec3 normal)
{
    mScene.positions.push_back(position);
    mScene.normals.push_back(normal);
    return static_cast<std::uint32_t>(mScene.positions.size() - 1);
}

void SceneBuilder::addTriangle(std::uint32_t a, std::uint32_t b, std::uint32_t c,
                               std::uint32_t material)
{
    mScene.indices.insert(mScene.indices.end(), {a, b, c});
    mScene.triangleMaterial.push_back(material);
    mTriangleObject.push_back(mObject);
}

void SceneBuilder::addQuad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d,
                           std::uint32_t material, std::optional<std::uint32_t> secondMaterial)
{
    ++mObject;
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const std::uint32_t ia = addVertex(a, n), ib = addVertex(b, n), ic = addVertex(c, n),
                        id = addVertex(d, n);
    addTriangle(ia, ib, ic, material);
    addTriangle(ia, ic, id, secondMaterial.value_or(material));
    mScene.updateBounds();
}

void SceneBuilder::addBox(glm::vec3 center, glm::vec3 halfExtents, float yawRadians,
                          std::uint32_t material)
{
    ++mObject;
    const float c = std::cos(yawRadians), s = std::sin(yawRadians);
    auto rotate = [&](glm::vec3 p) {
        return glm::vec3(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);
    };
    // Each face: outward axis, and two in-plane axes with u x v = axis (counter-clockwise).
    const glm::vec3 axes[6][3] = {
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
        {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
        {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {-1, 0, 0}, {0, 1, 0}},
    };
    for (const auto& face : axes) {
        const glm::vec3 n = face[0], u = face[1], v = face[2];
        const glm::vec3 h = halfExtents;
        auto corner = [&](float su, float sv) {
            return center + rotate(n * h + su * u * h + sv * v * h);
        };
        const glm::vec3 rn = rotate(n);
        const std::uint32_t a = addVertex(corner(-1, -1), rn), b = addVertex(corner(1, -1), rn),
                            cc = addVertex(corner(1, 1), rn), d = addVertex(corner(-1, 1), rn);
        addTriangle(a, b, cc, material);
        addTriangle(a, cc, d, material);
    }
    mScene.updateBounds();
}

void SceneBuilder::addSphere(glm::vec3 center, float radius, int segments, int rings,
                             std::uint32_t material)
{
    ++mObject;
    const auto first = static_cast<std::uint32_t>(mScene.positions.size());
    const double pi = std::acos(-1.0);
    for (int r = 0; r <= rings; ++r) {
        const double theta = pi * r / rings; // from +y
        for (int s = 0; s <= segments; ++s) {
            const double phi = 2.0 * pi * s / segments;
            const glm::vec3 n(static_cast<float>(std::sin(theta) * std::cos(phi)),
                              static_cast<float>(std::cos(theta)),
                              static_cast<float>(-std::sin(theta) * std::sin(phi)));
            addVertex(center + radius * n, n);
        }
    }
    auto at = [&](int r, int s) {
        return first + static_cast<std::uint32_t>(r * (segments + 1) + s);
    };
    for (int r = 0; r < rings; ++r) {
        for (int s = 0; s < segments; ++s) {
            // Counter-clockwise seen from outside: phi grows counter-clockwise about +y.
            if (r > 0)
                addTriangle(at(r, s), at(r + 1, s), at(r, s + 1), material);
            if (r + 1 < rings)
                addTriangle(at(r, s + 1), at(r + 1, s), at(r + 1, s + 1), material);
        }
    }
    mScene.updateBounds();
}

void SceneBuilder::addCheckerGrid(glm::vec3 corner, glm::vec3 u, glm::vec3 v, int n,
                                  std::uint32_t a, std::uint32_t b)
{
    ++mObject;
    const glm::vec3 normal = glm::normalize(glm::cross(u, v));
    const auto first = static_cast<std::uint32_t>(mScene.positions.size());
    for (int j = 0; j <= n; ++j) {
        for (int i = 0; i <= n; ++i)
            addVertex(corner + (float(i) / float(n)) * u + (float(j) / float(n)) * v, normal);
    }
    auto at = [&](int i, int j) { return first + static_cast<std::uint32_t>(j * (n + 1) + i); };
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            const bool even = (i + j) % 2 == 0;
            addTriangle(at(i, j), at(i + 1, j), at(i + 1, j + 1), even ? a : b);
            addTriangle(at(i, j), at(i + 1, j + 1), at(i, j + 1), even ? b : a);
        }
    }
    mScene.updateBounds();
}

glm::dvec3 computeReferenceRayDirection(const scene::Camera& camera, int width, int height,
                                        glm::dvec2 pixel)
{
    const glm::dvec3 forward =
        glm::normalize(glm::dvec3(camera.target) - glm::dvec3(camera.position));
    const glm::dvec3 right = glm::normalize(glm::cross(forward, glm::dvec3(camera.up)));
    const glm::dvec3 up = glm::cross(right, forward);
    const double tanHalf = std::tan(glm::radians(double(camera.verticalFovDegrees)) / 2.0);
    const double aspect = double(width) / double(height);
    const double ndcX = 2.0 * pixel.x / width - 1.0;
    const double ndcY = 2.0 * pixel.y / height - 1.0; // down
    return forward + ndcX * tanHalf * aspect * right - ndcY * tanHalf * up;
}

RayHit intersectScene(const scene::RenderScene& scene, glm::dvec3 origin, glm::dvec3 direction)
{
    RayHit best;
    best.t = std::numeric_limits<double>::infinity();
    for (std::size_t t = 0; t < scene.triangleCount(); ++t) {
        const glm::dvec3 p0(scene.positions[scene.indices[3 * t]]);
        const glm::dvec3 p1(scene.positions[scene.indices[3 * t + 1]]);
        const glm::dvec3 p2(scene.positions[scene.indices[3 * t + 2]]);
        const glm::dvec3 e1 = p1 - p0, e2 = p2 - p0;
        const glm::dvec3 pv = glm::cross(direction, e2);
        const double det = glm::dot(e1, pv);
        if (std::abs(det) < 1e-300)
            continue;
        const double inv = 1.0 / det;
        const glm::dvec3 tv = origin - p0;
        const double b1 = glm::dot(tv, pv) * inv;
        if (b1 < 0.0 || b1 > 1.0)
            continue;
        const glm::dvec3 qv = glm::cross(tv, e1);
        const double b2 = glm::dot(direction, qv) * inv;
        if (b2 < 0.0 || b1 + b2 > 1.0)
            continue;
        const double dist = glm::dot(e2, qv) * inv;
        if (dist > 0.0 && dist < best.t) {
            best.t = dist;
            best.triangle = static_cast<std::int64_t>(t);
            best.b1 = b1;
            best.b2 = b2;
        }
    }
    return best;
}

CpuSample castSample(const SceneBuilder& builder, const scene::Camera& camera, int width,
                     int height, glm::dvec2 pixel)
{
    const scene::RenderScene& scene = builder.getScene();
    const glm::dvec3 origin(camera.position);
    const glm::dvec3 forward = glm::normalize(glm::dvec3(camera.target) - origin);
    const glm::dvec3 dir = computeReferenceRayDirection(camera, width, height, pixel);
    const RayHit hit = intersectScene(scene, origin, dir);
    CpuSample s;
    if (hit.triangle < 0)
        return s;
    const double depth = hit.t * glm::dot(dir, forward);
    if (depth < camera.nearPlane || depth > camera.farPlane)
        return s;
    const auto t = static_cast<std::size_t>(hit.triangle);
    const std::uint32_t i0 = scene.indices[3 * t], i1 = scene.indices[3 * t + 1],
                        i2 = scene.indices[3 * t + 2];
    const double b0 = 1.0 - hit.b1 - hit.b2;
    glm::dvec3 n = b0 * glm::dvec3(scene.normals[i0]) + hit.b1 * glm::dvec3(scene.normals[i1]) +
                   hit.b2 * glm::dvec3(scene.normals[i2]);
    n = glm::normalize(n);
    const glm::dvec3 p0(scene.positions[i0]), p1(scene.positions[i1]), p2(scene.positions[i2]);
    if (glm::dot(glm::cross(p1 - p0, p2 - p0), dir) > 0.0) // seen from the back
        n = -n;
    s.hit = true;
    s.depth = depth;
    s.position = origin + hit.t * dir;
    s.normal = n;
    s.material = scene.triangleMaterial[t];
    s.object = builder.getTriangleObjects()[t];
    return s;
}

void RenderTest::SetUp()
{
    GpuTest::SetUp();
    if (HasFatalFailure())
        return;
    GBufferPassOptions options;
    options.compiler = getCompiler().getOptions();
    mPass.emplace(getContext(), options);
}

void RenderTest::TearDown()
{
    mPass.reset(); // before the context goes
    GpuTest::TearDown();
}

double RenderTest::getSnapPixels()
{
    const auto bits = getContext().getDeviceInfo().subPixelPrecisionBits;
    return std::ldexp(1.0, -static_cast<int>(bits));
}

} // namespace rtlab::render::test
