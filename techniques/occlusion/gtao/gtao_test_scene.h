#pragma once
// Analytic G-buffers for the GTAO tests: camera rays through the pixel samples (jitter included)
// intersected exactly with a floor, an optional infinite vertical wall and optional boxes.

#include "core/image.h"
#include "families/occlusion/occlusion.h"
#include "plugin/screen_space.h"
#include "scene/camera.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace rtlab::occlusion::test {

struct Box {
    glm::vec3 lo{0.0f};
    glm::vec3 hi{1.0f};
};

//! World: y up. The floor is the plane y = floorY; the wall the plane x = wallX above the floor,
//! facing -x; boxes are axis-aligned. Everything is opaque and seen from the camera.
struct AnalyticScene {
    std::optional<float> floorY = 0.0f;
    std::optional<float> wallX;
    std::vector<Box> boxes;

    //! Nearest hit along origin + t dir (t > 0): t and the world normal.
    bool intersect(const glm::dvec3& origin, const glm::dvec3& dir, double& t,
                   glm::dvec3& normal) const
    {
        t = std::numeric_limits<double>::infinity();
        if (floorY && dir.y != 0.0) {
            const double s = (double(*floorY) - origin.y) / dir.y;
            if (s > 0.0 && s < t) {
                t = s;
                normal = {0.0, 1.0, 0.0};
            }
        }
        if (wallX && dir.x != 0.0) {
            const double s = (double(*wallX) - origin.x) / dir.x;
            const double y = origin.y + s * dir.y;
            if (s > 0.0 && s < t && (!floorY || y >= double(*floorY))) {
                t = s;
                normal = {-1.0, 0.0, 0.0};
            }
        }
        for (const Box& box : boxes) {
            double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
            int axis = -1;
            bool hit = true;
            for (int a = 0; a < 3 && hit; ++a) {
                if (dir[a] == 0.0) {
                    hit = origin[a] >= box.lo[a] && origin[a] <= box.hi[a];
                    continue;
                }
                double n = (double(box.lo[a]) - origin[a]) / dir[a];
                double f = (double(box.hi[a]) - origin[a]) / dir[a];
                if (n > f)
                    std::swap(n, f);
                if (n > t0) {
                    t0 = n;
                    axis = a;
                }
                t1 = std::min(t1, f);
                hit = t0 <= t1;
            }
            if (hit && axis >= 0 && t0 > 0.0 && t0 < t) {
                t = t0;
                normal = glm::dvec3(0.0);
                normal[axis] = dir[axis] > 0.0 ? -1.0 : 1.0;
            }
        }
        return std::isfinite(t);
    }
};

//! A G-buffer as the occlusion family receives it, with the world-space hit of each pixel.
struct TestGBuffer {
    Image<float> depth;
    Image<glm::vec3> normal;
    Image<glm::dvec3> worldPosition; //!< NaN where there is no surface
    glm::mat4 projection{1.0f};
    glm::mat4 view{1.0f};

    plugin::OcclusionInput makeInput(int frameIndex = 0) const
    {
        plugin::OcclusionInput input;
        input.linearDepth = &depth;
        input.normal = &normal;
        input.projection = projection;
        input.view = view;
        input.frameIndex = frameIndex;
        return input;
    }
};

//! Ray-casts `scene` through the pixel samples of a width x height image (jitter in pixels).
inline TestGBuffer renderScene(const AnalyticScene& scene, const scene::Camera& camera, int width,
                               int height, glm::vec2 jitter = glm::vec2(0.0f))
{
    TestGBuffer g;
    g.view = camera.viewMatrix();
    g.projection =
        camera.projectionMatrix(float(width) / float(height), jitter, glm::ivec2(width, height));
    g.depth = Image<float>(width, height, std::numeric_limits<float>::infinity());
    g.normal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.worldPosition =
        Image<glm::dvec3>(width, height, glm::dvec3(std::numeric_limits<double>::quiet_NaN()));
    const auto projection = plugin::ScreenProjection::fromMatrix(g.projection, width, height);
    const glm::dmat3 viewToWorld = glm::inverse(glm::dmat3(glm::mat3(g.view)));
    const glm::dmat3 worldToView = glm::dmat3(glm::mat3(g.view));
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            // The view-space point at depth 1 through the pixel sample: depth = ray parameter.
            const glm::vec3 unit = projection.toView(glm::vec2(x, y) + 0.5f, 1.0f);
            const glm::dvec3 dir = viewToWorld * glm::dvec3(unit);
            double t = 0.0;
            glm::dvec3 normal(0.0);
            if (!scene.intersect(glm::dvec3(camera.position), dir, t, normal))
                continue;
            glm::dvec3 n = worldToView * normal;
            if (glm::dot(n, -glm::dvec3(unit)) < 0.0)
                n = -n; // facing the camera
            g.depth.at(x, y) = float(t);
            g.normal.at(x, y) = glm::vec3(glm::normalize(n));
            g.worldPosition.at(x, y) = glm::dvec3(camera.position) + t * dir;
        }
    }
    return g;
}

} // namespace rtlab::occlusion::test
