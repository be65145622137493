#pragma once
// Turns an SDF model into the triangles that the rasteriser and the ray tracer share. This is
// scene preparation, not a technique under study: a surface-nets mesher (one vertex per cell
// that the surface crosses, one quad per crossed grid edge) whose vertices are projected onto
// the surface with Newton steps, so the render mesh lies on the true surface up to float
// precision at its vertices. Closed (no boundary edges) always; 2-manifold except where two
// sheets of the surface pass through one cell (thin parts, sharp edges not aligned with the grid),
// where the shared vertex makes a few non-manifold edges.
//
// A dig re-meshes only what it touched (SdfMesher::update): the new edits are folded into the
// kept samples (the field is the edits applied in list order, so this gives the same numbers as
// evaluating every edit again), the cells with a changed corner or within an edit's reach are
// meshed again, the quads on their edges rebuilt, and the mesh's arrays patched in place. The
// result has the same triangles, vertices and normals as meshing the whole grid, up to order.

#include "core/mesh.h"
#include "scene/csg.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace rtlab::scene {

struct SdfMeshOptions {
    int resolution = 96;  //!< cells along the longest side of the model's bounds, [4, 2048]
    int frame = 1 << 30;  //!< apply edits up to this frame (meshSdfModel only)
    int projectionSteps = 3;  //!< Newton steps toward f = 0 per vertex (0 = plain surface nets)
};

struct SdfMesh {
    TriangleMesh mesh;                     //!< positions, unit normals, indices
    std::vector<std::uint32_t> triangleMaterial;  //!< material per triangle (SdfModel materials)
};

//! Meshes `model`; the grid extends one cell beyond its bounds so closed shapes stay closed.
SdfMesh meshSdfModel(const SdfModel& model, const SdfMeshOptions& options = {});

//! The grid cell size meshSdfModel uses for `model` at `resolution`.
double getSdfCellSize(const SdfModel& model, int resolution);

//! The box outside which `edit` changes nothing of `model`'s mesh at `resolution`: the edit's
//! primitive bounds grown by its blend radius (the polynomial soft minimum equals the hard one
//! farther than that, scene/csg.h) and by 7 cells. A vertex's Newton steps stay within a
//! 2-cell box around its cell, every point of which is within 2 sqrt(3) cells of the surface
//! the cell holds, so the field there is within 2 sqrt(3) L cells of zero for a field with
//! Lipschitz constant L; an exact primitive changes a min or max only where its distance is
//! below that, and 7 cells cover L up to 2 (CSG of exact distances has L = 1). Returns false
//! when no box bounds the edit: an intersection (it changes everything outside its primitive)
//! and an ellipsoid (its distance is a lower bound of unknown slack, csg.h).
bool findEditReach(const SdfModel& model, const CsgEdit& edit, int resolution, glm::dvec3& lo,
                   glm::dvec3& hi);

//! What SdfMesher::update did.
struct SdfMeshChange {
    bool changed = false;      //!< the mesh differs from the one before the call
    bool full = false;         //!< the whole grid was evaluated and meshed
    std::string what;          //!< in words: why it was meshed in full, or what was re-meshed
    std::size_t cellCount = 0;      //!< cells of the grid
    std::size_t cellsMeshed = 0;    //!< cells whose vertex was computed again
    std::size_t samplesChanged = 0; //!< grid samples whose value the new edits changed
    //! Box holding every triangle removed or added (empty, lo > hi, when none was).
    glm::dvec3 changedMin{1e300}, changedMax{-1e300};
};

//! Meshes one SDF model and keeps its grid, so that later frames re-mesh only what their edits
//! touched. `model` must outlive the mesher and keep its edits (digs only append).
class SdfMesher {
public:
    //! `options.frame` is ignored: update() takes the frame.
    SdfMesher(const SdfModel& model, const SdfMeshOptions& options);
    ~SdfMesher();
    SdfMesher(SdfMesher&&) noexcept;
    SdfMesher& operator=(SdfMesher&&) noexcept;

    //! Brings the mesh to the edits up to `frame`: in full on the first call, when `full` is
    //! set, when an edit that was applied no longer is (an earlier frame), when a new edit comes
    //! before an applied one in the list, or when a new edit has no bounded reach
    //! (findEditReach); otherwise only the cells the new edits touched.
    SdfMeshChange update(int frame, bool full = false);
    const SdfMesh& getMesh() const;
    //! The frame of the last update (-2^31 before the first).
    int getMeshedFrame() const;

private:
    struct State;
    std::unique_ptr<State> mState;
};

} // namespace rtlab::scene
