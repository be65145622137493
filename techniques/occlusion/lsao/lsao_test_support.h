#pragma once
// Test support for lsao: construction with parameter overrides, and analytic G-buffers: a pinhole
// camera (scene::Camera, optional jitter) looks at boxes and an infinite floor; every pixel
// centre's ray is intersected exactly, so depth and normals are those of the geometry the
// rasteriser would produce at the pixel samples.

#include "lsao.h"

#include "core/image.h"
#include "families/occlusion/occlusion.h"
#include "plugin/screen_space.h"
#include "scene/camera.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace rtlab::occlusion::lsao::test {

using Overrides = std::map<std::string, config::ParamValue>;

inline Lsao makeLsao(const Overrides& overrides = {})
{
    config::ParamSet params = config::ParamSet::defaultsOf(Lsao::declareParams());
    for (const auto& [name, value] : overrides)
        params.set(name, value);
    return Lsao(params);
}

struct Box {
    glm::vec3 lo;
    glm::vec3 hi;
};

struct SceneDesc {
    scene::Camera camera;
    glm::vec2 jitter{0.0f};
    bool floor = true; //!< the plane y = 0, normal +y
    std::vector<Box> boxes;
};

struct GBuffer {
    Image<float> depth;
    Image<glm::vec3> normal;
    glm::mat4 projection{1.0f};
    glm::mat4 view{1.0f};
    plugin::ScreenProjection screen;

    plugin::OcclusionInput makeInput(int frameIndex = 0, gpu::Context* gpu = nullptr) const
    {
        plugin::OcclusionInput input;
        input.linearDepth = &depth;
        input.normal = &normal;
        input.projection = projection;
        input.view = view;
        input.frameIndex = frameIndex;
        input.gpu = gpu;
        return input;
    }
    //! World position of the surface point of pixel (x, y).
    glm::vec3 getWorldPoint(int x, int y) const
    {
        const glm::vec3 v =
            screen.toView(glm::vec2(float(x) + 0.5f, float(y) + 0.5f), depth.at(x, y));
        return glm::vec3(glm::inverse(view) * glm::vec4(v, 1.0f));
    }
};

//! Slab intersection; returns the entry distance and the face normal, or inf.
inline float intersectBox(const Box& b, glm::vec3 o, glm::vec3 d, glm::vec3& normal)
{
    float tNear = -std::numeric_limits<float>::infinity();
    float tFar = std::numeric_limits<float>::infinity();
    int axis = -1;
    float sign = 0.0f;
    for (int a = 0; a < 3; ++a) {
        if (std::fabs(d[a]) < 1e-12f) {
            if (o[a] < b.lo[a] || o[a] > b.hi[a])
                return std::numeric_limits<float>::infinity();
            continue;
        }
        float t0 = (b.lo[a] - o[a]) / d[a];
        float t1 = (b.hi[a] - o[a]) / d[a];
        float s = -1.0f;
        if (t0 > t1) {
            std::swap(t0, t1);
            s = 1.0f;
        }
        if (t0 > tNear) {
            tNear = t0;
            axis = a;
            sign = s;
        }
        tFar = std::min(tFar, t1);
    }
    if (axis < 0 || tNear > tFar || tNear <= 0.0f)
        return std::numeric_limits<float>::infinity();
    normal = glm::vec3(0.0f);
    normal[axis] = sign;
    return tNear;
}

inline GBuffer renderScene(const SceneDesc& s, int width, int height)
{
    GBuffer g;
    g.view = s.camera.viewMatrix();
    g.projection = s.camera.projectionMatrix(float(width) / float(height), s.jitter,
                                             glm::ivec2(width, height));
    g.screen = plugin::ScreenProjection::fromMatrix(g.projection, width, height);
    g.depth = Image<float>(width, height, std::numeric_limits<float>::infinity());
    g.normal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    const glm::mat3 viewToWorld = glm::transpose(glm::mat3(g.view));
    const glm::mat3 worldToView = glm::mat3(g.view);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            // View-space direction with z = -1: the ray parameter is the linear depth.
            const glm::vec3 dv = g.screen.toView(glm::vec2(float(x) + 0.5f, float(y) + 0.5f), 1.0f);
            const glm::vec3 d = viewToWorld * dv;
            const glm::vec3 o = s.camera.position;
            float best = std::numeric_limits<float>::infinity();
            glm::vec3 n(0.0f);
            if (s.floor && d.y < 0.0f) {
                best = -o.y / d.y;
                n = glm::vec3(0.0f, 1.0f, 0.0f);
            }
            for (const Box& b : s.boxes) {
                glm::vec3 bn;
                const float t = intersectBox(b, o, d, bn);
                if (t < best) {
                    best = t;
                    n = bn;
                }
            }
            if (!(best < std::numeric_limits<float>::infinity()))
                continue;
            glm::vec3 nv = worldToView * n;
            if (glm::dot(nv, dv) > 0.0f)
                nv = -nv;
            g.depth.at(x, y) = best;
            g.normal.at(x, y) = glm::normalize(nv);
        }
    }
    return g;
}

//! A floor with a box on it, seen from above at an angle (the horizon and sky at the top).
inline SceneDesc makeFloorBoxScene()
{
    SceneDesc s;
    s.camera.position = glm::vec3(0.4f, 2.2f, 4.5f);
    s.camera.target = glm::vec3(0.0f, 0.2f, 0.0f);
    s.camera.verticalFovDegrees = 60.0f;
    s.jitter = glm::vec2(0.31f, -0.27f);
    s.boxes = {{glm::vec3(-0.6f, 0.0f, -0.5f), glm::vec3(0.5f, 0.9f, 0.4f)},
               {glm::vec3(1.0f, 0.0f, -1.6f), glm::vec3(1.3f, 2.0f, -1.3f)}};
    return s;
}

//! A floor in front of a long wall (front face z = 0, x in [-30, 30], y in [0, wallHeight]),
//! seen from above so that the wall's top edge (up to a height of 4.6) is on screen.
inline SceneDesc makeWallScene(float wallHeight)
{
    SceneDesc s;
    s.camera.position = glm::vec3(0.0f, 6.0f, 7.0f);
    s.camera.target = glm::vec3(0.0f, 0.5f, 0.0f);
    s.camera.verticalFovDegrees = 55.0f;
    s.boxes = {{glm::vec3(-30.0f, 0.0f, -0.3f), glm::vec3(30.0f, wallHeight, 0.0f)}};
    return s;
}

//! Form factor from a differential area at `x` with unit normal `n` to the polygon `poly`
//! (Lambert's formula; the polygon must lie above the tangent plane of x).
inline double computePolygonFormFactor(glm::dvec3 x, glm::dvec3 n,
                                       const std::vector<glm::dvec3>& poly)
{
    double sum = 0.0;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec3 a = glm::normalize(poly[i] - x);
        const glm::dvec3 b = glm::normalize(poly[(i + 1) % poly.size()] - x);
        const glm::dvec3 c = glm::cross(a, b);
        const double len = glm::length(c);
        if (len < 1e-15)
            continue;
        sum += std::atan2(len, glm::dot(a, b)) * glm::dot(n, c / len);
    }
    return std::fabs(sum) / (2.0 * 3.14159265358979323846);
}

//! Sutherland-Hodgman: the part of `poly` on the side dot(p - origin, normal) >= 0.
inline std::vector<glm::dvec3> clipPolygon(const std::vector<glm::dvec3>& poly, glm::dvec3 origin,
                                           glm::dvec3 normal)
{
    std::vector<glm::dvec3> out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec3 a = poly[i], b = poly[(i + 1) % poly.size()];
        const double da = glm::dot(a - origin, normal), db = glm::dot(b - origin, normal);
        if (da >= 0.0)
            out.push_back(a);
        if ((da >= 0.0) != (db >= 0.0))
            out.push_back(a + (b - a) * (da / (da - db)));
    }
    return out;
}

//! The part of the world-space polygon `poly` inside the view frustum of `g` (side planes).
inline std::vector<glm::dvec3> clipToFrustum(const GBuffer& g, const scene::Camera& camera,
                                             std::vector<glm::dvec3> poly)
{
    const glm::dmat3 viewToWorld = glm::transpose(glm::dmat3(glm::mat3(g.view)));
    const float w = g.screen.size.x, h = g.screen.size.y;
    const glm::vec2 corners[4] = {{0.0f, 0.0f}, {w, 0.0f}, {w, h}, {0.0f, h}};
    glm::dvec3 rays[4];
    for (int i = 0; i < 4; ++i)
        rays[i] = viewToWorld * glm::dvec3(g.screen.toView(corners[i], 1.0f));
    const glm::dvec3 o(camera.position);
    const glm::dvec3 centre = (rays[0] + rays[1] + rays[2] + rays[3]) * 0.25;
    for (int i = 0; i < 4; ++i) {
        glm::dvec3 normal = glm::cross(rays[i], rays[(i + 1) % 4]);
        if (glm::dot(normal, centre) < 0.0)
            normal = -normal;
        poly = clipPolygon(poly, o, normal);
    }
    return poly;
}

//! Cosine-weighted visible fraction A and unnormalised bent vector (3 / 2pi) Int V w cos dw (= n
//! when nothing is occluded) of a floor receiver `x` (normal +y, x.z > 0) whose only occluder is
//! the convex polygon `poly` in the plane z = 0: midpoint quadrature over (theta, phi).
inline std::pair<double, glm::dvec3> integrateFloorVisibility(glm::dvec3 x,
                                                              const std::vector<glm::dvec3>& poly,
                                                              int thetaSteps = 256,
                                                              int phiSteps = 1024)
{
    const double pi = 3.14159265358979323846;
    const double dTheta = 0.5 * pi / thetaSteps, dPhi = 2.0 * pi / phiSteps;
    double visible = 0.0;
    glm::dvec3 bent(0.0);
    for (int i = 0; i < thetaSteps; ++i) {
        const double theta = (i + 0.5) * dTheta;
        const double weight = std::cos(theta) * std::sin(theta) * dTheta * dPhi;
        for (int j = 0; j < phiSteps; ++j) {
            const double phi = (j + 0.5) * dPhi;
            const glm::dvec3 w(std::sin(theta) * std::cos(phi), std::cos(theta),
                               std::sin(theta) * std::sin(phi));
            bool blocked = false;
            if (w.z < 0.0) {
                const glm::dvec3 hit = x + w * (-x.z / w.z);
                // Inside the convex polygon: the same side of every edge (in the plane z = 0).
                int sign = 0;
                blocked = true;
                for (std::size_t k = 0; k < poly.size() && blocked; ++k) {
                    const glm::dvec3 a = poly[k], b = poly[(k + 1) % poly.size()];
                    const double cross = (b.x - a.x) * (hit.y - a.y) - (b.y - a.y) * (hit.x - a.x);
                    const int s = cross > 0.0 ? 1 : -1;
                    blocked = sign == 0 || s == sign;
                    sign = s;
                }
            }
            if (!blocked) {
                visible += weight;
                bent += weight * w;
            }
        }
    }
    return {visible / pi, bent * (3.0 / (2.0 * pi))};
}

} // namespace rtlab::occlusion::lsao::test
