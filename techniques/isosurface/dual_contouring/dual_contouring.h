#pragma once
// dual_contouring: one QEF-placed vertex per surface patch of a cell (or per cell), one quad per
// crossed grid edge.
//
// Registry key: isosurface/dual_contouring
//
// Paper: T. Ju, F. Losasso, S. Schaefer, J. Warren, "Dual Contouring of Hermite Data",
// SIGGRAPH 2002 (uniform-grid variant, no octree simplification). One vertex per surface
// component of a cell: G. M. Nielson, "Dual Marching Cubes", IEEE Visualization 2004; the
// finest-level vertex clustering of S. Schaefer, T. Ju, J. Warren, "Manifold Dual Contouring",
// IEEE TVCG 2007. QEF solved about the mass point with a truncated SVD: P. Lindstrom,
// "Out-of-Core Simplification of Large Polygonal Models", SIGGRAPH 2000; S. Schaefer, J. Warren,
// "Dual Contouring: The Secret Sauce", 2002. Iterative
// solver: L. Schmitz, C. Dietrich, J. Comba, "Efficient and High Quality Contouring of Isosurfaces
// on Uniform Grids", SIBGRAPI 2009 (extended as "Efficient and Quality Contouring Algorithms on
// the GPU", Computer Graphics Forum 2010).
//
// Seed: 000_3da000e866ebc485.txt (J. McLaren, "The Technology of The Tomorrow Children",
// GDC 2015, landscape part): marching cubes "destroys sharp features, looks blobby", changes with
// translation and turns rotated cubes into "polygonal vomit", and cannot use the stored normals;
// dual contouring keeps sharp edges ("cube in input means cube in output"). They replaced the QEF
// "annoying math" by the Schmitz et al. particle iteration ("much simpler & GPU friendly", at the
// price of "some sharp edges a little bit wobbly", tuned by iteration count and forces), used at
// most one plane per DC cube edge (12 per cube), and relaxed vertices on material transitions
// "in an elastic net fashion" because one material per quad gives staircase transitions.
//
// Algorithm
// - Inside is f < iso, outside f >= iso (as marching_cubes). A grid edge is crossed when its ends
//   differ; a cell is active when its corners differ. NaN samples throw std::invalid_argument;
//   +inf / -inf samples are outside / inside.
// - Hermite data, first available source, counter `hermite_source`:
//   0 = IsosurfaceInput::hermite (edges it lacks take the next source, counter
//   `hermite_edges_missing`); 1 = exactValue bisected along the edge until the bracket is at most
//   `crossing_precision` cells wide (|t - t_true| <= crossing_precision / 2 cells), normals from
//   exactGradient (either function may be missing: its part then comes from the samples);
//   2 = the samples: zero of the linear interpolant, normals from central differences of the
//   sampled field interpolated along the edge. `hermite: samples` forces source 2.
// - Vertices (`vertices`). per_cell (classic DC): one vertex per active cell, on all its crossed
//   edges. per_component (default): one vertex per surface patch of the cell [Nielson 2004;
//   Schaefer et al. 2007], the patches being the loops of the marching cubes case table shared
//   with marching_cubes (framework/isosurface/case_table.h), with ambiguous faces decided by the
//   asymptotic decider as marching_cubes does by default. The decision depends on the face's
//   four values only, so both cells on a face split its crossed edges into the same segments.
//   Each crossed edge's quad takes, in each of its 4 cells, the vertex of the patch holding that
//   edge. Where the patches of both cells on an ambiguous face cross it twice (a tunnel through
//   the face), one vertex per patch would put one mesh edge on four quads; there each of the
//   face's two segments gets a face vertex, the midpoint of its two crossings (on the face), the
//   quads around the segment's edges become pentagons through it, and those are fanned around
//   their first face vertex. Guarantee: a surface whose crossed edges all have four cells around
//   them gives a closed, consistently oriented 2-manifold (every edge in two triangles, every
//   vertex a single fan) with the Euler characteristic of the marching cubes polygon complex.
//   Limits: combinatorial only (vertices can coincide after clamping, triangles can fold or
//   intersect near sharp features); the topology is that of the table, which resolves faces but
//   not the interior ambiguity of a cell (each loop is one disk, no tunnel inside a cell);
//   surfaces leaving the grid are open there.
// - Per vertex the QEF sum_i (n_i . (x - p_i))^2 over the crossings of its own edges (all 12
//   of the cell for per_cell) [Ju et al. 2002, eq. 1], built relative to their mass point and
//   solved by a cyclic Jacobi eigen decomposition of A^T A: singular values
//   sigma_k = sqrt(lambda_k) below svd_threshold * sigma_max are dropped, so the vertex stays at
//   the mass point along them (3 planes at a corner give the corner, 2 the point of the edge
//   nearest the mass point, 1 the mass point's projection). Zero / NaN / infinite normals are
//   skipped; a vertex with no usable normal gets its mass point. `solver: schmitz` runs the
//   particle iteration instead.
// - Patch vertices outside their cell box (by more than 1e-9 cells) are counted before
//   `outside_policy` acts: clamp each coordinate to the box, replace by the mass point, or keep.
// - Optional material relaxation (when IsosurfaceInput::materials is given and
//   material_relaxation_iterations > 0): a quad takes the material of its edge's inside sample
//   (the talk's rule); a vertex whose quads carry different materials is a boundary vertex. Each
//   iteration moves every boundary vertex material_relaxation_weight of the way to the mean of its
//   boundary neighbours (vertices joined by a quad side) and projects it back onto the surface
//   (Newton steps on exactValue / exactGradient when both exist, else the QEF minimiser nearest
//   to it, which slides along flat and edge cells and keeps corners). A step whose projection
//   leaves the vertex's cell is halved up to 4 times, else dropped, so relaxed vertices stay on
//   the surface and in their cell (the talk: "we make sure they don't move outside their DC
//   cube"). Jacobi updates: all vertices move from the previous iterate. The talk's rule (mixed
//   quad materials) is used rather than "corner samples of different materials": air samples'
//   materials do not matter, only those of the inside ends of crossed edges.
// - One quad per crossed edge with all four cells around it (edges on the grid's outer faces give
//   none, so surfaces leaving the grid are open there), wound counter-clockwise seen from the
//   positive side, split into two triangles along the diagonal whose triangles' unit normals agree
//   best; ties (within 1e-12, e.g. planar convex quads) take the diagonal through the smallest
//   vertex index.
// - Indexed output: vertices numbered in cell scan order (within a cell its patches in table
//   order, then the face vertices of its high faces), triangles in crossed-edge scan order
//   (layer, row, sample, axis). All work is done in grid units (sample spacing = 1, cell frame
//   [0, 1]^3) and mapped to world units at the end, so results do not depend on the field's scale
//   or origin beyond float rounding of the output. TBB: every parallel loop writes per-item slots
//   and the reductions are serial, so the output is identical for every thread count.
// - Vertex normals: the normalised sum of the vertex's crossing normals (else the cell's sampled
//   gradient). Material relaxation moves patch vertices only; face vertices stay.
//
// Parameters
// | name                           | type  | default       | range / choices           | unit  |
// |--------------------------------|-------|---------------|---------------------------|-------|
// | vertices                       | enum  | per_component | {per_component, per_cell} |       |
// | solver                         | enum  | svd           | {svd, schmitz}            |       |
// | svd_threshold                  | float | 0.1           | [0, 1]                    |       |
// | schmitz_iterations             | int   | 20            | [1, 100000]               |       |
// | schmitz_step                   | float | 1             | [0.01, 1.9]               |       |
// | schmitz_start                  | enum  | mass_point    | {mass_point, cell_center} |       |
// | outside_policy                 | enum  | clamp         | {clamp, mass_point, keep} |       |
// | hermite                        | enum  | auto          | {auto, samples}           |       |
// | crossing_precision             | float | 1e-6          | [1e-12, 0.5]              | cells |
// | material_relaxation_iterations | int   | 0             | [0, 1000]                 |       |
// | material_relaxation_weight     | float | 0.5           | [0, 1]                    |       |
// | normals                        | enum  | hermite       | {hermite, none}           |       |
// svd_threshold: singular values of A below this fraction of the largest are dropped (a floor of
// 1e-6 always applies). schmitz_step: fraction of the mean plane force added per iteration; the
// iteration converges for every value in (0, 2) with unit normals. crossing_precision: bisection
// bracket on exactValue, in cells.
//
// Counters (per extract call): hermite_source (0 hermite, 1 exact, 2 samples),
// hermite_edges_missing, qef_solver (0 svd, 1 schmitz), crossed_edges, cells (with a sign
// change), vertices (all), cells_multi_vertex (cells with more than one patch vertex),
// face_vertices, quads, cells_rank_0..3 (SVD rank per patch vertex), normals_skipped,
// cells_without_normals, vertices_left_cell (count) and vertices_left_cell_share (of patch
// vertices), split_diagonal_13_share, material_boundary_vertices, material_relaxation_max_shift
// (cells).
//
// Config (technique parameters go under `params`, as for every technique):
//   techniques:
//     isosurface: {technique: dual_contouring, params: {svd_threshold: 0.1}}

#include "extraction.h"

#include "config/param.h"
#include "families/isosurface/isosurface.h"

#include <string>
#include <utility>
#include <vector>

namespace rtlab::isosurface {

class DualContouring final : public plugin::IsosurfaceTechnique {
public:
    static plugin::TechniqueInfo describe();
    static config::ParamSchema declareParams();

    //! `params` holds every declared parameter (validated by the harness); an enum value outside
    //! its choices or an out-of-range number throws std::invalid_argument.
    explicit DualContouring(const config::ParamSet& params);

    config::ParamSet effectiveParams() const override;
    std::vector<std::pair<std::string, double>> counters() const override;
    void extract(const plugin::IsosurfaceInput& input, TriangleMesh& out) override;

    const dc::ExtractionOptions& options() const { return mOptions; }
    const dc::ExtractionStats& stats() const { return mStats; }

private:
    dc::ExtractionOptions mOptions;
    dc::ExtractionStats mStats;
    dc::Workspace mWorkspace; //!< scratch arrays kept between extract() calls
};

} // namespace rtlab::isosurface
