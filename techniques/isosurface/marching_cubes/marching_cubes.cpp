// marching_cubes: the classic cell-by-cell isosurface mesher.
//
// Registry key: isosurface/marching_cubes
//
// Paper: W. E. Lorensen, H. E. Cline, "Marching Cubes: A High Resolution 3D Surface Construction
// Algorithm", SIGGRAPH 1987. Ambiguous faces: G. M. Nielson, B. Hamann, "The Asymptotic Decider:
// Resolving the Ambiguity in Marching Cubes", IEEE Visualization 1991.
//
// Seeds: 000_3da000e866ebc485.txt (The Tomorrow Children, landscape rendering: the Layered Depth
// Cube was meshed with marching cubes for most of the project, "robust but" blobby, orientation
// dependent, throwing the stored normals away, until dual contouring replaced it) and
// 001_5c6096db92814698.txt (Dreams "Learning from Failure", SIGGRAPH 2015: the SDF was kept in 83^3
// fp16 blocks, each meshed with marching cubes in a compute shader with histopyramid compaction,
// abandoned for dense meshes, mushy edges and slivers). rtlab uses this technique as the baseline
// that dual contouring is measured against.
//
// Algorithm
// - Inside is f < iso, outside f >= iso, so a sample exactly on the iso-value is outside and every
//   edge has a definite sign pair. A crossed edge's vertex is placed on the linear interpolant's
//   zero (or the edge midpoint); when the outside end is exactly on the iso-value the vertex is
//   exactly that sample. NaN samples are rejected (std::invalid_argument, naming the sample);
//   +inf / -inf samples are valid (outside / inside) and give finite vertices at the finite end.
// - The case table is generated at first use (framework/isosurface/case_table.cpp, shared with
//   dual_contouring), not copied: per face, segments between the crossed edges, oriented with the
//   inside corners on the right seen from outside; segments chain into loops. Each loop gets its
//   minimum-length triangulation (diagonals measured between edge midpoints) among those that never
//   join two edges of an ambiguous face that no segment joins: such a diagonal lies in the face,
//   the neighbouring cell may use it as well, and the mesh edge would carry four triangles. Loops
//   with no such triangulation (116 of the 1026 loops in the table, all from mixed decisions that
//   only the asymptotic decider makes, at most one per cell) are fanned around an interior vertex
//   at the centroid of their edge vertices, as the marching cubes 33 tables do; interior vertices
//   are numbered after all edge vertices. Triangles wind counter-clockwise seen from the positive
//   side. Entries exist for every decision on every ambiguous face (1, 2, 4, ... 64 per corner
//   configuration).
// - Ambiguous faces (inside corners on a diagonal) are decided by the asymptotic decider on the
//   face's four values, or by a fixed rule. Either way the decision depends on the face alone,
//   which both cells sharing it see identically, so closed surfaces give closed meshes. Ambiguity
//   in the cell interior (tunnels) is not resolved: each loop becomes one disk.
// - One vertex per crossed grid edge, shared by the up to four cells around it. Vertices are
//   numbered in scan order (layer, row, sample, axis) from per-layer counts and a prefix sum;
//   triangles come in cell scan order. The output is identical for every thread count and grain.
// - TBB: pass 1 (inside flags, NaN check, per-layer counts) over sample layers, pass 2 over z-slabs
//   of `grain` cell layers; a slab numbers the vertices of its layers plus the one above it and
//   writes only its own.
// - Several vertices can coincide where crossings land on the same sample (a sample exactly on the
//   iso-value with two or more inside neighbours in one cell), giving zero-area triangles. They are
//   kept: the mesh stays a closed, consistently oriented 2-manifold combinatorially, and welding
//   them could pinch it. Metrics that need non-degenerate triangles must weld or filter.
//
// Parameters
// | name             | type | default    | range / choices                            | unit  |
// |------------------|------|------------|--------------------------------------------|-------|
// | grain            | int  | 8          | [1, 1024]                                  | cells |
// | vertex_placement | enum | linear     | {linear, midpoint}                         |       |
// | ambiguity        | enum | asymptotic | {asymptotic, separate_inside, join_inside} |       |
// | normals          | enum | gradient   | {gradient, none}                           |       |
// grain: cell layers per TBB task (performance only). vertex_placement: linear interpolation of
// the crossing or the edge midpoint. ambiguity: asymptotic decider, or never / always connect the
// inside corners of an ambiguous face. normals: central-difference gradient of the field
// interpolated along the edge and normalised, or no normals.
//
// Config:
//   techniques:
//     isosurface: {technique: marching_cubes, params: {vertex_placement: linear}}

#include "marching_cubes.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace rtlab::isosurface {
namespace {

constexpr std::int64_t kMinGrain = 1;
constexpr std::int64_t kMaxGrain = 1024;

const std::vector<std::string> kPlacementChoices = {"linear", "midpoint"};
const std::vector<std::string> kAmbiguityChoices = {"asymptotic", "separate_inside", "join_inside"};
const std::vector<std::string> kNormalChoices = {"gradient", "none"};

//! Index of `value` in `choices`; throws naming the parameter when it is not there.
std::size_t findChoice(const std::string& param, const std::string& value,
                       const std::vector<std::string>& choices)
{
    for (std::size_t i = 0; i < choices.size(); ++i) {
        if (choices[i] == value)
            return i;
    }
    throw std::invalid_argument("marching_cubes: parameter '" + param + "' has no choice '" +
                                value + "'");
}

} // namespace

plugin::TechniqueInfo MarchingCubes::describe()
{
    plugin::TechniqueInfo info;
    info.summary = "marching cubes with a generated case table, asymptotic decider on ambiguous "
                   "faces, shared edge vertices, TBB z-slabs";
    info.reference = "Lorensen & Cline 1987, Marching Cubes: A High Resolution 3D Surface "
                     "Construction Algorithm (SIGGRAPH); Nielson & Hamann 1991, The Asymptotic "
                     "Decider (IEEE Visualization)";
    info.seed = "000_3da000e866ebc485.txt (The Tomorrow Children landscape meshing), "
                "001_5c6096db92814698.txt (Dreams, Learning from Failure)";
    return info;
}

config::ParamSchema MarchingCubes::declareParams()
{
    config::ParamSchema schema;
    schema.addInt(
        "grain", 8, kMinGrain, kMaxGrain, "cells",
        "cell layers along z per TBB task (z-slab thickness); output does not depend on it");
    schema.addEnum(
        "vertex_placement", "linear", kPlacementChoices,
        "vertex on a crossed edge: zero of the linear interpolant, or the edge midpoint");
    schema.addEnum("ambiguity", "asymptotic", kAmbiguityChoices,
                   "ambiguous faces: asymptotic decider on the face values, or never / always "
                   "connect the inside corners");
    schema.addEnum("normals", "gradient", kNormalChoices,
                   "vertex normals: central-difference field gradient interpolated along the edge, "
                   "or none");
    return schema;
}

MarchingCubes::MarchingCubes(const config::ParamSet& params)
{
    const std::int64_t grain = params.getInt("grain");
    if (grain < kMinGrain || grain > kMaxGrain)
        throw std::invalid_argument("marching_cubes: grain " + std::to_string(grain) +
                                    " is outside [1, 1024]");
    mOptions.grain = static_cast<int>(grain);
    mOptions.placement =
        findChoice("vertex_placement", params.getString("vertex_placement"), kPlacementChoices) == 0
            ? mc::VertexPlacement::Linear
            : mc::VertexPlacement::Midpoint;
    constexpr mc::AmbiguityRule kRules[] = {mc::AmbiguityRule::Asymptotic,
                                            mc::AmbiguityRule::SeparateInside,
                                            mc::AmbiguityRule::JoinInside};
    mOptions.ambiguity =
        kRules[findChoice("ambiguity", params.getString("ambiguity"), kAmbiguityChoices)];
    mOptions.computeNormals =
        findChoice("normals", params.getString("normals"), kNormalChoices) == 0;
}

config::ParamSet MarchingCubes::effectiveParams() const
{
    config::ParamSet params;
    params.set("grain", std::int64_t(mOptions.grain));
    params.set("vertex_placement",
               kPlacementChoices[mOptions.placement == mc::VertexPlacement::Linear ? 0 : 1]);
    params.set("ambiguity", kAmbiguityChoices[std::size_t(mOptions.ambiguity)]);
    params.set("normals", kNormalChoices[mOptions.computeNormals ? 0 : 1]);
    return params;
}

void MarchingCubes::extract(const plugin::IsosurfaceInput& input, TriangleMesh& out)
{
    if (input.field == nullptr)
        throw std::invalid_argument("marching_cubes: IsosurfaceInput::field is null");
    // The exact field and gradient (Hermite data) are not used: marching cubes sees only samples.
    mc::extractIsosurface(*input.field, input.isoValue, mOptions, out);
}

} // namespace rtlab::isosurface

RTLAB_REGISTER_TECHNIQUE(isosurface, marching_cubes, rtlab::isosurface::MarchingCubes)
