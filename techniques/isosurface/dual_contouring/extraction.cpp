#include "passes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <stdexcept>
#include <string>

namespace rtlab::isosurface::dc {

namespace detail {

//! Splits quad (v0, v1, v2, v3) into two triangles. Rule: the diagonal whose two triangles'
//! unit normals agree best (largest dot product), which never folds a planar non-convex quad and
//! follows the crease of a bent one; a tie (|difference| <= 1e-12, e.g. planar convex quads)
//! takes the diagonal through the quad's smallest vertex index, which does not depend on where
//! the quad's cycle starts. Returns true for the diagonal v1-v3.
bool chooseDiagonal13(const std::array<std::uint32_t, 4>& q, const std::array<glm::dvec3, 4>& p)
{
    const auto normal = [&](int a, int b, int c) { return glm::cross(p[b] - p[a], p[c] - p[a]); };
    // The cosine between two triangle normals from their unnormalised cross products (two square
    // roots per pair instead of four normalisations); 0 where a triangle is degenerate.
    const auto agree = [](const glm::dvec3& m, const glm::dvec3& n) {
        const double lengths = std::sqrt(glm::dot(m, m)) * std::sqrt(glm::dot(n, n));
        return lengths > 0.0 && std::isfinite(lengths) ? glm::dot(m, n) / lengths : 0.0;
    };
    const glm::dvec3 a012 = normal(0, 1, 2), a023 = normal(0, 2, 3);
    const glm::dvec3 a013 = normal(0, 1, 3), a123 = normal(1, 2, 3);
    // Most quads are decided without a square root or a division: with the cosines c = d / sqrt(L)
    // (d the dot product of the two normals, L the product of their squared lengths), c |c| =
    // d |d| / L is monotonic in c and |c13 - c02| >= |c13 |c13| - c02 |c02|| / 2, so where the
    // cross-multiplied difference exceeds 3e-12 (1e-12 twice, and a margin for rounding) the
    // cosines differ by more than the tie tolerance and the sign decides. Degenerate triangles
    // and near-ties take the exact path below.
    {
        const double d02 = glm::dot(a012, a023), l02 = glm::dot(a012, a012) * glm::dot(a023, a023);
        const double d13 = glm::dot(a013, a123), l13 = glm::dot(a013, a013) * glm::dot(a123, a123);
        if (l02 > 0.0 && l13 > 0.0 && std::isfinite(l02 * l13)) {
            const double difference = d13 * std::abs(d13) * l02 - d02 * std::abs(d02) * l13;
            if (std::abs(difference) > 3e-12 * l02 * l13)
                return difference > 0.0;
            // Planar convex quads (flat faces): both cosines within 0.4e-12 of 1 (c^2 >= 1 -
            // 0.8e-12), so they differ by less than the tolerance: a tie, without the exact path.
            constexpr double kNearOne = 1.0 - 0.8e-12;
            if (d02 > 0.0 && d13 > 0.0 && d02 * d02 >= kNearOne * l02 &&
                d13 * d13 >= kNearOne * l13)
                return (std::min_element(q.begin(), q.end()) - q.begin()) % 2 == 1;
        }
    }
    const double agree02 = agree(a012, a023);
    const double agree13 = agree(a013, a123);
    if (std::abs(agree02 - agree13) > 1e-12)
        return agree13 > agree02;
    const int smallest = int(std::min_element(q.begin(), q.end()) - q.begin());
    return smallest % 2 == 1;
}

} // namespace detail

namespace {

using namespace detail;

void validate(const plugin::IsosurfaceInput& input)
{
    if (input.field == nullptr)
        throw std::invalid_argument("dual_contouring: IsosurfaceInput::field is null");
    const plugin::SampledField& field = *input.field;
    if (!(std::isfinite(field.spacing) && field.spacing > 0.0))
        throw std::invalid_argument(
            "dual_contouring: the field spacing must be finite and > 0, got " +
            std::to_string(field.spacing));
    if (!isFinite(field.origin))
        throw std::invalid_argument("dual_contouring: the field origin must be finite");
    if (field.samples.x < 0 || field.samples.y < 0 || field.samples.z < 0)
        throw std::invalid_argument("dual_contouring: negative sample count");
    const std::size_t expected = std::size_t(field.samples.x) * field.samples.y * field.samples.z;
    if (field.values.size() != expected)
        throw std::invalid_argument("dual_contouring: the field has " +
                                    std::to_string(field.values.size()) + " values for " +
                                    std::to_string(expected) + " samples");
    if (!std::isfinite(input.isoValue))
        throw std::invalid_argument("dual_contouring: the iso-value must be finite, got " +
                                    std::to_string(input.isoValue));
    if (input.materials != nullptr && input.materials->size() != expected)
        throw std::invalid_argument("dual_contouring: " + std::to_string(input.materials->size()) +
                                    " materials for " + std::to_string(expected) + " samples");
    if (input.hermite != nullptr && input.hermite->samples != field.samples)
        throw std::invalid_argument("dual_contouring: the Hermite data refers to another grid");
}

struct ChunkOutput {
    std::vector<std::uint32_t> indices;
    std::size_t quads = 0;
    std::size_t flipped = 0;
};

} // namespace

struct Workspace::Arrays {
    std::vector<std::uint32_t> wordBase;
    std::vector<std::uint64_t> edges;
    std::vector<Crossing> crossings;
    CellVertices vertices;
    std::vector<ChunkOutput> chunks;
};

Workspace::Workspace() : mArrays(std::make_unique<Arrays>()) {}
Workspace::~Workspace() = default;
Workspace::Workspace(Workspace&&) noexcept = default;
Workspace& Workspace::operator=(Workspace&&) noexcept = default;

namespace {

//! Lends the workspace's arrays to the edge table for one call and takes them back at its end
//! (also when a pass throws), with whatever capacity they grew to.
class LentArrays {
public:
    LentArrays(Workspace::Arrays& arrays, EdgeTable& table) : mArrays(arrays), mTable(table)
    {
        swapAll();
    }
    ~LentArrays() { swapAll(); }
    LentArrays(const LentArrays&) = delete;
    LentArrays& operator=(const LentArrays&) = delete;

private:
    void swapAll()
    {
        mTable.wordBase.swap(mArrays.wordBase);
        mTable.edges.swap(mArrays.edges);
        mTable.crossings.swap(mArrays.crossings);
    }
    Workspace::Arrays& mArrays;
    EdgeTable& mTable;
};

} // namespace

void extractDualContour(const plugin::IsosurfaceInput& input, const ExtractionOptions& options,
                        TriangleMesh& out, ExtractionStats& stats, Workspace* workspace)
{
    Workspace local;
    Workspace::Arrays& arrays = (workspace != nullptr ? *workspace : local).arrays();
    validate(input);
    stats = ExtractionStats{};
    const plugin::SampledField& field = *input.field;
    const Grid grid(field, input.isoValue);
    const CrossingSource source(grid, input, options);
    stats.source = source.source();
    if (field.samples.x < 2 || field.samples.y < 2 || field.samples.z < 2) {
        out.clear();
        return;
    }

    std::size_t firstNan = SignRows::kNoNan;
    EdgeTable table(SignRows(field, input.isoValue, firstNan));
    if (firstNan != SignRows::kNoNan) {
        const glm::ivec3 s = grid.sampleOf(firstNan);
        throw std::invalid_argument("dual_contouring: NaN sample at (" + std::to_string(s.x) +
                                    ", " + std::to_string(s.y) + ", " + std::to_string(s.z) +
                                    ")");
    }
    const LentArrays lent(arrays, table);
    buildEdgeTable(grid, table);
    const std::size_t edgeCount = table.edges.size();
    stats.crossedEdges = edgeCount;

    // Hermite data [Ju et al. 2002, sec. 2]: one crossing and normal per crossed edge.
    table.crossings.resize(edgeCount);
    std::atomic<std::size_t> missing{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, edgeCount),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          std::size_t missingHere = 0;
                          // The table's edge numbers (sample * 3 + axis) are the Hermite keys,
                          // both ascending: one binary search per range, then a merge.
                          std::size_t cursor =
                              source.findHermiteLowerBound(table.edges[range.begin()]);
                          for (std::size_t k = range.begin(); k != range.end(); ++k) {
                              const std::size_t sample = std::size_t(table.edges[k] / 3u);
                              const int axis = int(table.edges[k] % 3u);
                              bool edgeMissing = false;
                              table.crossings[k] = source.computeInOrder(grid.sampleOf(sample),
                                                                         axis, edgeMissing, cursor);
                              missingHere += edgeMissing;
                          }
                          missing += missingHere;
                      });
    stats.hermiteMissing = missing.load();

    CellVertices& vertices = arrays.vertices;
    numberCells(grid, table, options, vertices);
    const bool relaxing = input.materials != nullptr && options.materialRelaxationIterations > 0;
    placeVertices(grid, table, options, relaxing && !source.hasExactProjection(), vertices, stats);
    stats.vertices = vertices.cell.size();
    for (const CellCase& c : vertices.cases) {
        stats.cells += c.patches > 0;
        stats.multiVertexCells += c.patches > 1;
        stats.patchVertices += c.patches;
    }
    stats.faceVertices = stats.vertices - stats.patchVertices;

    if (input.materials != nullptr)
        relaxMaterialBoundaries(grid, table, *input.materials, options, source, input, relaxing,
                                vertices, stats);

    // One quad per crossed edge with four cells around it [Ju et al. 2002, sec. 2.1], wound
    // counter-clockwise seen from the outside: when the edge's low end is inside the outward
    // normal points along +axis, and the cells come counter-clockwise seen from +axis.
    // A quad side between two cells whose patches both cross their shared face twice passes
    // through the face vertex of the edge's segment (see numberCells); such polygons are fanned
    // around their first face vertex.
    // Edges are cut into fixed chunks, each writing its triangles to a list of its own; the lists
    // are concatenated in chunk order, so the triangle order is the edge order whatever the
    // thread count.
    constexpr std::size_t kChunk = 8192;
    // Face vertices are rare (tunnels through ambiguous faces); without any, no quad side can
    // pass through one and the four lookups per quad are skipped.
    const bool faceVertices =
        options.vertices == VertexMode::PerComponent && stats.faceVertices > 0;
    std::vector<ChunkOutput>& chunks = arrays.chunks;
    chunks.resize((edgeCount + kChunk - 1) / kChunk);
    tbb::parallel_for(std::size_t(0), chunks.size(), [&](std::size_t chunk) {
        ChunkOutput& result = chunks[chunk];
        result.indices.clear();
        result.quads = 0;
        result.flipped = 0;
        result.indices.reserve(6 * kChunk);
        const std::size_t end = std::min(edgeCount, (chunk + 1) * kChunk);
        for (std::size_t k = chunk * kChunk; k != end; ++k) {
            const std::size_t sample = std::size_t(table.edges[k] / 3u);
            const int axis = int(table.edges[k] % 3u);
            const glm::ivec3 s = grid.sampleOf(sample);
            if (!isInteriorEdge(grid, s, axis))
                continue;
            const std::array<glm::ivec3, 4> cells = getCellsAroundEdge(s, axis);
            const bool lowInside = table.isInside(s);
            std::array<glm::ivec3, 4> around;
            std::array<std::uint32_t, 4> q;
            std::array<glm::dvec3, 4> p;
            for (int c = 0; c < 4; ++c) {
                around[c] = cells[lowInside ? c : (4 - c) % 4];
                q[c] = findEdgeVertex(vertices, around[c], s, axis);
                p[c] = glm::dvec3(around[c] - s) + vertices.local[q[c]];
            }
            ++result.quads;
            std::array<std::uint32_t, 8> polygon;
            int size = 0;
            int firstFace = -1;
            for (int c = 0; c < 4; ++c) {
                polygon[size++] = q[c];
                if (!faceVertices)
                    continue;
                const std::uint32_t f =
                    findFaceVertex(grid, vertices, around[c], around[(c + 1) % 4], s, axis);
                if (f == kNone)
                    continue;
                if (firstFace < 0)
                    firstFace = size;
                polygon[size++] = f;
            }
            auto& out = result.indices;
            if (firstFace >= 0) {
                for (int i = 1; i + 1 < size; ++i)
                    out.insert(out.end(), {polygon[firstFace], polygon[(firstFace + i) % size],
                                           polygon[(firstFace + i + 1) % size]});
            } else if (chooseDiagonal13(q, p)) {
                ++result.flipped;
                out.insert(out.end(), {q[0], q[1], q[3], q[1], q[2], q[3]});
            } else {
                out.insert(out.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
            }
        }
    });

    // Nothing below throws std::invalid_argument, so the mesh is built in `out` itself, reusing
    // its storage from the last call (as the vtk_flying_edges wrapper does). Every entry is
    // written below: it is resized in place, as marching_cubes does, and nothing is zero-filled
    // where the size did not change.
    const std::size_t vertexCount = vertices.cell.size();
    out.positions.resize(vertexCount);
    if (options.computeNormals)
        out.normals.resize(vertexCount);
    else
        out.normals.clear();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, vertexCount),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                          for (std::size_t v = range.begin(); v != range.end(); ++v) {
                              out.positions[v] = glm::vec3(grid.toWorld(
                                  glm::dvec3(vertices.cell[v]) + vertices.local[v]));
                              if (options.computeNormals)
                                  out.normals[v] = glm::vec3(vertices.normal[v]);
                          }
                      });
    std::vector<std::size_t> firstIndex(chunks.size() + 1, 0);
    for (std::size_t c = 0; c < chunks.size(); ++c) {
        firstIndex[c + 1] = firstIndex[c] + chunks[c].indices.size();
        stats.quads += chunks[c].quads;
        stats.flippedSplits += chunks[c].flipped;
    }
    out.indices.resize(firstIndex.back());
    tbb::parallel_for(std::size_t(0), chunks.size(), [&](std::size_t c) {
        std::copy(chunks[c].indices.begin(), chunks[c].indices.end(),
                  out.indices.begin() + std::ptrdiff_t(firstIndex[c]));
    });
}

} // namespace rtlab::isosurface::dc
