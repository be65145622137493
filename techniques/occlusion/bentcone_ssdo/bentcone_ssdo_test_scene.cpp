#include "bentcone_ssdo_test_scene.h"

#include "plugin/screen_space.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace rtlab::bentcone_ssdo::test {

double integrateCapIntersection(double d, double a, double b)
{
    constexpr double kPi = 3.14159265358979323846;
    // The ring at polar angle theta (about A) lies in B where
    // cos(theta) cos(d) + sin(theta) sin(d) cos(phi) >= cos(b): a fraction acos(x) / pi of it.
    auto fraction = [&](double theta) {
        const double denominator = std::sin(theta) * std::sin(d);
        if (denominator < 1e-300)
            return std::cos(theta) * std::cos(d) >= std::cos(b) ? 1.0 : 0.0;
        const double x = (std::cos(b) - std::cos(theta) * std::cos(d)) / denominator;
        return x <= -1.0 ? 1.0 : (x >= 1.0 ? 0.0 : std::acos(x) / kPi);
    };
    // Pieces between the breakpoints |b - d| and b + d, where rings start and stop touching B.
    std::vector<double> cuts = {0.0, a};
    for (double cut : {std::abs(b - d), b + d})
        if (cut > 0.0 && cut < a)
            cuts.push_back(cut);
    std::sort(cuts.begin(), cuts.end());
    constexpr int kSteps = 20000;
    double sum = 0.0;
    for (std::size_t p = 0; p + 1 < cuts.size(); ++p) {
        const double h = (cuts[p + 1] - cuts[p]) / kSteps;
        for (int i = 0; i < kSteps; ++i) {
            const double theta = cuts[p] + (i + 0.5) * h;
            sum += 2.0 * kPi * std::sin(theta) * fraction(theta) * h;
        }
    }
    return sum;
}

TestGBuffer renderGBuffer(const scene::Camera& camera, int width, int height,
                          const TraceFunction& trace, glm::vec2 jitter)
{
    TestGBuffer g;
    g.view = camera.viewMatrix();
    g.projection =
        camera.projectionMatrix(float(width) / float(height), jitter, glm::ivec2(width, height));
    g.depth = Image<float>(width, height, std::numeric_limits<float>::infinity());
    g.normal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    const auto projection = plugin::ScreenProjection::fromMatrix(g.projection, width, height);
    const glm::dmat4 view(g.view);
    const glm::dmat3 viewRotation(view);
    const glm::dmat3 toWorld = glm::transpose(viewRotation); // camera matrices are rigid
    const glm::dvec3 origin(camera.position);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const glm::dvec3 viewPoint(
                projection.toView(glm::vec2(float(x) + 0.5f, float(y) + 0.5f), 1.0f));
            const glm::dvec3 direction = glm::normalize(toWorld * viewPoint);
            const std::optional<Hit> hit = trace(origin, direction);
            if (!hit)
                continue;
            const glm::dvec3 world = origin + hit->t * direction;
            const glm::dvec3 inView = glm::dvec3(view * glm::dvec4(world, 1.0));
            glm::dvec3 n = glm::normalize(viewRotation * hit->normal);
            if (glm::dot(n, inView) > 0.0)
                n = -n; // face the camera
            g.depth.at(x, y) = float(-inView.z);
            g.normal.at(x, y) = glm::vec3(n);
        }
    }
    return g;
}

std::optional<Hit> intersectPlane(const glm::dvec3& origin, const glm::dvec3& direction,
                                  const glm::dvec3& point, const glm::dvec3& normal)
{
    const double denominator = glm::dot(direction, normal);
    if (std::abs(denominator) < 1e-15)
        return std::nullopt;
    const double t = glm::dot(point - origin, normal) / denominator;
    if (!(t > 0.0))
        return std::nullopt;
    return Hit{t, normal};
}

std::optional<Hit> intersectBox(const glm::dvec3& origin, const glm::dvec3& direction,
                                const glm::dvec3& lo, const glm::dvec3& hi)
{
    double tNear = -std::numeric_limits<double>::infinity();
    double tFar = std::numeric_limits<double>::infinity();
    int axis = -1;
    for (int i = 0; i < 3; ++i) {
        if (std::abs(direction[i]) < 1e-15) {
            if (origin[i] < lo[i] || origin[i] > hi[i])
                return std::nullopt;
            continue;
        }
        double t0 = (lo[i] - origin[i]) / direction[i];
        double t1 = (hi[i] - origin[i]) / direction[i];
        if (t0 > t1)
            std::swap(t0, t1);
        if (t0 > tNear) {
            tNear = t0;
            axis = i;
        }
        tFar = std::min(tFar, t1);
    }
    if (axis < 0 || tNear > tFar || !(tNear > 0.0))
        return std::nullopt;
    glm::dvec3 n(0.0);
    n[axis] = direction[axis] > 0.0 ? -1.0 : 1.0;
    return Hit{tNear, n};
}

std::optional<Hit> pickNearer(const std::optional<Hit>& a, const std::optional<Hit>& b)
{
    if (!a)
        return b;
    if (!b)
        return a;
    return a->t <= b->t ? a : b;
}

scene::Camera CreaseScene::camera() const
{
    scene::Camera c;
    c.position = glm::vec3(0.0f, float(eyeHeight), 0.0f);
    c.target = glm::vec3(0.0f, float(eyeHeight), -1.0f);
    c.up = glm::vec3(0.0f, 1.0f, 0.0f);
    c.verticalFovDegrees = 60.0f;
    return c;
}

TraceFunction CreaseScene::trace() const
{
    const double wall = wallDistance;
    return [wall](const glm::dvec3& o, const glm::dvec3& d) -> std::optional<Hit> {
        std::optional<Hit> floor = intersectPlane(o, d, glm::dvec3(0.0), glm::dvec3(0, 1, 0));
        if (floor && (o + floor->t * d).z <= -wall)
            floor.reset();
        std::optional<Hit> front =
            intersectPlane(o, d, glm::dvec3(0.0, 0.0, -wall), glm::dvec3(0, 0, 1));
        if (front && (o + front->t * d).y < 0.0)
            front.reset();
        return pickNearer(floor, front);
    };
}

TraceFunction makeBoxSceneTrace()
{
    return [](const glm::dvec3& o, const glm::dvec3& d) -> std::optional<Hit> {
        std::optional<Hit> hit = intersectPlane(o, d, glm::dvec3(0.0), glm::dvec3(0, 1, 0));
        hit = pickNearer(
            hit, intersectBox(o, d, glm::dvec3(-0.5, 0.0, -0.5), glm::dvec3(0.5, 1.0, 0.5)));
        hit = pickNearer(
            hit, intersectBox(o, d, glm::dvec3(0.9, 0.0, 0.2), glm::dvec3(0.96, 1.4, 0.26)));
        return hit;
    };
}

scene::Camera makeBoxSceneCamera()
{
    scene::Camera c;
    c.position = glm::vec3(2.2f, 1.7f, 2.6f);
    c.target = glm::vec3(0.0f, 0.35f, 0.0f);
    c.verticalFovDegrees = 50.0f;
    return c;
}

} // namespace rtlab::bentcone_ssdo::test
