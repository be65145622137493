#include "scene/sdf_mesher.h"
#include "scene/sdf_mesher_state.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>

namespace rtlab::scene {

namespace {

// Cells an edit's reach adds around its primitive (findEditReach: 2 sqrt(3) cells times a
// Lipschitz constant up to 2).
constexpr double kReachCells = 7.0;

} // namespace

double getSdfCellSize(const SdfModel& model, int resolution)
{
    const glm::dvec3 extent = model.boundsMax - model.boundsMin;
    return std::max({extent.x, extent.y, extent.z}) / double(std::max(resolution, 1));
}

bool findEditReach(const SdfModel& model, const CsgEdit& edit, int resolution, glm::dvec3& lo,
                   glm::dvec3& hi)
{
    if (edit.op == CsgOp::Intersect || edit.shape == CsgShape::Ellipsoid)
        return false;
    edit.getBounds(lo, hi);
    // The Newton steps' gradient stencil (csg.cpp evaluateGradient) reaches a little farther.
    const double stencil = 1e-5 * std::max(1.0, glm::length(model.boundsMax - model.boundsMin));
    const double margin =
        std::max(edit.blend, 0.0) + kReachCells * getSdfCellSize(model, resolution) + stencil;
    lo -= margin;
    hi += margin;
    return true;
}


void SdfMesher::State::meshAll(int frame)
{
    raw.resize(std::size_t(samples.x) * samples.y * samples.z);
    values.resize(raw.size());
    tbb::parallel_for(0, samples.z, [&](int z) {
        for (int y = 0; y < samples.y; ++y)
            for (int x = 0; x < samples.x; ++x) {
                const std::size_t i = sampleIndex(x, y, z);
                raw[i] = model->evaluate(position(x, y, z), frame);
                values[i] = padded(raw[i], x, y, z);
            }
    });
    auto& positions = mesh.mesh.positions;
    positions.clear();
    vertexCell.clear();
    cellVertex.assign(std::size_t(cells.x) * cells.y * cells.z, kNone);
    for (int z = 0; z < cells.z; ++z)
        for (int y = 0; y < cells.y; ++y)
            for (int x = 0; x < cells.x; ++x) {
                glm::vec3 p;
                if (!computeVertex(x, y, z, frame, p))
                    continue;
                const std::size_t c = cellIndex(x, y, z);
                cellVertex[c] = std::uint32_t(positions.size());
                vertexCell.push_back(std::uint32_t(c));
                positions.push_back(p);
            }

    auto& indices = mesh.mesh.indices;
    indices.clear();
    quadEdge.clear();
    edgeQuad.assign(3 * raw.size(), kNone);
    for (int axis = 0; axis < 3; ++axis)
        for (int z = 0; z < samples.z; ++z)
            for (int y = 0; y < samples.y; ++y)
                for (int x = 0; x < samples.x; ++x) {
                    std::uint32_t tri[6];
                    const glm::ivec3 p0(x, y, z);
                    if (!computeQuad(axis, p0, tri))
                        continue;
                    const std::size_t e = edgeIndex(axis, p0);
                    edgeQuad[e] = std::uint32_t(quadEdge.size());
                    quadEdge.push_back(std::uint32_t(e));
                    indices.insert(indices.end(), tri, tri + 6);
                }

    // The incremental update's marks, touched here once rather than on a dig frame.
    cellStamp.assign(cellVertex.size(), 0u);
    edgeStamp.assign(edgeQuad.size(), 0u);
    vertexStamp.assign(positions.size(), 0u);

    mesh.mesh.normals.resize(positions.size());
    tbb::parallel_for(std::size_t(0), positions.size(), [&](std::size_t i) {
        mesh.mesh.normals[i] = glm::vec3(model->evaluateGradient(glm::dvec3(positions[i]), frame));
    });
    mesh.triangleMaterial.resize(indices.size() / 3);
    tbb::parallel_for(std::size_t(0), mesh.triangleMaterial.size(),
                      [&](std::size_t t) {
                          mesh.triangleMaterial[t] = computeMaterial(
                              positions[indices[3 * t]], positions[indices[3 * t + 1]],
                              positions[indices[3 * t + 2]], frame);
                      });
}


SdfMesher::SdfMesher(const SdfModel& model, const SdfMeshOptions& options)
    : mState(std::make_unique<State>())
{
    if (options.resolution < 4 || options.resolution > 2048)
        throw std::invalid_argument("SDF mesh resolution must be in [4, 2048]");
    const glm::dvec3 extent = model.boundsMax - model.boundsMin;
    const double longest = std::max({extent.x, extent.y, extent.z});
    if (!(longest > 0.0) || !std::isfinite(longest))
        throw std::invalid_argument("SDF model '" + model.name + "' has empty or non-finite bounds");
    State& s = *mState;
    s.model = &model;
    s.options = options;
    s.spacing = longest / options.resolution;
    s.cells = glm::ivec3(glm::ceil(extent / s.spacing)) + 2; // one padding cell per side
    s.samples = s.cells + 1;
    s.origin = model.boundsMin - glm::dvec3(s.spacing);
}

SdfMesher::~SdfMesher() = default;
SdfMesher::SdfMesher(SdfMesher&&) noexcept = default;
SdfMesher& SdfMesher::operator=(SdfMesher&&) noexcept = default;

const SdfMesh& SdfMesher::getMesh() const { return mState->mesh; }

int SdfMesher::getMeshedFrame() const { return mState->meshedFrame; }

SdfMeshChange SdfMesher::update(int frame, bool full)
{
    State& s = *mState;
    SdfMeshChange change;
    change.cellCount = std::size_t(s.cells.x) * s.cells.y * s.cells.z;
    const auto& edits = s.model->edits;
    std::string why;
    std::vector<const CsgEdit*> added;
    std::vector<std::pair<glm::dvec3, glm::dvec3>> reach;
    if (s.meshedFrame == kNotMeshed) {
        why = "first meshing";
    } else if (full) {
        why = "asked for in full";
    } else {
        std::ptrdiff_t lastApplied = -1;
        for (std::size_t i = 0; i < edits.size(); ++i)
            if (edits[i].frame <= s.meshedFrame)
                lastApplied = std::ptrdiff_t(i);
        for (std::size_t i = 0; i < edits.size() && why.empty(); ++i) {
            const bool was = edits[i].frame <= s.meshedFrame, now = edits[i].frame <= frame;
            if (was && !now)
                why = "edit " + std::to_string(i) + " (frame " + std::to_string(edits[i].frame) +
                      ") is not applied at frame " + std::to_string(frame);
            else if (!was && now && std::ptrdiff_t(i) < lastApplied)
                why = "edit " + std::to_string(i) + " (frame " + std::to_string(edits[i].frame) +
                      ") comes before an applied edit in the list";
            else if (!was && now)
                added.push_back(&edits[i]);
        }
        for (std::size_t k = 0; k < added.size() && why.empty(); ++k) {
            glm::dvec3 lo, hi;
            if (!findEditReach(*s.model, *added[k], s.options.resolution, lo, hi))
                why = std::string("edit ") + std::to_string(added[k] - edits.data()) + " (" +
                      toString(added[k]->shape) + " " + toString(added[k]->op) +
                      ") has no bounded reach";
            reach.emplace_back(lo, hi);
        }
    }
    if (!why.empty()) {
        s.meshAll(frame);
        s.meshedFrame = frame;
        change.changed = change.full = true;
        change.cellsMeshed = change.cellCount;
        change.samplesChanged = s.raw.size();
        change.what = "meshed in full (" + why + ")";
        for (const glm::vec3& p : s.mesh.mesh.positions)
            growBox(change.changedMin, change.changedMax, p);
        return change;
    }
    s.meshedFrame = frame;
    if (added.empty()) {
        change.what = "no new edit";
        return change;
    }
    s.meshIncrementally(frame, added, reach, change);
    change.what = "re-meshed " + std::to_string(change.cellsMeshed) + " of " +
                  std::to_string(change.cellCount) + " cells for " + std::to_string(added.size()) +
                  " new edit" + (added.size() == 1 ? "" : "s") +
                  (change.changed ? "" : " (the mesh did not change)");
    return change;
}

SdfMesh meshSdfModel(const SdfModel& model, const SdfMeshOptions& options)
{
    SdfMesher mesher(model, options);
    mesher.update(options.frame);
    return mesher.getMesh();
}

} // namespace rtlab::scene
