// dual_contouring: see dual_contouring.h for the doc block (papers, seed, parameters, config).

#include "dual_contouring.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace rtlab::isosurface {
namespace {

const std::vector<std::string> kVertexChoices = {"per_component", "per_cell"};
const std::vector<std::string> kSolverChoices = {"svd", "schmitz"};
const std::vector<std::string> kStartChoices = {"mass_point", "cell_center"};
const std::vector<std::string> kPolicyChoices = {"clamp", "mass_point", "keep"};
const std::vector<std::string> kHermiteChoices = {"auto", "samples"};
const std::vector<std::string> kNormalChoices = {"hermite", "none"};

constexpr std::int64_t kMaxSchmitzIterations = 100000;
constexpr std::int64_t kMaxRelaxationIterations = 1000;
constexpr double kMinSchmitzStep = 0.01;
constexpr double kMaxSchmitzStep = 1.9;
constexpr double kMinCrossingPrecision = 1e-12;
constexpr double kMaxCrossingPrecision = 0.5;

//! Index of `value` in `choices`; throws naming the parameter when it is not there.
std::size_t findChoice(const std::string& param, const std::string& value,
                       const std::vector<std::string>& choices)
{
    for (std::size_t i = 0; i < choices.size(); ++i) {
        if (choices[i] == value)
            return i;
    }
    throw std::invalid_argument("dual_contouring: parameter '" + param + "' has no choice '" +
                                value + "'");
}

double getFloatIn(const config::ParamSet& params, const std::string& name, double min, double max)
{
    const double value = params.getFloat(name);
    if (!(value >= min && value <= max))
        throw std::invalid_argument("dual_contouring: " + name + " " + std::to_string(value) +
                                    " is outside [" + std::to_string(min) + ", " +
                                    std::to_string(max) + "]");
    return value;
}

int getIntIn(const config::ParamSet& params, const std::string& name, std::int64_t min,
             std::int64_t max)
{
    const std::int64_t value = params.getInt(name);
    if (value < min || value > max)
        throw std::invalid_argument("dual_contouring: " + name + " " + std::to_string(value) +
                                    " is outside [" + std::to_string(min) + ", " +
                                    std::to_string(max) + "]");
    return int(value);
}

} // namespace

plugin::TechniqueInfo DualContouring::describe()
{
    plugin::TechniqueInfo info;
    info.summary = "dual contouring on the uniform grid: one QEF vertex per surface patch of a "
                   "cell (marching cubes loops; 2-manifold on closed surfaces) or per cell "
                   "(truncated SVD about the mass point, or the Schmitz particle iteration), one "
                   "quad per crossed edge, optional material boundary relaxation, TBB";
    info.reference = "Ju, Losasso, Schaefer & Warren 2002, Dual Contouring of Hermite Data "
                     "(SIGGRAPH); Nielson 2004, Dual Marching Cubes (IEEE Visualization); "
                     "Schaefer, Ju & Warren 2007, Manifold Dual Contouring (IEEE TVCG); "
                     "Schmitz, Dietrich & Comba 2009, Efficient and High Quality Contouring of "
                     "Isosurfaces on Uniform Grids (SIBGRAPI)";
    info.seed = "000_3da000e866ebc485.txt (The Tomorrow Children: dual contouring of the Layered "
                "Depth Cube landscape, Schmitz solver, elastic relaxation of material "
                "transitions)";
    return info;
}

config::ParamSchema DualContouring::declareParams()
{
    config::ParamSchema schema;
    schema.addEnum("vertices", "per_component", kVertexChoices,
                   "one vertex per surface patch of a cell (marching cubes loops, 2-manifold on "
                   "closed surfaces), or one per cell (classic dual contouring)");
    schema.addEnum("solver", "svd", kSolverChoices,
                   "QEF solver: truncated SVD about the mass point, or the Schmitz et al. 2009 "
                   "particle iteration");
    schema.addFloat("svd_threshold", 0.1, 0.0, 1.0, "",
                    "singular values of A below this fraction of the largest are dropped");
    schema.addInt("schmitz_iterations", 20, 1, kMaxSchmitzIterations, "",
                  "particle iterations of the Schmitz solver");
    schema.addFloat("schmitz_step", 1.0, kMinSchmitzStep, kMaxSchmitzStep, "",
                    "fraction of the mean plane force added per Schmitz iteration");
    schema.addEnum("schmitz_start", "mass_point", kStartChoices,
                   "where the Schmitz particle starts: the crossings' mass point or the cell "
                   "centre");
    schema.addEnum("outside_policy", "clamp", kPolicyChoices,
                   "vertex outside its cell: clamp to the cell box, replace by the mass point, "
                   "or keep");
    schema.addEnum("hermite", "auto", kHermiteChoices,
                   "Hermite data: input.hermite, else exact field, else samples (auto); or "
                   "always the samples");
    schema.addFloat("crossing_precision", 1e-6, kMinCrossingPrecision, kMaxCrossingPrecision,
                    "cells", "bisection bracket width for crossings on the exact field");
    schema.addInt("material_relaxation_iterations", 0, 0, kMaxRelaxationIterations, "",
                  "elastic relaxation iterations of material boundary vertices (0 = off)");
    schema.addFloat("material_relaxation_weight", 0.5, 0.0, 1.0, "",
                    "fraction of the way to the boundary neighbours' mean per iteration");
    schema.addEnum("normals", "hermite", kNormalChoices,
                   "vertex normals: normalised sum of the cell's Hermite normals, or none");
    return schema;
}

DualContouring::DualContouring(const config::ParamSet& params)
{
    mOptions.vertices = findChoice("vertices", params.getString("vertices"), kVertexChoices) == 0
                            ? dc::VertexMode::PerComponent
                            : dc::VertexMode::PerCell;
    mOptions.solver = findChoice("solver", params.getString("solver"), kSolverChoices) == 0
                          ? dc::QefSolver::Svd
                          : dc::QefSolver::Schmitz;
    mOptions.svdThreshold = getFloatIn(params, "svd_threshold", 0.0, 1.0);
    mOptions.schmitzIterations = getIntIn(params, "schmitz_iterations", 1, kMaxSchmitzIterations);
    mOptions.schmitzStep = getFloatIn(params, "schmitz_step", kMinSchmitzStep, kMaxSchmitzStep);
    mOptions.schmitzStart =
        findChoice("schmitz_start", params.getString("schmitz_start"), kStartChoices) == 0
            ? dc::SchmitzStart::MassPoint
            : dc::SchmitzStart::CellCenter;
    constexpr dc::OutsidePolicy kPolicies[] = {
        dc::OutsidePolicy::Clamp, dc::OutsidePolicy::MassPoint, dc::OutsidePolicy::Keep};
    mOptions.outsidePolicy =
        kPolicies[findChoice("outside_policy", params.getString("outside_policy"), kPolicyChoices)];
    mOptions.hermite = findChoice("hermite", params.getString("hermite"), kHermiteChoices) == 0
                           ? dc::HermiteMode::Auto
                           : dc::HermiteMode::Samples;
    mOptions.crossingPrecision =
        getFloatIn(params, "crossing_precision", kMinCrossingPrecision, kMaxCrossingPrecision);
    mOptions.materialRelaxationIterations =
        getIntIn(params, "material_relaxation_iterations", 0, kMaxRelaxationIterations);
    mOptions.materialRelaxationWeight = getFloatIn(params, "material_relaxation_weight", 0.0, 1.0);
    mOptions.computeNormals =
        findChoice("normals", params.getString("normals"), kNormalChoices) == 0;
}

config::ParamSet DualContouring::effectiveParams() const
{
    config::ParamSet params;
    params.set("vertices",
               kVertexChoices[mOptions.vertices == dc::VertexMode::PerComponent ? 0 : 1]);
    params.set("solver", kSolverChoices[mOptions.solver == dc::QefSolver::Svd ? 0 : 1]);
    params.set("svd_threshold", mOptions.svdThreshold);
    params.set("schmitz_iterations", std::int64_t(mOptions.schmitzIterations));
    params.set("schmitz_step", mOptions.schmitzStep);
    params.set("schmitz_start",
               kStartChoices[mOptions.schmitzStart == dc::SchmitzStart::MassPoint ? 0 : 1]);
    params.set("outside_policy", kPolicyChoices[std::size_t(mOptions.outsidePolicy)]);
    params.set("hermite", kHermiteChoices[mOptions.hermite == dc::HermiteMode::Auto ? 0 : 1]);
    params.set("crossing_precision", mOptions.crossingPrecision);
    params.set("material_relaxation_iterations",
               std::int64_t(mOptions.materialRelaxationIterations));
    params.set("material_relaxation_weight", mOptions.materialRelaxationWeight);
    params.set("normals", kNormalChoices[mOptions.computeNormals ? 0 : 1]);
    return params;
}

std::vector<std::pair<std::string, double>> DualContouring::counters() const
{
    const dc::ExtractionStats& s = mStats;
    const auto share = [&](std::size_t count, std::size_t of) {
        return of == 0 ? 0.0 : double(count) / double(of);
    };
    return {
        {"hermite_source", double(int(s.source))},
        {"hermite_edges_missing", double(s.hermiteMissing)},
        {"qef_solver", mOptions.solver == dc::QefSolver::Svd ? 0.0 : 1.0},
        {"crossed_edges", double(s.crossedEdges)},
        {"cells", double(s.cells)},
        {"vertices", double(s.vertices)},
        {"cells_multi_vertex", double(s.multiVertexCells)},
        {"face_vertices", double(s.faceVertices)},
        {"quads", double(s.quads)},
        {"cells_rank_0", double(s.rank[0])},
        {"cells_rank_1", double(s.rank[1])},
        {"cells_rank_2", double(s.rank[2])},
        {"cells_rank_3", double(s.rank[3])},
        {"normals_skipped", double(s.skippedNormals)},
        {"cells_without_normals", double(s.cellsWithoutPlanes)},
        {"vertices_left_cell", double(s.leftCell)},
        {"vertices_left_cell_share", share(s.leftCell, s.patchVertices)},
        {"split_diagonal_13_share", share(s.flippedSplits, s.quads)},
        {"material_boundary_vertices", double(s.boundaryVertices)},
        {"material_relaxation_max_shift", s.maxRelaxationShift},
    };
}

void DualContouring::extract(const plugin::IsosurfaceInput& input, TriangleMesh& out)
{
    dc::ExtractionStats stats;
    dc::extractDualContour(input, mOptions, out, stats, &mWorkspace);
    mStats = stats;
}

} // namespace rtlab::isosurface

RTLAB_REGISTER_TECHNIQUE(isosurface, dual_contouring, rtlab::isosurface::DualContouring)
