#pragma once
// The sign of every sample of a grid as one bit, 64 samples of an x-row per word: the first pass of
// the isosurface meshers. Crossed edges and cells with mixed corners then come out of XORs of
// neighbouring rows, a word at a time, and a walk over set bits touches only the surface's rows
// and cells. The row-at-a-time walk is the idea of Flying Edges [W. Schroeder, R. Maynard,
// B. Geveci, "Flying Edges: A High-Performance Scalable Isocontouring Algorithm", LDAV 2015],
// which keeps per-row edge cases and trim ranges where this keeps bit masks.

#include "core/sampled_field.h"

#include <glm/vec3.hpp>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace rtlab::isosurface {

//! The smallest float t >= iso: for every float v, v < t exactly when double(v) < iso, so the float
//! comparison classifies like the double one without widening each sample.
float getInsideThreshold(double iso);

class SignRows {
public:
    static constexpr std::size_t kNoNan = std::numeric_limits<std::size_t>::max();

    //! Classifies every sample of `field` (inside: value < iso), in parallel over layers. Returns
    //! the index of the first NaN sample in scan order through `firstNan` (kNoNan when none; NaN
    //! samples are classified outside).
    SignRows(const SampledField& field, double iso, std::size_t& firstNan);

    int size(int axis) const { return mSize[axis]; }
    //! 64-bit words per row: (nx + 63) / 64. Bits at and past nx are 0 in every row.
    std::size_t words() const { return mWords; }
    const std::uint64_t* row(int y, int z) const
    {
        return &mBits[(std::size_t(z) * std::size_t(mSize.y) + std::size_t(y)) * mWords];
    }
    bool isInside(const glm::ivec3& s) const
    {
        return (row(s.y, s.z)[std::size_t(s.x) >> 6] >> (s.x & 63)) & 1u;
    }

    //! Word w of the x crossings of `row`: bit x set when samples x and x + 1 differ (x < nx - 1).
    std::uint64_t getXCrossings(const std::uint64_t* row, std::size_t w) const
    {
        const std::uint64_t next = w + 1 < mWords ? row[w + 1] : 0;
        const std::uint64_t crossed = row[w] ^ ((row[w] >> 1) | (next << 63));
        return w == mLastWord ? crossed & mLastMask : crossed;
    }

    //! The crossed edges starting in sample row (y, z), word w: x edges, and y and z edges to the
    //! next row and layer (0 where there is none).
    struct Crossings {
        std::uint64_t axis[3];
        std::uint64_t any() const { return axis[0] | axis[1] | axis[2]; }
        int count() const
        {
            return std::popcount(axis[0]) + std::popcount(axis[1]) + std::popcount(axis[2]);
        }
    };
    Crossings getCrossings(int y, int z, std::size_t w) const
    {
        const std::uint64_t* r = row(y, z);
        return {getXCrossings(r, w), y + 1 < mSize.y ? r[w] ^ row(y + 1, z)[w] : 0,
                z + 1 < mSize.z ? r[w] ^ row(y, z + 1)[w] : 0};
    }

    //! Number of crossed edges starting in sample layer z.
    std::uint64_t countCrossedEdges(int z) const;

    //! Calls visit(x, y, axis) for every crossed edge starting in sample layer z, in scan order:
    //! rows (y), samples (x), then axes x, y, z.
    template <class Visit>
    void visitCrossedEdges(int z, Visit&& visit) const
    {
        for (int y = 0; y < mSize.y; ++y)
            for (std::size_t w = 0; w < mWords; ++w) {
                const Crossings c = getCrossings(y, z, w);
                for (std::uint64_t any = c.any(); any != 0; any &= any - 1) {
                    const int bit = std::countr_zero(any);
                    const int x = int(64 * w) + bit;
                    for (int axis = 0; axis < 3; ++axis)
                        if ((c.axis[axis] >> bit) & 1u)
                            visit(x, y, axis);
                }
            }
    }

    //! Word w of the cells of row (y, z) whose eight corners are not all on one side: bit x for
    //! cell (x, y, z), x < nx - 1. Needs y + 1 < ny and z + 1 < nz.
    std::uint64_t getActiveCells(int y, int z, std::size_t w) const;

    //! The case index of cell (x, y, z): bit c set when corner c = (c & 1, (c >> 1) & 1,
    //! (c >> 2) & 1) is inside (the marching cubes convention of case_table.h).
    unsigned getCube(int x, int y, int z) const
    {
        return getCornerPair(row(y, z), x) | getCornerPair(row(y + 1, z), x) << 2 |
               getCornerPair(row(y, z + 1), x) << 4 | getCornerPair(row(y + 1, z + 1), x) << 6;
    }

private:
    std::uint64_t* mutableRow(int y, int z) { return const_cast<std::uint64_t*>(row(y, z)); }
    static unsigned getCornerPair(const std::uint64_t* row, int x)
    {
        const unsigned low = unsigned(row[std::size_t(x) >> 6] >> (x & 63)) & 1u;
        const unsigned high = unsigned(row[std::size_t(x + 1) >> 6] >> ((x + 1) & 63)) & 1u;
        return low | high << 1;
    }

    glm::ivec3 mSize;
    std::size_t mWords;
    std::size_t mLastWord;   //!< the word holding sample nx - 1
    std::uint64_t mLastMask; //!< clears bit nx - 1 there: no edge or cell starts at the last sample
    std::unique_ptr<std::uint64_t[]> mBits;
};

} // namespace rtlab::isosurface
