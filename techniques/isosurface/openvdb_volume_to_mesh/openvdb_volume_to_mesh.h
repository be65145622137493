#pragma once
// Technique isosurface/openvdb_volume_to_mesh: see openvdb_volume_to_mesh.cpp for the doc block.

#include "config/param.h"
#include "families/isosurface/isosurface.h"

#include <string>
#include <utility>
#include <vector>

namespace rtlab::isosurface {

class OpenVdbVolumeToMesh final : public plugin::IsosurfaceTechnique {
public:
    static plugin::TechniqueInfo describe();
    static config::ParamSchema declareParams();

    //! `params` holds every declared parameter; an out-of-range value throws std::invalid_argument.
    explicit OpenVdbVolumeToMesh(const config::ParamSet& params);

    config::ParamSet effectiveParams() const override;
    //! grid_ms, mesh_ms, convert_ms, active_voxels, quads, triangles (see the doc block).
    std::vector<std::pair<std::string, double>> counters() const override;
    void extract(const plugin::IsosurfaceInput& input, TriangleMesh& out) override;

private:
    double mAdaptivity = 0.0;  //!< [0, 1]
    int mThreads = 0;          //!< 0 = all
    double mGridMs = 0.0;
    double mMeshMs = 0.0;
    double mConvertMs = 0.0;
    double mActiveVoxels = 0.0;
    double mQuads = 0.0;
    double mTriangles = 0.0;
};

} // namespace rtlab::isosurface
