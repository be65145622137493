#pragma once
// The dual contouring mesher proper: Hermite data, one QEF vertex per surface patch of a cell (or
// per cell), one quad per crossed grid edge, optional material boundary relaxation. See
// dual_contouring.h for the doc block.

#include "core/mesh.h"
#include "families/isosurface/isosurface.h"

#include <cstddef>
#include <cstdint>
#include <memory>

namespace rtlab::isosurface::dc {

enum class QefSolver {
    Svd,     //!< truncated SVD (Jacobi eigen decomposition of A^T A) about the mass point
    Schmitz, //!< particle iteration of Schmitz, Dietrich and Comba 2009
};

enum class SchmitzStart {
    MassPoint,  //!< mean of the cell's crossings
    CellCenter, //!< centre of the cell box
};

enum class OutsidePolicy {
    Clamp,     //!< clamp each coordinate to the cell box
    MassPoint, //!< replace the vertex by the cell's mass point
    Keep,      //!< leave it where the solver put it
};

enum class VertexMode {
    PerComponent, //!< one vertex per surface patch (marching cubes loop) of a cell
    PerCell,      //!< one vertex per cell with a sign change (classic dual contouring)
};

enum class HermiteMode {
    Auto,    //!< input.hermite, else exactValue/exactGradient, else the samples
    Samples, //!< always the samples (linear crossings, central-difference normals)
};

//! Which source gave the Hermite data of a call (counter `hermite_source`).
enum class HermiteSource {
    Hermite = 0, //!< IsosurfaceInput::hermite
    Exact = 1,   //!< bisection on exactValue, normals from exactGradient
    Samples = 2, //!< linear interpolation and central differences of the samples
};

struct ExtractionOptions {
    VertexMode vertices = VertexMode::PerComponent;
    QefSolver solver = QefSolver::Svd;
    double svdThreshold = 0.1;  //!< relative to the largest singular value, [0, 1]
    int schmitzIterations = 20; //!< >= 1
    double schmitzStep = 1.0;   //!< times the mean plane force, (0, 2)
    SchmitzStart schmitzStart = SchmitzStart::MassPoint;
    OutsidePolicy outsidePolicy = OutsidePolicy::Clamp;
    HermiteMode hermite = HermiteMode::Auto;
    double crossingPrecision = 1e-6;       //!< bisection interval on exactValue, cells, (0, 0.5]
    int materialRelaxationIterations = 0;  //!< >= 0
    double materialRelaxationWeight = 0.5; //!< fraction of the way to the neighbour mean, [0, 1]
    bool computeNormals = true;
};

//! What one call did; DualContouring::counters() reports it.
struct ExtractionStats {
    HermiteSource source = HermiteSource::Samples;
    std::size_t crossedEdges = 0;   //!< grid edges with a sign change
    std::size_t hermiteMissing = 0; //!< crossed edges absent from input.hermite (next source used)
    std::size_t cells = 0;          //!< cells with a sign change
    std::size_t vertices = 0;       //!< all output vertices (patch and face vertices)
    std::size_t patchVertices = 0;  //!< QEF vertices: one per cell (per_cell) or per patch
    std::size_t multiVertexCells = 0;   //!< cells with more than one patch vertex
    std::size_t faceVertices = 0;       //!< vertices on faces that two patches cross twice
    std::size_t quads = 0;              //!< crossed edges with four cells around them
    std::size_t rank[4] = {0, 0, 0, 0}; //!< patch vertices by QEF rank (Schmitz: 0 or 3)
    std::size_t skippedNormals = 0;     //!< crossings whose normal was zero, NaN or infinite
    std::size_t cellsWithoutPlanes = 0; //!< patch vertices at their mass point (no normals)
    std::size_t leftCell = 0;           //!< patch vertices outside their cell box (pre-policy)
    std::size_t flippedSplits = 0;      //!< quads split along the diagonal v1-v3
    std::size_t boundaryVertices = 0;   //!< material boundary vertices (when materials are given)
    double maxRelaxationShift = 0.0;    //!< largest relaxation displacement, cells
};

//! The passes' scratch arrays (crossed edges, crossings, cell vertices, triangle lists), kept
//! between calls so that re-meshing a grid of the same size allocates, and faults in, nothing
//! new. Not shared between threads.
class Workspace {
public:
    Workspace();
    ~Workspace();
    Workspace(Workspace&&) noexcept;
    Workspace& operator=(Workspace&&) noexcept;
    struct Arrays;
    Arrays& arrays() { return *mArrays; }

private:
    std::unique_ptr<Arrays> mArrays;
};

//! Replaces `out` with the dual contour of {f = isoValue}; f < isoValue is inside. Throws
//! std::invalid_argument (leaving `out` untouched) on a NaN sample, a non-finite iso-value,
//! spacing or origin, a value or material count that does not match the samples, or Hermite data
//! for another grid. Fewer than 2 samples along an axis give an empty mesh. The output does not
//! depend on `workspace` (null: a fresh one for this call).
void extractDualContour(const plugin::IsosurfaceInput& input, const ExtractionOptions& options,
                        TriangleMesh& out, ExtractionStats& stats, Workspace* workspace = nullptr);

} // namespace rtlab::isosurface::dc
