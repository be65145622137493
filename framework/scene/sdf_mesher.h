#pragma once
// Turns an SDF model into the triangles that the rasteriser and the ray tracer share. This is
// scene preparation, not a technique under study: a surface-nets mesher (one vertex per cell
// that the surface crosses, one quad per crossed grid edge) whose vertices are projected onto
// the surface with Newton steps, so the render mesh lies on the true surface up to float
// precision at its vertices. Closed (no boundary edges) always; 2-manifold except where two
// sheets of the surface pass through one cell (thin parts, sharp edges not aligned with the grid),
// where the shared vertex makes a few non-manifold edges.

#include "core/mesh.h"
#include "scene/csg.h"

#include <cstdint>
#include <vector>

namespace rtlab::scene {

struct SdfMeshOptions {
    int resolution = 96;  //!< cells along the longest side of the model's bounds, [4, 2048]
    int frame = 1 << 30;  //!< apply edits up to this frame
    int projectionSteps = 3;  //!< Newton steps toward f = 0 per vertex (0 = plain surface nets)
};

struct SdfMesh {
    TriangleMesh mesh;                     //!< positions, unit normals, indices
    std::vector<std::uint32_t> triangleMaterial;  //!< material per triangle (SdfModel materials)
};

//! Meshes `model`; the grid extends one cell beyond its bounds so closed shapes stay closed.
SdfMesh meshSdfModel(const SdfModel& model, const SdfMeshOptions& options = {});

} // namespace rtlab::scene
