#pragma once
// Technique occlusion/gtao: see gtao.cpp for the doc block.

#include "config/param.h"
#include "families/occlusion/occlusion.h"

#include <memory>

namespace rtlab::occlusion {

//! How far along a slice the horizon search goes, in pixels, before max_pixel_radius.
enum class GtaoSearchExtent {
    //! Exact screen extent of the sphere of radius `radius` around the pixel's point along the
    //! slice, per side (every point within the radius is reachable).
    Sphere,
    //! radius projected at the pixel's depth, the same on both sides [Jimenez et al. 2016].
    Depth,
};

//! The parameters in effect (after validation).
struct GtaoSettings {
    double radius = 1.0;           //!< world units, [0, inf]; occluders farther do not count
    int slices = 2;                //!< slice directions per pixel and frame, [1, 32]
    int steps = 8;                 //!< depth samples per side of a slice, [1, 64]
    double maxPixelRadius = 256.0; //!< px, [1, 4096]; screen-space search limit per side
    double falloffFraction = 0.0;  //!< [0, 1]: last fraction of radius blended out; 0 = hard
    bool normalize = true;         //!< divide by the unoccluded integral of the same slices
    bool temporalRotation = true;  //!< rotate slices and steps with OcclusionInput::frameIndex
    GtaoSearchExtent searchExtent = GtaoSearchExtent::Sphere;
};

class GtaoGpu;

class Gtao final : public plugin::OcclusionTechnique {
public:
    static plugin::TechniqueInfo describe();
    static config::ParamSchema declareParams();

    //! `params` holds every declared parameter; values outside their ranges or an unknown enum
    //! choice throw std::invalid_argument.
    explicit Gtao(const config::ParamSet& params);
    ~Gtao() override;

    config::ParamSet effectiveParams() const override;
    plugin::OcclusionDefinition definition() const override;
    //! With input.gpu, gpuLinearDepth and gpuNormal set: binds those (no upload). Otherwise
    //! throws std::invalid_argument when linearDepth or normal is null or their sizes differ.
    void compute(const plugin::OcclusionInput& input, plugin::OcclusionOutput& out) override;
    bool acceptsGpuInputs() const override { return true; }
    bool outputsOnGpu() const override { return true; }
    void readBack(plugin::OcclusionOutput& out) override;

    const GtaoSettings& settings() const { return mSettings; }

private:
    GtaoSettings mSettings;
    std::unique_ptr<GtaoGpu> mGpu; //!< pipeline and images, created on the first GPU frame
};

} // namespace rtlab::occlusion
