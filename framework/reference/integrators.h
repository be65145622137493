#pragma once
// Per-sample estimators of the ground truth (internal to rtlab_reference). One call evaluates
// sample `index` of one pixel and writes getChannelCount(quantity) channels; see reference.h for
// the quantities and their conventions.

#include "reference/embree_scene.h"
#include "reference/reference.h"
#include "reference/samplers.h"
#include "reference/sequences.h"

#include <glm/vec3.hpp>

#include <array>
#include <cstdint>
#include <vector>

namespace rtlab::reference {

constexpr int kMaxChannels = 5;
using SampleValue = std::array<double, kMaxChannels>;

//! Estimator channels: 1 (ao, ao_uniform, obscurance), 5 (bent: V w, V, V_u), 3 (E / pi, RGB).
int getChannelCount(Quantity quantity);

//! Materials and light tables of a RenderScene, in the form the path tracer samples them.
class SceneLights {
public:
    //! Throws rtlab::Error when triangleMaterial or normals do not match the triangles.
    explicit SceneLights(const scene::RenderScene& scene);

    // By material: a path's hit reads one small per-triangle index and a table that stays in
    // cache, not two triangle-sized arrays.
    const glm::dvec3& getAlbedo(std::uint32_t triangle) const
    {
        return mMaterialAlbedo[mScene.triangleMaterial[triangle]];
    }
    const glm::dvec3& getEmission(std::uint32_t triangle) const
    {
        return mMaterialEmission[mScene.triangleMaterial[triangle]];
    }
    //! Interpolated shading normal (the geometric one where the scene has no normals).
    glm::dvec3 getShadingNormal(std::uint32_t triangle, double u, double v,
                                const glm::dvec3& geometricNormal) const;
    glm::dvec3 getPoint(std::uint32_t triangle, double u, double v) const;
    //! getPoint and getShadingNormal from one read of the triangle's indices.
    void getSurface(std::uint32_t triangle, double u, double v, const glm::dvec3& geometricNormal,
                    glm::dvec3& point, glm::dvec3& shadingNormal) const;
    //! Unit geometric normal (zero for a degenerate triangle).
    const glm::dvec3& getGeometricNormal(std::uint32_t triangle) const { return mNormal[triangle]; }
    const std::vector<scene::PointLight>& getPointLights() const { return mScene.pointLights; }
    const scene::Sky& getSky() const { return mScene.sky; }

    //! Solid-angle density of sampling `triangle` by emitter sampling, seen from `distance` with
    //! |cos| at the emitter `cosLight`; 0 when the triangle is not emissive.
    double pdfEmitter(std::uint32_t triangle, double distance, double cosLight) const;

    DiscreteDistribution pointLightPick;
    bool evaluateAllPointLights = true; //!< few lights: every one each sample, no pick noise
    DiscreteDistribution emitterPick;   //!< by luminance(Le) * area
    std::vector<std::uint32_t> emitterTriangles;
    std::vector<double> emitterArea;
    SkyLobeSampler skyLobes;

private:
    const scene::RenderScene& mScene;
    std::vector<glm::dvec3> mMaterialAlbedo;
    std::vector<glm::dvec3> mMaterialEmission;
    std::vector<glm::dvec3> mNormal;
    std::vector<std::int32_t> mEmitterSlot; //!< per triangle, -1 when not emissive
};

struct TraceContext {
    const EmbreeScene* embree = nullptr;
    const SceneLights* lights = nullptr;
    Quantity quantity = Quantity::Ao;
    double radius = 0.0;
    Falloff falloff = Falloff::Linear;
    int bounces = 2;
    double rayEpsilon = 0.0;
};

//! A G-buffer surface sample: position and unit shading normal.
struct SurfacePoint {
    glm::dvec3 position{0.0};
    glm::dvec3 normal{0.0, 0.0, 1.0};
};

//! ao, ao_uniform, obscurance, bent. Returns the number of rays traced.
std::uint32_t evaluateOcclusionSample(const TraceContext& context, const SurfacePoint& point,
                                      const PixelSequence& sequence, std::uint32_t index,
                                      SampleValue& value);
//! Samples first .. first + count - 1 of the same quantities into values[0 .. count - 1], the
//! same values as evaluateOcclusionSample; ao, ao_uniform and bent trace their rays as Embree
//! ray streams from the point. Returns the number of rays traced.
std::uint32_t evaluateOcclusionBatch(const TraceContext& context, const SurfacePoint& point,
                                     const PixelSequence& sequence, std::uint32_t first,
                                     std::uint32_t count, SampleValue* values);
//! direct, indirect, full: E/pi per colour (before albedo). Returns the number of rays traced.
//! `streams` (optional): sequence.getStream(p) for the pairs p < streamCount, which a batch of
//! the pixel's samples computes once; `firstVertexPointLights` (optional): what
//! evaluateFirstVertexPointLights computed for the point, when it says it is shared. The samples
//! are the same bits either way.
std::uint32_t evaluateLightSample(const TraceContext& context, const SurfacePoint& point,
                                  const PixelSequence& sequence, std::uint32_t index,
                                  SampleValue& value, const SobolStream* streams = nullptr,
                                  std::uint32_t streamCount = 0,
                                  const glm::dvec3* firstVertexPointLights = nullptr);
//! The point lights' term at the G-buffer point itself (the path's first vertex), where every
//! point light is evaluated each sample (few lights, no pick): it uses no sample dimension, so
//! every sample of the pixel computes the same value with the same shadow rays. `shared` says
//! whether it applies (and the quantity keeps that light); then a batch of the pixel's samples
//! traces those rays once and passes `sum` to evaluateLightSample. Returns the rays traced.
std::uint32_t evaluateFirstVertexPointLights(const TraceContext& context, const SurfacePoint& point,
                                             const PixelSequence& sequence, glm::dvec3& sum,
                                             bool& shared);
//! The pairs of the first vertices of a path, whose streams a batch computes once.
constexpr std::uint32_t kLightStreamsPerBatch = 24;

} // namespace rtlab::reference
