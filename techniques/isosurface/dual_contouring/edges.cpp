#include "passes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <stdexcept>
#include <string>

namespace rtlab::isosurface::dc::detail {

//! Pass 1 (after the sign bits): the crossed edges, numbered in scan order.
void buildEdgeTable(const Grid& grid, EdgeTable& table)
{
    const SignRows& rows = table.rows;
    const int ny = grid.size(1);
    const int nz = grid.size(2);
    const std::size_t words = rows.words();
    std::vector<std::uint64_t> layerCount(nz + 1, 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, nz), [&](const tbb::blocked_range<int>& range) {
        for (int z = range.begin(); z != range.end(); ++z)
            layerCount[z + 1] = rows.countCrossedEdges(z);
    });
    for (int z = 0; z < nz; ++z)
        layerCount[z + 1] += layerCount[z];
    const std::uint64_t edgeCount = layerCount[nz];
    if (edgeCount >= kNone)
        throw std::length_error("dual_contouring: " + std::to_string(edgeCount) +
                                " crossed edges exceed 32-bit indices");
    table.edges.resize(edgeCount);
    table.wordBase.resize(std::size_t(nz) * std::size_t(ny) * words);
    tbb::parallel_for(tbb::blocked_range<int>(0, nz), [&](const tbb::blocked_range<int>& range) {
        for (int z = range.begin(); z != range.end(); ++z) {
            std::uint32_t next = std::uint32_t(layerCount[z]);
            for (int y = 0; y < ny; ++y)
                for (std::size_t w = 0; w < words; ++w) {
                    table.wordBase[(std::size_t(z) * ny + y) * words + w] = next;
                    const SignRows::Crossings c = rows.getCrossings(y, z, w);
                    for (std::uint64_t any = c.any(); any != 0; any &= any - 1) {
                        const int bit = std::countr_zero(any);
                        const std::size_t sample = grid.index({int(64 * w) + bit, y, z});
                        for (int axis = 0; axis < 3; ++axis)
                            if ((c.axis[axis] >> bit) & 1u)
                                table.edges[next++] = std::uint64_t(sample) * 3u + std::uint64_t(axis);
                    }
                }
        }
    });
}

} // namespace rtlab::isosurface::dc::detail
