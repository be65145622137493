// The mesher's internal passes (passes.h) on their own: the grid's sample decoding and the rule
// that splits a quad. The QEF is tested in qef_test.cpp, whole meshes in dual_contouring_test.cpp.

#include "passes.h"

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace rtlab::isosurface {
namespace {

TEST(DualContouringGrid, SampleIndicesDecodeByReciprocalsLikeByDivision)
{
    // Grid::sampleOf divides by the row and layer strides through precomputed 64-bit
    // reciprocals; it must invert index() on every grid shape, powers of two, odd sizes and the
    // largest index included.
    std::mt19937 rng(3);
    for (const glm::ivec3 size :
         {glm::ivec3(2, 2, 2), glm::ivec3(257, 257, 257), glm::ivec3(256, 3, 7),
          glm::ivec3(3, 1021, 5), glm::ivec3(4096, 1024, 1023), glm::ivec3(65535, 2, 3)}) {
        plugin::SampledField field;
        field.samples = size;
        const dc::detail::Grid grid(field, 0.0);
        std::uniform_int_distribution<int> x(0, size.x - 1), y(0, size.y - 1), z(0, size.z - 1);
        std::vector<glm::ivec3> samples = {glm::ivec3(0), size - 1, glm::ivec3(size.x - 1, 0, 0),
                                           glm::ivec3(0, size.y - 1, 0),
                                           glm::ivec3(0, 0, size.z - 1)};
        for (int i = 0; i < 20000; ++i)
            samples.emplace_back(x(rng), y(rng), z(rng));
        for (const glm::ivec3& s : samples) {
            const std::size_t index =
                std::size_t(s.x) +
                std::size_t(size.x) * (std::size_t(s.y) + std::size_t(size.y) * std::size_t(s.z));
            ASSERT_EQ(grid.sampleOf(index), s) << size.x << "x" << size.y << "x" << size.z;
        }
    }
}

TEST(DualContouringQuads, TheDiagonalChoiceMatchesNormalisedNormalsOnRandomQuads)
{
    // chooseDiagonal13 decides most quads on cross-multiplied squares of the cosines, without a
    // square root or a division; it must choose as comparing the normalised triangle normals
    // does (the rule as stated, written out here), ties of 1e-12 to the smallest index included.
    const auto reference = [](const std::array<std::uint32_t, 4>& q,
                              const std::array<glm::dvec3, 4>& p) {
        const auto unit = [&](int a, int b, int c) {
            const glm::dvec3 n = glm::cross(p[b] - p[a], p[c] - p[a]);
            const double l = glm::length(n);
            return l > 0.0 ? n / l : glm::dvec3(0.0);
        };
        const double agree02 = glm::dot(unit(0, 1, 2), unit(0, 2, 3));
        const double agree13 = glm::dot(unit(0, 1, 3), unit(1, 2, 3));
        if (std::abs(agree02 - agree13) > 1e-12)
            return agree13 > agree02;
        return (std::min_element(q.begin(), q.end()) - q.begin()) % 2 == 1;
    };
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::uniform_int_distribution<std::uint32_t> index(0, 1000);
    int decided = 0, close = 0;
    for (int trial = 0; trial < 200000; ++trial) {
        // A unit square around the edge bent by up to 10^-k out of its plane (k from 0 to 14),
        // its corners moved inside their cells; sometimes exactly planar, sometimes degenerate.
        std::array<glm::dvec3, 4> p = {glm::dvec3(-0.5, -0.5, 0), glm::dvec3(0.5, -0.5, 0),
                                       glm::dvec3(0.5, 0.5, 0), glm::dvec3(-0.5, 0.5, 0)};
        const double bend = trial % 7 == 0 ? 0.0 : std::pow(10.0, -14.0 * u(rng));
        for (auto& corner : p) {
            corner.x += 0.45 * (u(rng) - 0.5);
            corner.y += 0.45 * (u(rng) - 0.5);
            corner.z += bend * (u(rng) - 0.5);
        }
        if (trial % 101 == 0)
            p[2] = p[1]; // a degenerate triangle
        const std::array<std::uint32_t, 4> q = {index(rng), index(rng), index(rng), index(rng)};
        const bool expected = reference(q, p);
        ASSERT_EQ(dc::detail::chooseDiagonal13(q, p), expected)
            << "trial " << trial << " bend " << bend;
        decided += expected;
        // Planar or nearly planar quads: the tie rule's region.
        close += bend < 1e-12;
    }
    EXPECT_GT(decided, 20000);
    EXPECT_GT(close, 20000);
}

} // namespace
} // namespace rtlab::isosurface
