#pragma once
// Test support of bentcone_ssdo: numerical cap intersection, and analytic G-buffers: camera rays
// through the pixel samples (ScreenProjection, jitter included) intersected in double precision
// with planes and boxes.

#include "core/image.h"
#include "scene/camera.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <functional>
#include <optional>

namespace rtlab::bentcone_ssdo::test {

//! Solid angle of cap(A, a) n cap(B, b) with axes d apart, by integration over the rings around
//! A: the ring at polar angle theta lies in B where cos(theta) cos(d) + sin(theta) sin(d) cos(phi)
//! >= cos(b), a fraction acos(x) / pi of its azimuths. Midpoint rule in theta on the pieces
//! between |b - d| and b + d, where rings start and stop touching B; inside the pieces the
//! integrand is smooth up to square-root ends, so the error is O(h^1.5), below 1e-6 sr with
//! 20000 steps per piece. Independent of intersectCaps.
double integrateCapIntersection(double d, double a, double b);

//! A ray hit in world space.
struct Hit {
    double t = 0.0;
    glm::dvec3 normal{0.0};
};

//! Nearest hit of the ray origin + t * direction (t > 0), if any.
using TraceFunction = std::function<std::optional<Hit>(const glm::dvec3&, const glm::dvec3&)>;

struct TestGBuffer {
    Image<float> depth;      //!< linear view depth, inf where the ray hits nothing
    Image<glm::vec3> normal; //!< view space, facing the camera, zero where nothing is hit
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
};

//! Renders `trace` seen by `camera` into a w x h G-buffer with sub-pixel `jitter`.
TestGBuffer renderGBuffer(const scene::Camera& camera, int width, int height,
                          const TraceFunction& trace, glm::vec2 jitter = glm::vec2(0.0f));

//! Hit of the plane through `point` with normal `normal`, if t > 0.
std::optional<Hit> intersectPlane(const glm::dvec3& origin, const glm::dvec3& direction,
                                  const glm::dvec3& point, const glm::dvec3& normal);

//! Hit of the axis-aligned box [lo, hi] from outside, if t > 0.
std::optional<Hit> intersectBox(const glm::dvec3& origin, const glm::dvec3& direction,
                                const glm::dvec3& lo, const glm::dvec3& hi);

//! The nearer of two optional hits.
std::optional<Hit> pickNearer(const std::optional<Hit>& a, const std::optional<Hit>& b);

//! Floor y = 0 (where z > -wallDistance) and a wall z = -wallDistance (where y >= 0), infinite in
//! x, seen by a camera at (0, eyeHeight, 0) looking along -z: the wall faces the camera, so the
//! depth difference behind it is the distance behind it, and every floor row has one distance
//! to the wall.
struct CreaseScene {
    double wallDistance = 4.0;
    double eyeHeight = 1.5;
    scene::Camera camera() const;
    TraceFunction trace() const;
};

//! A floor y = 0 with a unit box [-0.5, 0.5] x [0, 1] x [-0.5, 0.5] on it and a thin pole,
//! seen from above at an angle.
TraceFunction makeBoxSceneTrace();
scene::Camera makeBoxSceneCamera();

} // namespace rtlab::bentcone_ssdo::test
