// vtk_flying_edges: VTK's vtkFlyingEdges3D as an isosurface baseline.
//
// Registry key: isosurface/vtk_flying_edges
//
// Paper: W. Schroeder, R. Maynard, B. Geveci, "Flying Edges: A High-Performance Scalable
// Isocontouring Algorithm", IEEE LDAV 2015. Implementation: VTK 9.1 (Debian 12, libvtk9-dev),
// vtkFlyingEdges3D. rtlab compares its own meshers with it on the very same sampled grids
// (throughput ratios and error side by side); nothing of the algorithm is reimplemented here.
//
// Algorithm (inside VTK, [Schroeder et al. 2015]): pass 1 classifies the x-edges of every grid row
// and records where each row's crossings start and end; pass 2 classifies the y- and z-edges of
// each row pair inside those trimmed ranges and counts points and triangles per row; pass 3 is a
// prefix sum over rows that gives every row its output offsets; pass 4 walks the rows again and
// writes points (one per crossed edge, so the output is indexed and shared) and triangles from
// the marching cubes case table. Passes 1, 2 and 4 are parallel over rows / slices (vtkSMPTools).
//
// This wrapper
// - Wraps SampledField::values in a vtkFloatArray without copying (SetArray with save = 1: VTK
//   never frees or writes it) as the point scalars of a vtkImageData with the field's sample
//   counts, origin (0, 0, 0) and spacing 1. The filter therefore works in index space, where
//   float coordinates are exact to 2^-24 of the grid extent at any world scale; the conversion maps
//   each point to origin + spacing * p in double.
// - Runs vtkFlyingEdges3D at input.isoValue (one contour value; no scalars, no gradients).
// - Converts the vtkPolyData to TriangleMesh: positions (index -> world), triangles with two
//   indices swapped and normals negated. VTK's triangles wind clockwise seen from the positive
//   side and its normals (the central-difference gradient, normalised) point toward decreasing
//   values, i.e. inward for an SDF; rtlab wants both outward. The unit tests check the result
//   (enclosed volume positive, normals radial).
// - The call's time includes the conversion (it is part of producing a TriangleMesh); counters
//   split it: filter_ms (vtkFlyingEdges3D::Update) and convert_ms (copy, index -> world, winding,
//   normals; TBB over points and triangles).
// - Fewer than 2 samples along an axis gives an empty mesh. Samples are not checked for NaN: VTK's
//   comparisons decide. Null field, a value count that does not match the sample counts, or a
//   non-finite iso-value, origin or spacing throw std::invalid_argument.
//
// Threads. Debian 12's VTK 9.1 is built with the vtkSMPTools backends TBB (the default),
// STDThread and Sequential; vtkSMPTools::GetBackend() returns "TBB". The thread count is set with
// vtkSMPTools::Initialize(n): with TBB, n > 0 makes VTK run its loops inside a task arena of
// concurrency n, n = 0 removes that arena (loops then use the caller's arena: all hardware threads
// by default). It is process-wide state, so this technique calls it before every extraction with
// its own `threads`. The conversion runs in a task arena of the same concurrency.
//
// Parameters
// | name    | type | default  | range / choices  | unit    |
// |---------|------|----------|------------------|---------|
// | threads | int  | 0        | [0, 1024]        | threads |
// | normals | enum | gradient | {gradient, none} |         |
// threads: vtkSMPTools::Initialize(threads) before the filter, 0 = all hardware threads.
// normals: VTK's central-difference gradient normals (ComputeNormals), flipped outward; or none.
//
// Counters: filter_ms, convert_ms (milliseconds of the last call), smp_threads
// (vtkSMPTools::GetEstimatedNumberOfThreads() during the call), smp_backend (0 Sequential,
// 1 STDThread, 2 TBB, 3 OpenMP).
//
// Config:
//   techniques:
//     isosurface: {technique: vtk_flying_edges, params: {threads: 0}}

#include "vtk_flying_edges.h"

#include "smp_control.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTypeInt32Array.h>
#include <vtkTypeInt64Array.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rtlab::isosurface {
namespace {

constexpr std::int64_t kMaxThreads = 1024;
const std::vector<std::string> kNormalChoices = {"gradient", "none"};

using Clock = std::chrono::steady_clock;

double getMilliseconds(Clock::time_point from, Clock::time_point to)
{
    return std::chrono::duration<double, std::milli>(to - from).count();
}

//! Triangles of `polys` into out.indices, winding reversed ((a, b, c) -> (a, c, b)).
template <class IdArray>
void copyReversedTriangles(IdArray* connectivity, std::size_t triangleCount,
                           std::vector<std::uint32_t>& indices)
{
    const auto* ids = connectivity->GetPointer(0);
    indices.resize(3 * triangleCount);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangleCount, 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t t = r.begin(); t != r.end(); ++t) {
                              indices[3 * t] = std::uint32_t(ids[3 * t]);
                              indices[3 * t + 1] = std::uint32_t(ids[3 * t + 2]);
                              indices[3 * t + 2] = std::uint32_t(ids[3 * t + 1]);
                          }
                      });
}

void convertPolyData(vtkPolyData* poly, const plugin::SampledField& field, bool normals,
                     TriangleMesh& out)
{
    out.clear();
    const vtkIdType pointCount = poly->GetNumberOfPoints();
    if (pointCount == 0)
        return;
    if (pointCount > vtkIdType(UINT32_MAX))
        throw std::runtime_error("vtk_flying_edges: " + std::to_string(pointCount) +
                                 " points do not fit 32-bit indices");
    auto* points = vtkFloatArray::FastDownCast(poly->GetPoints()->GetData());
    if (points == nullptr)
        throw std::logic_error("vtk_flying_edges: vtkFlyingEdges3D returned non-float points");
    const float* p = points->GetPointer(0);
    const float* n = nullptr;
    if (normals) {
        auto* normalArray = vtkFloatArray::FastDownCast(poly->GetPointData()->GetNormals());
        if (normalArray == nullptr)
            throw std::logic_error("vtk_flying_edges: vtkFlyingEdges3D returned no float normals");
        n = normalArray->GetPointer(0);
    }
    out.positions.resize(std::size_t(pointCount));
    if (n != nullptr)
        out.normals.resize(std::size_t(pointCount));
    const glm::dvec3 origin = field.origin;
    const double spacing = field.spacing;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, std::size_t(pointCount), 4096),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t i = r.begin(); i != r.end(); ++i) {
                              const glm::dvec3 index(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
                              out.positions[i] = glm::vec3(origin + spacing * index);
                              if (n != nullptr)
                                  out.normals[i] = -glm::vec3(n[3 * i], n[3 * i + 1], n[3 * i + 2]);
                          }
                      });

    vtkCellArray* polys = poly->GetPolys();
    const std::size_t triangleCount = std::size_t(polys->GetNumberOfCells());
    if (std::size_t(polys->GetNumberOfConnectivityIds()) != 3 * triangleCount)
        throw std::logic_error("vtk_flying_edges: vtkFlyingEdges3D returned non-triangle cells");
    if (polys->IsStorage64Bit())
        copyReversedTriangles(polys->GetConnectivityArray64(), triangleCount, out.indices);
    else
        copyReversedTriangles(polys->GetConnectivityArray32(), triangleCount, out.indices);
}

void checkInput(const plugin::IsosurfaceInput& input)
{
    if (input.field == nullptr)
        throw std::invalid_argument("vtk_flying_edges: IsosurfaceInput::field is null");
    const plugin::SampledField& field = *input.field;
    const glm::ivec3 s = field.samples;
    if (s.x < 0 || s.y < 0 || s.z < 0 ||
        field.values.size() != std::size_t(s.x) * std::size_t(s.y) * std::size_t(s.z))
        throw std::invalid_argument("vtk_flying_edges: " + std::to_string(field.values.size()) +
                                    " values for " + std::to_string(s.x) + " x " +
                                    std::to_string(s.y) + " x " + std::to_string(s.z) +
                                    " samples");
    if (!std::isfinite(input.isoValue) || !std::isfinite(field.spacing) ||
        !std::isfinite(field.origin.x) || !std::isfinite(field.origin.y) ||
        !std::isfinite(field.origin.z))
        throw std::invalid_argument(
            "vtk_flying_edges: iso-value, spacing and origin must be finite");
    // Flying Edges turns non-finite samples into NaN vertices.
    plugin::requireFiniteSamples(*input.field, "vtk_flying_edges");
}

} // namespace

plugin::TechniqueInfo VtkFlyingEdges::describe()
{
    plugin::TechniqueInfo info;
    info.summary = "baseline: VTK 9.1 vtkFlyingEdges3D on the sampled grid (zero-copy input, "
                   "vtkSMPTools/TBB), converted to an outward-wound TriangleMesh";
    info.reference = "Schroeder, Maynard & Geveci 2015, Flying Edges: A High-Performance "
                     "Scalable Isocontouring Algorithm (IEEE LDAV); VTK vtkFlyingEdges3D";
    return info;
}

config::ParamSchema VtkFlyingEdges::declareParams()
{
    config::ParamSchema schema;
    schema.addInt("threads", 0, 0, kMaxThreads, "threads",
                  "vtkSMPTools::Initialize(threads) before the filter (TBB backend: a task arena "
                  "of that size); 0 = all hardware threads");
    schema.addEnum("normals", "gradient", kNormalChoices,
                   "vertex normals: VTK's central-difference gradient normals flipped outward, or "
                   "none");
    return schema;
}

VtkFlyingEdges::VtkFlyingEdges(const config::ParamSet& params)
{
    const std::int64_t threads = params.getInt("threads");
    if (threads < 0 || threads > kMaxThreads)
        throw std::invalid_argument("vtk_flying_edges: threads " + std::to_string(threads) +
                                    " is outside [0, 1024]");
    mThreads = int(threads);
    const std::string& normals = params.getString("normals");
    if (normals != kNormalChoices[0] && normals != kNormalChoices[1])
        throw std::invalid_argument("vtk_flying_edges: parameter 'normals' has no choice '" +
                                    normals + "'");
    mComputeNormals = normals == kNormalChoices[0];
    mSmpBackend = vtk::getSmpBackend();
}

config::ParamSet VtkFlyingEdges::effectiveParams() const
{
    config::ParamSet params;
    params.set("threads", std::int64_t(mThreads));
    params.set("normals", kNormalChoices[mComputeNormals ? 0 : 1]);
    return params;
}

std::vector<std::pair<std::string, double>> VtkFlyingEdges::counters() const
{
    return {{"filter_ms", mFilterMs},
            {"convert_ms", mConvertMs},
            {"smp_threads", double(mSmpThreads)},
            {"smp_backend", vtk::getSmpBackendCode(mSmpBackend)}};
}

void VtkFlyingEdges::extract(const plugin::IsosurfaceInput& input, TriangleMesh& out)
{
    checkInput(input);
    const plugin::SampledField& field = *input.field;
    mFilterMs = 0.0;
    mConvertMs = 0.0;
    vtk::initializeSmp(mThreads);
    mSmpThreads = vtk::getSmpThreadEstimate();
    const glm::ivec3 s = field.samples;
    if (s.x < 2 || s.y < 2 || s.z < 2) {
        out.clear();
        return;
    }

    const Clock::time_point start = Clock::now();
    vtkNew<vtkFloatArray> scalars;
    scalars->SetNumberOfComponents(1);
    // save = 1: the array neither frees nor writes the caller's buffer.
    scalars->SetArray(const_cast<float*>(field.values.data()), vtkIdType(field.values.size()), 1);
    vtkNew<vtkImageData> image;
    image->SetDimensions(s.x, s.y, s.z);
    image->SetOrigin(0.0, 0.0, 0.0);
    image->SetSpacing(1.0, 1.0, 1.0);
    image->GetPointData()->SetScalars(scalars);

    // [Schroeder et al. 2015]: the four passes over rows run inside Update().
    vtkNew<vtkFlyingEdges3D> filter;
    filter->SetInputData(image);
    filter->SetNumberOfContours(1);
    filter->SetValue(0, input.isoValue);
    filter->SetComputeNormals(mComputeNormals);
    filter->SetComputeGradients(false);
    filter->SetComputeScalars(false);
    filter->SetInterpolateAttributes(false);
    filter->Update();
    const Clock::time_point filtered = Clock::now();

    const auto convert = [&] { convertPolyData(filter->GetOutput(), field, mComputeNormals, out); };
    if (mThreads > 0)
        tbb::task_arena(mThreads).execute(convert);
    else
        convert();
    const Clock::time_point converted = Clock::now();
    mFilterMs = getMilliseconds(start, filtered);
    mConvertMs = getMilliseconds(filtered, converted);
}

} // namespace rtlab::isosurface

RTLAB_REGISTER_TECHNIQUE(isosurface, vtk_flying_edges, rtlab::isosurface::VtkFlyingEdges)
