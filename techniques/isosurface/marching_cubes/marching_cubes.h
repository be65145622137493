#pragma once
// Technique isosurface/marching_cubes: see marching_cubes.cpp for the doc block.

#include "extraction.h"

#include "config/param.h"
#include "families/isosurface/isosurface.h"

namespace rtlab::isosurface {

class MarchingCubes final : public plugin::IsosurfaceTechnique {
public:
    static plugin::TechniqueInfo describe();
    static config::ParamSchema declareParams();

    //! `params` holds every declared parameter (validated by the harness); an enum value outside
    //! its choices or an out-of-range grain throws std::invalid_argument.
    explicit MarchingCubes(const config::ParamSet& params);

    config::ParamSet effectiveParams() const override;
    void extract(const plugin::IsosurfaceInput& input, TriangleMesh& out) override;

    const mc::ExtractionOptions& options() const { return mOptions; }

private:
    mc::ExtractionOptions mOptions;
};

} // namespace rtlab::isosurface
