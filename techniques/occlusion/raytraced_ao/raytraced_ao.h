#pragma once
// Technique occlusion/raytraced_ao: see raytraced_ao.cpp for the doc block.

#include "config/param.h"
#include "families/occlusion/occlusion.h"

#include <cstdint>

namespace rtlab::occlusion {

struct RaytracedAoSettings {
    int samplesPerPixel = 4;         //!< rays per pixel and frame, [1, 65536]
    double radius = 1.0;             //!< world units, [0, inf]
    std::uint64_t seed = 0x5eed0fa0; //!< of the ray directions; differs from the ground truth's
    bool rotateSeedPerFrame = true;  //!< new directions every frame (frameIndex added to the seed)
};

class RaytracedAo final : public plugin::OcclusionTechnique {
public:
    static plugin::TechniqueInfo describe();
    static config::ParamSchema declareParams();
    explicit RaytracedAo(const config::ParamSet& params);

    config::ParamSet effectiveParams() const override;
    plugin::OcclusionDefinition definition() const override;
    //! Traces input.scene from input.gbuffer when both are given, else the depth buffer as a
    //! height field. Throws std::invalid_argument when linearDepth or normal is null.
    void compute(const plugin::OcclusionInput& input, plugin::OcclusionOutput& out) override;
    std::vector<std::pair<std::string, double>> counters() const override;

private:
    RaytracedAoSettings mSettings;
    double mRaysPerSecond = 0.0;
    bool mTracedScene = false;
};

} // namespace rtlab::occlusion
