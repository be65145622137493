#include "reference/integrators.h"

#include "core/error.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <string>

namespace rtlab::reference {

namespace {

constexpr std::size_t kMaxPointLightsEvaluatedAll = 8;

bool isFiniteNonNegative(const glm::vec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) && v.x >= 0.0f &&
           v.y >= 0.0f && v.z >= 0.0f;
}

} // namespace

SceneLights::SceneLights(const scene::RenderScene& scene) : mScene(scene)
{
    const std::size_t triangles = scene.triangleCount();
    if (scene.triangleMaterial.size() != triangles)
        throw Error("reference: the scene has " + std::to_string(triangles) + " triangles but " +
                    std::to_string(scene.triangleMaterial.size()) + " triangle materials");
    if (!scene.normals.empty() && scene.normals.size() != scene.positions.size())
        throw Error("reference: the scene has " + std::to_string(scene.positions.size()) +
                    " positions but " + std::to_string(scene.normals.size()) + " normals");
    for (std::size_t m = 0; m < scene.materials.size(); ++m)
        if (!isFiniteNonNegative(scene.materials[m].albedo) ||
            !isFiniteNonNegative(scene.materials[m].emission))
            throw Error("reference: material " + std::to_string(m) + " ('" +
                        scene.materials[m].name +
                        "') has a negative or non-finite albedo or emission");
    for (std::size_t l = 0; l < scene.pointLights.size(); ++l)
        if (!isFiniteNonNegative(scene.pointLights[l].intensity))
            throw Error("reference: point light " + std::to_string(l) +
                        " has a negative or non-finite intensity");

    for (const scene::Material& m : scene.materials) {
        mMaterialAlbedo.push_back(glm::dvec3(m.albedo));
        mMaterialEmission.push_back(glm::dvec3(m.emission));
    }
    mNormal.resize(triangles);
    mEmitterSlot.assign(triangles, -1);
    std::vector<double> emitterWeights;
    for (std::size_t t = 0; t < triangles; ++t) {
        const std::uint32_t m = scene.triangleMaterial[t];
        if (m >= scene.materials.size())
            throw Error("reference: triangle " + std::to_string(t) + " uses material " +
                        std::to_string(m) + " but the scene has " +
                        std::to_string(scene.materials.size()) + " materials");
        const glm::dvec3 p0(scene.positions[scene.indices[3 * t + 0]]);
        const glm::dvec3 p1(scene.positions[scene.indices[3 * t + 1]]);
        const glm::dvec3 p2(scene.positions[scene.indices[3 * t + 2]]);
        const glm::dvec3 cross = glm::cross(p1 - p0, p2 - p0);
        const double area = 0.5 * glm::length(cross);
        mNormal[t] = area > 0.0 ? cross / (2.0 * area) : glm::dvec3(0.0);
        const double power = computeLuminance(mMaterialEmission[m]) * area;
        if (power > 0.0) {
            mEmitterSlot[t] = std::int32_t(emitterTriangles.size());
            emitterTriangles.push_back(std::uint32_t(t));
            emitterArea.push_back(area);
            emitterWeights.push_back(power);
        }
    }
    emitterPick = DiscreteDistribution(emitterWeights);
    pointLightPick = buildPointLightDistribution(scene.pointLights);
    evaluateAllPointLights = scene.pointLights.size() <= kMaxPointLightsEvaluatedAll;
    skyLobes = SkyLobeSampler(scene.sky);
}

namespace {

glm::dvec3 interpolateNormal(const std::vector<glm::vec3>& normals, const std::uint32_t* corners,
                             double u, double v, const glm::dvec3& geometricNormal)
{
    if (normals.empty())
        return geometricNormal;
    const glm::dvec3 n = (1.0 - u - v) * glm::dvec3(normals[corners[0]]) +
                         u * glm::dvec3(normals[corners[1]]) + v * glm::dvec3(normals[corners[2]]);
    const double length = glm::length(n);
    return length > 0.0 && std::isfinite(length) ? n / length : geometricNormal;
}

glm::dvec3 interpolatePoint(const std::vector<glm::vec3>& positions, const std::uint32_t* corners,
                            double u, double v)
{
    const glm::dvec3 p0(positions[corners[0]]);
    const glm::dvec3 p1(positions[corners[1]]);
    const glm::dvec3 p2(positions[corners[2]]);
    return p0 + u * (p1 - p0) + v * (p2 - p0);
}

} // namespace

glm::dvec3 SceneLights::getShadingNormal(std::uint32_t triangle, double u, double v,
                                         const glm::dvec3& geometricNormal) const
{
    return interpolateNormal(mScene.normals, &mScene.indices[3 * std::size_t(triangle)], u, v,
                             geometricNormal);
}

glm::dvec3 SceneLights::getPoint(std::uint32_t triangle, double u, double v) const
{
    return interpolatePoint(mScene.positions, &mScene.indices[3 * std::size_t(triangle)], u, v);
}

void SceneLights::getSurface(std::uint32_t triangle, double u, double v,
                             const glm::dvec3& geometricNormal, glm::dvec3& point,
                             glm::dvec3& shadingNormal) const
{
    const std::uint32_t* corners = &mScene.indices[3 * std::size_t(triangle)];
    point = interpolatePoint(mScene.positions, corners, u, v);
    shadingNormal = interpolateNormal(mScene.normals, corners, u, v, geometricNormal);
}

double SceneLights::pdfEmitter(std::uint32_t triangle, double distance, double cosLight) const
{
    const std::int32_t slot = mEmitterSlot[triangle];
    if (slot < 0 || cosLight <= 0.0)
        return 0.0;
    // Area density pmf / area converted to solid angle: * d^2 / |cos| [Veach 1997, 8.2.2].
    return emitterPick.pmf(std::size_t(slot)) * distance * distance /
           (emitterArea[std::size_t(slot)] * cosLight);
}

} // namespace rtlab::reference
