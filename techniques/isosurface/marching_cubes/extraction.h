#pragma once
// The marching cubes mesher proper: grid walk, shared edge vertices, TBB slabs.

#include "case_table.h"

#include "core/mesh.h"
#include "families/isosurface/isosurface.h"

namespace rtlab::isosurface::mc {

enum class VertexPlacement {
    Linear,   //!< crossing of the linear interpolant along the edge
    Midpoint, //!< edge midpoint (the field values only pick the topology)
};

struct ExtractionOptions {
    VertexPlacement placement = VertexPlacement::Linear;
    AmbiguityRule ambiguity = AmbiguityRule::Asymptotic;
    bool computeNormals = true; //!< vertex normals from central differences of the field
    int grain = 8;              //!< cell layers per TBB task (z-slab thickness), >= 1
};

//! Replaces `out` with the surface {f = isoValue} of `field`. Samples with f < isoValue are inside,
//! f >= isoValue outside. Throws std::invalid_argument (leaving `out` untouched) on a NaN sample,
//! a non-finite iso-value, spacing or origin, or a value count that does not match the sample
//! counts; throws std::length_error (leaving `out` empty) when the mesh needs more than 32-bit
//! indices. A field with fewer than 2 samples along some axis gives an empty mesh.
void extractIsosurface(const plugin::SampledField& field, double isoValue,
                       const ExtractionOptions& options, TriangleMesh& out);

} // namespace rtlab::isosurface::mc
