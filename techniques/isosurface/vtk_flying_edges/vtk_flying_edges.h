#pragma once
// Technique isosurface/vtk_flying_edges: see vtk_flying_edges.cpp for the doc block.

#include "config/param.h"
#include "families/isosurface/isosurface.h"

#include <string>
#include <utility>
#include <vector>

namespace rtlab::isosurface {

class VtkFlyingEdges final : public plugin::IsosurfaceTechnique {
public:
    static plugin::TechniqueInfo describe();
    static config::ParamSchema declareParams();

    //! `params` holds every declared parameter; an out-of-range value throws std::invalid_argument.
    explicit VtkFlyingEdges(const config::ParamSet& params);

    config::ParamSet effectiveParams() const override;
    //! filter_ms, convert_ms, smp_threads, smp_backend (see the doc block).
    std::vector<std::pair<std::string, double>> counters() const override;
    void extract(const plugin::IsosurfaceInput& input, TriangleMesh& out) override;

private:
    int mThreads = 0;            //!< 0 = all
    bool mComputeNormals = true;
    double mFilterMs = 0.0;
    double mConvertMs = 0.0;
    int mSmpThreads = 0;
    std::string mSmpBackend;
};

} // namespace rtlab::isosurface
