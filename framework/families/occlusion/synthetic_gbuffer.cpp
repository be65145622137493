#include "families/occlusion/synthetic_gbuffer.h"

#include "plugin/screen_space.h"
#include "reference/reference.h"
#include "scene/camera.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace rtlab::occlusion {

SyntheticGBuffer makeSyntheticGBuffer(int w, int h, float fovDegrees, const HitFunction& hit)
{
    scene::Camera camera;
    camera.position = {0, 0, 0};
    camera.target = {0, 0, -1};
    camera.verticalFovDegrees = fovDegrees;
    camera.nearPlane = 1e-3f;
    camera.farPlane = 1e6f;
    SyntheticGBuffer g;
    g.projection = camera.projectionMatrix(float(w) / float(h), glm::vec2(0.0f), {w, h});
    g.view = camera.viewMatrix();
    g.depth = Image<float>(w, h, std::numeric_limits<float>::infinity());
    g.normal = Image<glm::vec3>(w, h, glm::vec3(0.0f));
    const auto sp = plugin::ScreenProjection::fromMatrix(g.projection, w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::vec3 dir = glm::normalize(sp.toView({x + 0.5f, y + 0.5f}, 1.0f));
            const auto [t, n] = hit(dir);
            if (t > 0.0f && std::isfinite(t)) {
                g.depth.at(x, y) = -(dir * t).z;
                g.normal.at(x, y) = n;
            }
        }
    return g;
}

plugin::OcclusionInput makeOcclusionInput(const SyntheticGBuffer& g, gpu::Context* gpu)
{
    plugin::OcclusionInput in;
    in.linearDepth = &g.depth;
    in.normal = &g.normal;
    in.projection = g.projection;
    in.view = g.view;
    in.gpu = gpu;
    return in;
}

std::pair<float, glm::vec3> hitPlanes(const glm::vec3& direction, const std::vector<Plane>& planes)
{
    std::pair<float, glm::vec3> best{-1.0f, glm::vec3(0.0f)};
    for (const Plane& p : planes) {
        const double d = glm::dot(glm::dvec3(direction), p.normal);
        if (std::abs(d) < 1e-8)
            continue;
        const double t = glm::dot(p.point, p.normal) / d;
        if (!(t > 0.0) || !std::isfinite(t))
            continue;
        if (best.first <= 0.0f || t < best.first)
            best = {float(t), glm::vec3(d > 0.0 ? -p.normal : p.normal)};
    }
    return best;
}

SyntheticGBuffer makePlanesGBuffer(int w, int h, float fovDegrees, const std::vector<Plane>& planes)
{
    return makeSyntheticGBuffer(w, h, fovDegrees,
                                [&](const glm::vec3& d) { return hitPlanes(d, planes); });
}

std::vector<Plane> makeFloorAndWall()
{
    return {{{0, -1, 0}, {0, 1, 0}}, {{0, 0, -4}, {0, 0, 1}}};
}

namespace {

//! Shirley and Chiu's concentric map (1997) of [0, 1]^2 onto the unit disk: area-preserving, so
//! the midpoints of a k x k grid are equal-area samples of the disk.
glm::dvec2 mapConcentric(double u, double v)
{
    const double a = 2.0 * u - 1.0, b = 2.0 * v - 1.0;
    if (a == 0.0 && b == 0.0)
        return {0.0, 0.0};
    const double quarter = glm::quarter_pi<double>();
    if (std::abs(a) > std::abs(b))
        return {a * std::cos(quarter * b / a), a * std::sin(quarter * b / a)};
    return {b * std::cos(glm::half_pi<double>() - quarter * a / b),
            b * std::sin(glm::half_pi<double>() - quarter * a / b)};
}

} // namespace

Image<float> integrateOcclusion(const SyntheticGBuffer& g, const std::vector<Plane>& planes,
                                const plugin::OcclusionDefinition& definition, int k)
{
    const int w = g.depth.width, h = g.depth.height;
    const auto sp = plugin::ScreenProjection::fromMatrix(g.projection, w, h);
    Image<glm::vec3> positions(w, h, glm::vec3(0.0f));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (std::isfinite(g.depth.at(x, y)))
                positions.at(x, y) = sp.toView({x + 0.5f, y + 0.5f}, g.depth.at(x, y));
    return integrateOcclusion(positions, g.normal, planes, definition, k);
}

Image<float> integrateOcclusion(const Image<glm::vec3>& positions, const Image<glm::vec3>& normals,
                                const std::vector<Plane>& planes, const plugin::OcclusionDefinition& definition,
                                int k)
{
    const int w = positions.width, h = positions.height;
    Image<float> out(w, h, 1.0f);
    const bool uniform = definition.quantity == plugin::OcclusionQuantity::UniformAo;
    // The sample directions in the frame of the normal (z along it), the same for every pixel.
    std::vector<glm::dvec3> local;
    local.reserve(std::size_t(k) * k);
    for (int j = 0; j < k; ++j)
        for (int i = 0; i < k; ++i) {
            const double u = (i + 0.5) / k, v = (j + 0.5) / k;
            if (uniform) {
                // Uniform in solid angle: cos(theta) and phi uniform.
                const double z = u, r = std::sqrt(std::max(0.0, 1.0 - z * z));
                const double phi = glm::two_pi<double>() * v;
                local.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
            } else {
                // Malley: equal-area disk points lifted to the hemisphere are cosine-weighted.
                const glm::dvec2 d = mapConcentric(u, v);
                local.emplace_back(d.x, d.y, std::sqrt(std::max(0.0, 1.0 - glm::dot(d, d))));
            }
        }
    const double radius = definition.radius;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const glm::dvec3 n = normals.at(x, y);
            if (glm::dot(n, n) == 0.0)
                continue;
            const glm::dvec3 p = positions.at(x, y);
            // The frame around the normal.
            const glm::dvec3 nz = glm::normalize(n);
            const glm::dvec3 helper = std::abs(nz.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
            const glm::dvec3 tx = glm::normalize(glm::cross(helper, nz));
            const glm::dvec3 ty = glm::cross(nz, tx);
            // The plane the pixel lies on does not occlude it (its rays leave it).
            const double onPlane = 1e-4 * std::max(1.0, glm::length(p));
            double sum = 0.0;
            for (const glm::dvec3& l : local) {
                const glm::dvec3 dir = l.x * tx + l.y * ty + l.z * nz;
                double nearest = std::numeric_limits<double>::infinity();
                for (const Plane& plane : planes) {
                    const double offset = glm::dot(plane.point - p, plane.normal);
                    const double along = glm::dot(dir, plane.normal);
                    if (std::abs(offset) < onPlane || along == 0.0)
                        continue;
                    const double t = offset / along;
                    if (t > 0.0)
                        nearest = std::min(nearest, t);
                }
                switch (definition.quantity) {
                case plugin::OcclusionQuantity::CosineAo:
                case plugin::OcclusionQuantity::UniformAo:
                    sum += nearest < radius ? 0.0 : 1.0;
                    break;
                case plugin::OcclusionQuantity::Obscurance:
                    sum += radius > 0.0 ? reference::evaluateFalloff(definition.falloff == plugin::OcclusionFalloff::Linear
                                                                         ? reference::Falloff::Linear
                                                                         : reference::Falloff::Smoothstep,
                                                                     nearest / radius)
                                        : 1.0;
                    break;
                }
            }
            out.at(x, y) = float(sum / double(local.size()));
        }
    return out;
}

} // namespace rtlab::occlusion
