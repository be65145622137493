#pragma once
// occlusion/lsao: Line-Sweep Ambient Obscurance (see the doc block in lsao.cpp).

#include "lsao_core.h"

#include "families/occlusion/occlusion.h"

#include <memory>

namespace rtlab::occlusion::lsao {

class GpuRunner;

class Lsao final : public plugin::OcclusionTechnique {
public:
    static plugin::TechniqueInfo describe();
    static config::ParamSchema declareParams();

    //! Throws std::invalid_argument for values outside the declared ranges.
    explicit Lsao(const config::ParamSet& params);
    ~Lsao() override;

    config::ParamSet effectiveParams() const override;
    plugin::OcclusionDefinition definition() const override;
    //! GPU when input.gpu is set (pipelines and images kept across calls), else C++.
    void compute(const plugin::OcclusionInput& input, plugin::OcclusionOutput& out) override;
    bool acceptsGpuInputs() const override { return true; }
    bool outputsOnGpu() const override { return true; }
    void readBack(plugin::OcclusionOutput& out) override;

    const Params& getParams() const { return mParams; }

private:
    Params mParams;
    std::unique_ptr<GpuRunner> mGpu;
};

} // namespace rtlab::occlusion::lsao
