#include "reference/primary_rays.h"

#include "core/error.h"
#include "reference/embree_scene.h"
#include "reference/integrators.h"
#include "reference/reference.h"

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

namespace rtlab::reference {

CameraRays::CameraRays(const scene::GBuffer& gbuffer)
    : mClipToWorld(glm::inverse(glm::dmat4(gbuffer.projection) * glm::dmat4(gbuffer.view))),
      mWidth(std::max(1, gbuffer.width)), mHeight(std::max(1, gbuffer.height))
{
}

glm::dvec3 CameraRays::unproject(int x, int y, double depth) const
{
    // Vulkan conventions: NDC y points down (row 0 at the top), depth 0 at the near plane.
    const double ndcX = 2.0 * (double(x) + 0.5) / double(mWidth) - 1.0;
    const double ndcY = 2.0 * (double(y) + 0.5) / double(mHeight) - 1.0;
    const glm::dvec4 p = mClipToWorld * glm::dvec4(ndcX, ndcY, depth, 1.0);
    return glm::dvec3(p) / p.w;
}

glm::dvec3 CameraRays::getOrigin(int x, int y) const
{
    return unproject(x, y, 0.0);
}

glm::dvec3 CameraRays::getDirection(int x, int y) const
{
    const glm::dvec3 d = unproject(x, y, 1.0) - unproject(x, y, 0.0);
    const double length = glm::length(d);
    return length > 0.0 && std::isfinite(length) ? d / length : glm::dvec3(0.0, 0.0, -1.0);
}

scene::GBuffer castGBuffer(const scene::RenderScene& scene, const scene::Camera& camera, int width,
                           int height, glm::vec2 jitter)
{
    if (width <= 0 || height <= 0)
        throw Error("reference: cannot cast a G-buffer of " + std::to_string(width) + "x" +
                    std::to_string(height) + " pixels");
    scene::GBuffer g;
    g.width = width;
    g.height = height;
    g.camera = camera;
    g.jitter = jitter;
    g.view = camera.viewMatrix();
    g.projection =
        camera.projectionMatrix(float(width) / float(height), jitter, glm::ivec2(width, height));
    g.depth = Image<float>(width, height, std::numeric_limits<float>::infinity());
    g.position = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.normal = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.albedo = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.emission = Image<glm::vec3>(width, height, glm::vec3(0.0f));
    g.materialId = Image<std::uint32_t>(width, height, scene::kNoMaterial);

    const EmbreeScene embree(scene);
    const SceneLights lights(scene);
    const CameraRays rays(g);
    const glm::dmat4 view(g.view);
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y) {
            for (int x = 0; x < width; ++x) {
                const glm::dvec3 origin = rays.getOrigin(x, y);
                const glm::dvec3 dir = rays.getDirection(x, y);
                // From the near plane to the far plane along this ray.
                const double farDistance =
                    glm::length(origin - glm::dvec3(camera.position)) *
                    (double(camera.farPlane) / double(camera.nearPlane) - 1.0);
                RayHit hit;
                if (!embree.intersect(glm::vec3(origin), glm::vec3(dir), float(farDistance), hit))
                    continue;
                const glm::dvec3 p = lights.getPoint(hit.triangle, hit.u, hit.v);
                glm::dvec3 ng = glm::normalize(glm::dvec3(hit.geometricNormal));
                if (glm::dot(ng, dir) > 0.0)
                    ng = -ng;
                glm::dvec3 ns = lights.getShadingNormal(hit.triangle, hit.u, hit.v, ng);
                if (glm::dot(ns, ng) < 0.0)
                    ns = -ns;
                const std::uint32_t material = scene.triangleMaterial[hit.triangle];
                g.depth.at(x, y) = float(-(view * glm::dvec4(p, 1.0)).z);
                g.position.at(x, y) = glm::vec3(p);
                g.normal.at(x, y) = glm::vec3(ns);
                g.albedo.at(x, y) = scene.materials[material].albedo;
                g.emission.at(x, y) = scene.materials[material].emission;
                g.materialId.at(x, y) = material;
            }
        }
    });
    return g;
}

} // namespace rtlab::reference
