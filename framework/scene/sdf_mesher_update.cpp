// SdfMesher's incremental update: a dig's new edits folded into the kept grid, the cells they
// touched meshed again, the mesh patched and put back in the order of a full meshing.

#include "scene/sdf_mesher.h"
#include "scene/sdf_mesher_state.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cstring>

namespace rtlab::scene {

namespace {

// Distance from p to the box [lo, hi] (0 inside): outside the box, a lower bound of the distance
// of an exact primitive that lies in it.
double getBoxDistance(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi)
{
    return glm::length(glm::max(glm::max(lo - p, p - hi), 0.0));
}

// The live slots (key != kNone) in the order of their keys, when every slot outside `written`
// already is in that order (the slots an update did not write kept their place in the order a
// full meshing gives): the others sorted, then merged in. Linear but for the sort of `written`.
template <class Less>
std::vector<std::uint32_t> mergeInOrder(const std::vector<std::uint32_t>& key,
                                        std::vector<std::uint32_t> written, Less less)
{
    std::vector<std::uint8_t> isWritten(key.size(), 0);
    std::erase_if(written, [&](std::uint32_t slot) {
        const bool drop = key[slot] == kNone || isWritten[slot];
        isWritten[slot] = 1;
        return drop;
    });
    std::sort(written.begin(), written.end(), less);
    std::vector<std::uint32_t> out;
    out.reserve(key.size());
    std::size_t j = 0;
    for (std::uint32_t slot = 0; slot < key.size(); ++slot) {
        if (key[slot] == kNone || isWritten[slot])
            continue;
        while (j < written.size() && less(written[j], slot))
            out.push_back(written[j++]);
        out.push_back(slot);
    }
    out.insert(out.end(), written.begin() + std::ptrdiff_t(j), written.end());
    return out;
}

} // namespace

void SdfMesher::State::meshIncrementally(int frame, const std::vector<const CsgEdit*>& added,
                                         const std::vector<std::pair<glm::dvec3, glm::dvec3>>& reach,
                                         SdfMeshChange& change)
{
    auto& positions = mesh.mesh.positions;
    auto& normals = mesh.mesh.normals;
    auto& indices = mesh.mesh.indices;
    auto& materials = mesh.triangleMaterial;
    if (++stamp == 0) { // wrapped: every old mark must go
        std::fill(cellStamp.begin(), cellStamp.end(), 0u);
        std::fill(edgeStamp.begin(), edgeStamp.end(), 0u);
        std::fill(vertexStamp.begin(), vertexStamp.end(), 0u);
        stamp = 1;
    }
    cellStamp.resize(cellVertex.size(), 0u);
    edgeStamp.resize(edgeQuad.size(), 0u);
    dirtyCells.clear();
    const auto markCell = [&](int x, int y, int z) {
        if (x < 0 || y < 0 || z < 0 || x >= cells.x || y >= cells.y || z >= cells.z)
            return;
        const std::size_t c = cellIndex(x, y, z);
        if (cellStamp[c] != stamp) {
            cellStamp[c] = stamp;
            dirtyCells.push_back(std::uint32_t(c));
        }
    };

    // 1. The new edits folded into the samples: SdfModel::evaluate applies the edits in list
    //    order and the new ones come after every applied one, so this is the value evaluating
    //    them all gives, bit for bit. An edit changes a sample only where its primitive is
    //    closer than the field's own value allows (csg.cpp: max(d, -s) = d when s >= -d, min(d, s)
    //    = d when s >= d, beyond the blend radius); outside the primitive's box the distance to
    //    the box bounds an exact primitive's distance from below, so farther samples skip it.
    std::vector<glm::dvec3> boundsLo(added.size()), boundsHi(added.size());
    for (std::size_t k = 0; k < added.size(); ++k)
        added[k]->getBounds(boundsLo[k], boundsHi[k]);
    changedBySlice.resize(std::size_t(samples.z));
    tbb::parallel_for(0, samples.z, [&](int z) {
        auto& changed = changedBySlice[std::size_t(z)];
        changed.clear();
        for (int y = 0; y < samples.y; ++y)
            for (int x = 0; x < samples.x; ++x) {
                const std::size_t i = sampleIndex(x, y, z);
                const glm::dvec3 p = position(x, y, z);
                double d = raw[i];
                for (std::size_t k = 0; k < added.size(); ++k) {
                    const CsgEdit& e = *added[k];
                    const double threshold =
                        (e.op == CsgOp::Add ? d : -d) + std::max(e.blend, 0.0);
                    // Outside the box only (inside it the primitive's distance may be
                    // negative); the slack covers the rounding of the primitive's evaluation.
                    const double boxDistance = getBoxDistance(p, boundsLo[k], boundsHi[k]);
                    if (boxDistance > 0.0 &&
                        boxDistance > threshold + 1e-9 * (1.0 + std::abs(threshold)))
                        continue;
                    d = e.applyTo(d, p);
                }
                if (std::bit_cast<std::uint64_t>(d) == std::bit_cast<std::uint64_t>(raw[i]))
                    continue;
                raw[i] = d;
                values[i] = padded(d, x, y, z);
                changed.push_back(std::uint32_t(i));
            }
    });
    // The cells around each changed sample (it is a corner of each).
    for (const auto& slice : changedBySlice)
        for (const std::uint32_t i : slice) {
            ++change.samplesChanged;
            const int x = int(i % std::uint32_t(samples.x));
            const int y = int((i / std::uint32_t(samples.x)) % std::uint32_t(samples.y));
            const int z = int(i / (std::uint32_t(samples.x) * std::uint32_t(samples.y)));
            for (int dz = -1; dz <= 0; ++dz)
                for (int dy = -1; dy <= 0; ++dy)
                    for (int dx = -1; dx <= 0; ++dx)
                        markCell(x + dx, y + dy, z + dz);
        }
    // 2. Cells whose vertex window (the cell grown by half a cell, where the Newton steps stay)
    //    meets an edit's reach: their vertex may move although no corner changed.
    for (const auto& [lo, hi] : reach) {
        const glm::ivec3 begin =
            glm::max(glm::ivec3(glm::floor((lo - origin) / spacing - 1.5)), glm::ivec3(0));
        const glm::ivec3 end =
            glm::min(glm::ivec3(glm::ceil((hi - origin) / spacing + 0.5)) + 1, cells);
        for (int z = begin.z; z < end.z; ++z)
            for (int y = begin.y; y < end.y; ++y)
                for (int x = begin.x; x < end.x; ++x)
                    markCell(x, y, z);
    }
    change.cellsMeshed = dirtyCells.size();

    const std::size_t vertexCountBefore = positions.size(), quadCountBefore = quadEdge.size();
    const auto grow = [&](const glm::vec3& p) { growBox(change.changedMin, change.changedMax, p); };
    // The 12 edges a cell borders: along each axis, the edges whose four cells include it.
    const auto forEachCellEdge = [&](std::uint32_t cell, auto&& visit) {
        const glm::ivec3 c = cellCoords(cell);
        for (int axis = 0; axis < 3; ++axis) {
            const int u = (axis + 1) % 3, w = (axis + 2) % 3;
            for (int a = 0; a < 2; ++a)
                for (int b = 0; b < 2; ++b) {
                    glm::ivec3 p0 = c;
                    p0[u] += a;
                    p0[w] += b;
                    visit(axis, p0);
                }
        }
    };

    // 3. The quads on the dirty cells' edges, as they were: each edge once, in the order the
    //    dirty cells first reach it, and only an edge that has a quad or whose ends now differ
    //    in sign (no other edge can have one after).
    edges.clear();
    for (const std::uint32_t cell : dirtyCells)
        forEachCellEdge(cell, [&](int axis, const glm::ivec3& p0) {
            const std::size_t e = edgeIndex(axis, p0);
            if (edgeStamp[e] == stamp)
                return;
            edgeStamp[e] = stamp;
            glm::ivec3 p1 = p0;
            p1[axis] += 1;
            if (edgeQuad[e] != kNone ||
                (p1[axis] < samples[axis] && (values[sampleIndex(p0.x, p0.y, p0.z)] < 0.0) !=
                                                 (values[sampleIndex(p1.x, p1.y, p1.z)] < 0.0)))
                edges.push_back(e);
        });
    before.resize(edges.size());
    after.resize(edges.size());
    for (std::size_t k = 0; k < edges.size(); ++k) {
        Quad& q = before[k];
        q.slot = edgeQuad[edges[k]];
        if (q.slot == kNone)
            continue;
        std::copy_n(indices.begin() + std::ptrdiff_t(6 * std::size_t(q.slot)), 6, q.indices.begin());
        q.materials = {materials[2 * std::size_t(q.slot)], materials[2 * std::size_t(q.slot) + 1]};
    }

    // 4. The dirty cells' vertices, computed again (in parallel: each reads the field only); a
    //    cell still crossed keeps its slot. A vertex that moves, leaves or arrives is stamped,
    //    and its old and new positions go into the changed box.
    newPosition.resize(dirtyCells.size());
    crossed.assign(dirtyCells.size(), 0);
    tbb::parallel_for(std::size_t(0), dirtyCells.size(), [&](std::size_t k) {
        const glm::ivec3 c = cellCoords(dirtyCells[k]);
        crossed[k] = computeVertex(c.x, c.y, c.z, frame, newPosition[k]) ? 1 : 0;
    });
    vertexStamp.resize(positions.size(), 0u);
    std::vector<std::uint32_t> freeVertices, written;
    std::size_t nextFreeVertex = 0;
    bool changed = false;
    for (std::size_t k = 0; k < dirtyCells.size(); ++k) {
        const std::uint32_t cell = dirtyCells[k];
        const std::uint32_t old = cellVertex[cell];
        if (!crossed[k]) {
            if (old != kNone) {
                freeVertices.push_back(old);
                vertexCell[old] = kNone;
                vertexStamp[old] = stamp;
                cellVertex[cell] = kNone;
                grow(positions[old]);
                changed = true;
            }
            continue;
        }
        std::uint32_t v = old;
        if (v == kNone) {
            if (nextFreeVertex < freeVertices.size()) {
                v = freeVertices[nextFreeVertex++];
            } else {
                v = std::uint32_t(positions.size());
                positions.emplace_back();
                normals.emplace_back();
                vertexCell.push_back(kNone);
                vertexStamp.push_back(0u);
            }
        } else if (std::bit_cast<glm::uvec3>(positions[v]) ==
                   std::bit_cast<glm::uvec3>(newPosition[k])) {
            continue; // the same vertex: nothing to write
        } else {
            grow(positions[v]);
        }
        changed = true;
        positions[v] = newPosition[k];
        grow(positions[v]);
        vertexCell[v] = cell;
        vertexStamp[v] = stamp;
        cellVertex[cell] = v;
        written.push_back(v);
    }
    freeVertices.erase(freeVertices.begin(), freeVertices.begin() + std::ptrdiff_t(nextFreeVertex));
    tbb::parallel_for(std::size_t(0), written.size(), [&](std::size_t k) {
        const std::uint32_t v = written[k];
        normals[v] = glm::vec3(model->evaluateGradient(glm::dvec3(positions[v]), frame));
    });

    // 5. The quads on the same edges built again, with their materials (in parallel), then put
    //    in place: a quad that is still there keeps its slot, a new one takes a freed slot or
    //    goes at the end. A quad whose indices, materials and corners are unchanged is the same
    //    quad; any other goes into the changed box (a corner that moved is already there with
    //    its old position).
    tbb::parallel_for(std::size_t(0), edges.size(), [&](std::size_t k) {
        const std::size_t e = edges[k];
        const int axis = int(e / raw.size());
        const std::size_t s = e % raw.size();
        const glm::ivec3 p0(int(s % std::size_t(samples.x)),
                            int((s / std::size_t(samples.x)) % std::size_t(samples.y)),
                            int(s / (std::size_t(samples.x) * std::size_t(samples.y))));
        Quad& q = after[k];
        q.slot = kNone;
        if (!computeQuad(axis, p0, q.indices.data()))
            return;
        q.slot = 0; // built; the slot is chosen below
        for (std::size_t t = 0; t < 2; ++t)
            q.materials[t] = computeMaterial(positions[q.indices[3 * t]], positions[q.indices[3 * t + 1]],
                                             positions[q.indices[3 * t + 2]], frame);
    });
    const auto moved = [&](const Quad& q) {
        return std::any_of(q.indices.begin(), q.indices.end(),
                           [&](std::uint32_t v) { return vertexStamp[v] == stamp; });
    };
    std::vector<std::uint32_t> freeQuads;
    for (std::size_t k = 0; k < edges.size(); ++k) {
        const Quad& b = before[k];
        const Quad& a = after[k];
        if (b.slot == kNone && a.slot == kNone)
            continue; // no quad before or after
        if (b.slot != kNone && a.slot == kNone) {
            freeQuads.push_back(b.slot);
            edgeQuad[edges[k]] = kNone;
            quadEdge[b.slot] = kNone;
        }
        if (b.slot != kNone && a.slot != kNone && b.indices == a.indices &&
            b.materials == a.materials && !moved(a))
            continue;
        changed = true;
        for (const Quad* q : {&b, &a})
            if (q->slot != kNone)
                for (const std::uint32_t v : q->indices)
                    grow(positions[v]);
    }
    std::size_t nextFreeQuad = 0;
    std::vector<std::uint32_t> writtenQuads;
    for (std::size_t k = 0; k < edges.size(); ++k) {
        if (after[k].slot == kNone)
            continue;
        std::uint32_t q = before[k].slot;
        if (q == kNone) {
            if (nextFreeQuad < freeQuads.size()) {
                q = freeQuads[nextFreeQuad++];
            } else {
                q = std::uint32_t(quadEdge.size());
                quadEdge.push_back(kNone);
                indices.resize(indices.size() + 6);
                materials.resize(materials.size() + 2);
            }
        } else if (before[k].indices == after[k].indices &&
                   before[k].materials == after[k].materials) {
            continue; // the same bytes in the same slot
        }
        std::copy(after[k].indices.begin(), after[k].indices.end(),
                  indices.begin() + std::ptrdiff_t(6 * std::size_t(q)));
        materials[2 * std::size_t(q)] = after[k].materials[0];
        materials[2 * std::size_t(q) + 1] = after[k].materials[1];
        quadEdge[q] = std::uint32_t(edges[k]);
        edgeQuad[edges[k]] = q;
        writtenQuads.push_back(q);
    }
    freeQuads.erase(freeQuads.begin(), freeQuads.begin() + std::ptrdiff_t(nextFreeQuad));

    // 6. The arrays back in the order a full meshing gives (vertices by cell, quads by edge,
    //    as meshAll visits them), the freed slots dropped: the patched mesh is then the full
    //    re-mesh byte for byte, not only up to order (rasterising the same triangles in another
    //    order rounds some interpolated values differently, so the frame would not be bitwise
    //    the unculled one). Only the dirty slots broke the order, so each array is a sorted run
    //    with a few entries out of place; the rebuild is a copy with a remap of the indices.
    {
        if (!freeQuads.empty())
            changed = true;
        const auto byEdge = [&](std::uint32_t x, std::uint32_t y) { return quadEdge[x] < quadEdge[y]; };
        const std::vector<std::uint32_t> quads = mergeInOrder(quadEdge, writtenQuads, byEdge);
        if (!std::is_sorted(quads.begin(), quads.end()) || quads.size() != quadEdge.size()) {
            std::vector<std::uint32_t> sortedIndices(6 * quads.size()), sortedMaterials(2 * quads.size()),
                sortedEdges(quads.size());
            for (std::size_t k = 0; k < quads.size(); ++k) {
                const std::uint32_t q = quads[k];
                std::copy_n(indices.begin() + std::ptrdiff_t(6 * std::size_t(q)), 6,
                            sortedIndices.begin() + std::ptrdiff_t(6 * k));
                sortedMaterials[2 * k] = materials[2 * std::size_t(q)];
                sortedMaterials[2 * k + 1] = materials[2 * std::size_t(q) + 1];
                sortedEdges[k] = quadEdge[q];
                edgeQuad[quadEdge[q]] = std::uint32_t(k);
            }
            indices = std::move(sortedIndices);
            materials = std::move(sortedMaterials);
            quadEdge = std::move(sortedEdges);
        }
        const auto byCell = [&](std::uint32_t x, std::uint32_t y) { return vertexCell[x] < vertexCell[y]; };
        const std::vector<std::uint32_t> order = mergeInOrder(vertexCell, written, byCell);
        if (!std::is_sorted(order.begin(), order.end()) || order.size() != positions.size()) {
            std::vector<std::uint32_t> remap(positions.size(), kNone);
            std::vector<glm::vec3> sortedPositions(order.size()), sortedNormals(order.size());
            std::vector<std::uint32_t> sortedCells(order.size());
            for (std::size_t k = 0; k < order.size(); ++k) {
                const std::uint32_t v = order[k];
                remap[v] = std::uint32_t(k);
                sortedPositions[k] = positions[v];
                sortedNormals[k] = normals[v];
                sortedCells[k] = vertexCell[v];
                cellVertex[vertexCell[v]] = std::uint32_t(k);
            }
            positions = std::move(sortedPositions);
            normals = std::move(sortedNormals);
            vertexCell = std::move(sortedCells);
            for (std::uint32_t& i : indices)
                i = remap[i];
        }
    }

    change.changed = changed || positions.size() != vertexCountBefore ||
                     quadEdge.size() != quadCountBefore;
}


} // namespace rtlab::scene
