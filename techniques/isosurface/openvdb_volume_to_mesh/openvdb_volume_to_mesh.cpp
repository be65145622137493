// openvdb_volume_to_mesh: OpenVDB's tools::volumeToMesh as an isosurface baseline.
//
// Registry key: isosurface/openvdb_volume_to_mesh
//
// Paper: K. Museth, "VDB: High-Resolution Sparse Volumes with Dynamic Topology", ACM Transactions
// on Graphics 32(3), 2013 (the data structure); the mesher is OpenVDB's tools::VolumeToMesh
// (OpenVDB 10.0.1, Debian 12 libopenvdb-dev). rtlab compares its own meshers with it on the very
// same sampled grids; nothing of the algorithm is reimplemented here.
//
// Algorithm (inside OpenVDB): a dual mesher. Voxels (cells of 2x2x2 samples) whose corners
// straddle the iso-value get one point per connected group of crossed edges (the marching cubes
// edge groups, so a voxel crossed by two sheets gets two points), placed at the mean of the
// group's linear edge crossings; every crossed grid edge gives one quad joining the points of the
// four voxels around it. With adaptivity > 0, points of neighbouring voxels whose normals agree
// within the threshold are merged, and the quads of merged regions become fewer, larger quads and
// triangles. Everything runs in TBB over leaf nodes (8^3 voxels).
//
// This wrapper
// - Grid: openvdb::FloatGrid with the identity transform (index space), background +1e18, filled
//   from the samples by tools::copyFromDense over a tools::Dense view (LayoutXYZ, x fastest) of
//   SampledField::values, without an intermediate copy, tolerance 0: every sample becomes an active
//   voxel (full dense copy, not a narrow band). A narrow band is not offered: samples left out
//   would read the positive background, which turns the deep inside of a solid into outside.
// - The grid's outside is +1e18, so a surface that leaves the sampled box is closed there: the
//   crossing between a boundary sample and the background lies on the boundary sample (relative
//   offset |f| / 1e18, below float resolution), and the voxels beyond the boundary get their points
//   on the boundary faces. Surfaces inside the box are not affected; open ones come back capped
//   along the box faces (marching cubes leaves them open). 1e18 keeps differences and squares of
//   values finite in float; |isoValue| must stay below 1e15 (else std::invalid_argument).
// - tools::volumeToMesh(grid, points, triangles, quads, isoValue, adaptivity) (relaxation of
//   disoriented triangles on, OpenVDB's default).
// - Conversion: index -> world (origin + spacing * p, in double), each quad split along its
//   shorter diagonal, adaptive triangles kept. OpenVDB's polygons already wind counter-clockwise
//   seen from the positive side (tests: enclosed volume positive); no normals are produced.
// - Timing: the call includes grid build, meshing and conversion; counters split them.
// - Fewer than 2 samples along an axis gives an empty mesh; samples are not checked for NaN.
//   Null field, a value count that does not match the sample counts, or a non-finite iso-value,
//   origin or spacing throw std::invalid_argument.
//
// Threads: OpenVDB uses TBB; the whole call (grid build, meshing, conversion) runs inside a
// tbb::task_arena of `threads` slots (0: the caller's arena, all hardware threads by default). An
// arena limits this call only; tbb::global_control would also cap every other TBB user of the
// process while it lives.
//
// Parameters
// | name       | type  | default | range     | unit    |
// |------------|-------|---------|-----------|---------|
// | adaptivity | float | 0       | [0, 1]    |         |
// | threads    | int   | 0       | [0, 1024] | threads |
// adaptivity: OpenVDB's surface adaptivity threshold; 0 gives the uniform dual mesh (one point per
// voxel edge group, quads only), larger values merge flat regions into fewer polygons.
// threads: TBB concurrency of the call, 0 = all hardware threads.
//
// Counters: grid_ms (copyFromDense), mesh_ms (volumeToMesh), convert_ms (world mapping, quad
// split), active_voxels, quads, triangles (OpenVDB's polygon counts before the split).
//
// Config:
//   techniques:
//     isosurface: {technique: openvdb_volume_to_mesh, params: {adaptivity: 0.0}}

#include "openvdb_volume_to_mesh.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <mutex>
#include <stdexcept>
#include <string>

namespace rtlab::isosurface {
namespace {

constexpr std::int64_t kMaxThreads = 1024;
//! Value of every voxel outside the sampled box (outside the surface).
constexpr float kBackground = 1e18f;
//! Bound on |isoValue|, far below the background.
constexpr double kMaxIsoValue = 1e15;

using Clock = std::chrono::steady_clock;

double getMilliseconds(Clock::time_point from, Clock::time_point to)
{
    return std::chrono::duration<double, std::milli>(to - from).count();
}

void initializeOpenVdb()
{
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

void checkInput(const plugin::IsosurfaceInput& input)
{
    if (input.field == nullptr)
        throw std::invalid_argument("openvdb_volume_to_mesh: IsosurfaceInput::field is null");
    const plugin::SampledField& field = *input.field;
    const glm::ivec3 s = field.samples;
    if (s.x < 0 || s.y < 0 || s.z < 0 ||
        field.values.size() != std::size_t(s.x) * std::size_t(s.y) * std::size_t(s.z))
        throw std::invalid_argument("openvdb_volume_to_mesh: " +
                                    std::to_string(field.values.size()) + " values for " +
                                    std::to_string(s.x) + " x " + std::to_string(s.y) + " x " +
                                    std::to_string(s.z) + " samples");
    if (!std::isfinite(input.isoValue) || !std::isfinite(field.spacing) ||
        !std::isfinite(field.origin.x) || !std::isfinite(field.origin.y) ||
        !std::isfinite(field.origin.z))
        throw std::invalid_argument(
            "openvdb_volume_to_mesh: iso-value, spacing and origin must be finite");
    if (std::abs(input.isoValue) >= kMaxIsoValue)
        throw std::invalid_argument("openvdb_volume_to_mesh: |iso-value| must be below 1e15 (the "
                                    "grid's background is 1e18)");
    // volumeToMesh refuses non-finite samples with openvdb::ValueError, which is not ours.
    plugin::requireFiniteSamples(*input.field, "openvdb_volume_to_mesh");
}

//! World positions and triangles from OpenVDB's index-space points and polygons.
void convertPolygons(const std::vector<openvdb::Vec3s>& points,
                     const std::vector<openvdb::Vec3I>& triangles,
                     const std::vector<openvdb::Vec4I>& quads, const plugin::SampledField& field,
                     TriangleMesh& out)
{
    out.clear();
    out.positions.resize(points.size());
    const glm::dvec3 origin = field.origin;
    const double spacing = field.spacing;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i) {
                              const glm::dvec3 index(points[i].x(), points[i].y(), points[i].z());
                              out.positions[i] = glm::vec3(origin + spacing * index);
                          }
                      });
    out.indices.resize(3 * (triangles.size() + 2 * quads.size()));
    std::uint32_t* dst = out.indices.data();
    for (const openvdb::Vec3I& t : triangles) {
        *dst++ = t[0];
        *dst++ = t[1];
        *dst++ = t[2];
    }
    // Split each quad (a, b, c, d) along its shorter diagonal, keeping its winding.
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, quads.size(), 4096),
        [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t q = r.begin(); q != r.end(); ++q) {
                const openvdb::Vec4I& v = quads[q];
                std::uint32_t* t = dst + 6 * q;
                if ((points[v[0]] - points[v[2]]).lengthSqr() <=
                    (points[v[1]] - points[v[3]]).lengthSqr()) {
                    t[0] = v[0], t[1] = v[1], t[2] = v[2];
                    t[3] = v[0], t[4] = v[2], t[5] = v[3];
                } else {
                    t[0] = v[0], t[1] = v[1], t[2] = v[3];
                    t[3] = v[1], t[4] = v[2], t[5] = v[3];
                }
            }
        });
}

} // namespace

plugin::TechniqueInfo OpenVdbVolumeToMesh::describe()
{
    plugin::TechniqueInfo info;
    info.summary = "baseline: OpenVDB 10 tools::volumeToMesh (dual mesher, optional adaptivity) "
                   "on a FloatGrid copied from the samples, quads split into triangles";
    info.reference = "Museth 2013, VDB: High-Resolution Sparse Volumes with Dynamic Topology "
                     "(ACM TOG 32(3)); OpenVDB tools::VolumeToMesh";
    return info;
}

config::ParamSchema OpenVdbVolumeToMesh::declareParams()
{
    config::ParamSchema schema;
    schema.addFloat("adaptivity", 0.0, 0.0, 1.0, "",
                    "OpenVDB surface adaptivity threshold: 0 = uniform dual mesh (quads only), "
                    "larger merges flat regions into fewer polygons");
    schema.addInt("threads", 0, 0, kMaxThreads, "threads",
                  "TBB concurrency of the call (a task arena); 0 = all hardware threads");
    return schema;
}

OpenVdbVolumeToMesh::OpenVdbVolumeToMesh(const config::ParamSet& params)
{
    mAdaptivity = params.getFloat("adaptivity");
    if (!(mAdaptivity >= 0.0 && mAdaptivity <= 1.0))
        throw std::invalid_argument("openvdb_volume_to_mesh: adaptivity " +
                                    std::to_string(mAdaptivity) + " is outside [0, 1]");
    const std::int64_t threads = params.getInt("threads");
    if (threads < 0 || threads > kMaxThreads)
        throw std::invalid_argument("openvdb_volume_to_mesh: threads " + std::to_string(threads) +
                                    " is outside [0, 1024]");
    mThreads = int(threads);
    initializeOpenVdb();
}

config::ParamSet OpenVdbVolumeToMesh::effectiveParams() const
{
    config::ParamSet params;
    params.set("adaptivity", mAdaptivity);
    params.set("threads", std::int64_t(mThreads));
    return params;
}

std::vector<std::pair<std::string, double>> OpenVdbVolumeToMesh::counters() const
{
    return {{"grid_ms", mGridMs},           {"mesh_ms", mMeshMs}, {"convert_ms", mConvertMs},
            {"active_voxels", mActiveVoxels}, {"quads", mQuads},    {"triangles", mTriangles}};
}

void OpenVdbVolumeToMesh::extract(const plugin::IsosurfaceInput& input, TriangleMesh& out)
{
    checkInput(input);
    const plugin::SampledField& field = *input.field;
    mGridMs = mMeshMs = mConvertMs = 0.0;
    mActiveVoxels = mQuads = mTriangles = 0.0;
    const glm::ivec3 s = field.samples;
    if (s.x < 2 || s.y < 2 || s.z < 2) {
        out.clear();
        return;
    }

    const auto run = [&] {
        const Clock::time_point start = Clock::now();
        openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(kBackground);
        const openvdb::CoordBBox box(openvdb::Coord(0, 0, 0),
                                     openvdb::Coord(s.x - 1, s.y - 1, s.z - 1));
        // A view of the caller's buffer (x fastest); copyFromDense only reads it.
        const openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(
            box, const_cast<float*>(field.values.data()));
        openvdb::tools::copyFromDense(dense, *grid, 0.0f);
        const Clock::time_point built = Clock::now();

        std::vector<openvdb::Vec3s> points;
        std::vector<openvdb::Vec3I> triangles;
        std::vector<openvdb::Vec4I> quads;
        openvdb::tools::volumeToMesh(*grid, points, triangles, quads, input.isoValue, mAdaptivity);
        const Clock::time_point meshed = Clock::now();

        if (points.size() > std::size_t(UINT32_MAX))
            throw std::runtime_error("openvdb_volume_to_mesh: too many points for 32-bit indices");
        convertPolygons(points, triangles, quads, field, out);
        const Clock::time_point converted = Clock::now();
        mGridMs = getMilliseconds(start, built);
        mMeshMs = getMilliseconds(built, meshed);
        mConvertMs = getMilliseconds(meshed, converted);
        mActiveVoxels = double(grid->activeVoxelCount());
        mQuads = double(quads.size());
        mTriangles = double(triangles.size());
    };
    if (mThreads > 0)
        tbb::task_arena(mThreads).execute(run);
    else
        run();
}

} // namespace rtlab::isosurface

RTLAB_REGISTER_TECHNIQUE(isosurface, openvdb_volume_to_mesh,
                         rtlab::isosurface::OpenVdbVolumeToMesh)
