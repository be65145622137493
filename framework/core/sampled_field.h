#pragma once
// A signed distance field sampled on a regular grid, and Hermite data (edge crossings with
// normals). The SDF evaluator (framework/sdf/) produces them, the isosurface family's techniques
// (framework/families/isosurface/isosurface.h) consume them, meshio writes them.

#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

namespace rtlab {

//! Samples of a signed distance field on a regular grid (negative inside, positive outside).
struct SampledField {
    glm::ivec3 samples{0};     //!< sample count per axis; cells per axis = samples - 1
    glm::dvec3 origin{0.0};    //!< world position of sample (0, 0, 0)
    double spacing = 1.0;      //!< world distance between neighbouring samples
    std::vector<float> values; //!< samples.x * samples.y * samples.z, x fastest

    std::size_t index(int x, int y, int z) const
    {
        return (std::size_t(z) * samples.y + y) * samples.x + x;
    }
    float at(int x, int y, int z) const { return values[index(x, y, z)]; }
    glm::dvec3 position(int x, int y, int z) const
    {
        return origin + spacing * glm::dvec3(x, y, z);
    }
};

//! Hermite data: where the surface crosses a grid edge, and the surface normal there. Produced by
//! the SDF evaluator (framework/sdf/) from the exact edit list, to a stated precision along the
//! edge; dual contouring consumes it (the "Hermite data" of Ju et al. 2002).
struct HermiteEdge {
    glm::ivec3 sample{0};   //!< lower end of the edge (a sample index)
    int axis = 0;           //!< 0 = x, 1 = y, 2 = z: the edge runs from `sample` to sample + e_axis
    double t = 0.5;         //!< crossing at sample + t * e_axis, t in [0, 1]
    glm::dvec3 normal{0.0}; //!< unit outward normal at the crossing; zero when undefined (kink)
};

struct HermiteData {
    //! Sorted by key(sample, axis) so find() is a binary search.
    std::vector<HermiteEdge> edges;
    double precision = 0.0; //!< bound on |t - t_true| * spacing, world units
    glm::ivec3 samples{0};  //!< of the field the edges refer to

    std::uint64_t key(const glm::ivec3& s, int axis) const
    {
        return ((std::uint64_t(s.z) * std::uint64_t(samples.y) + std::uint64_t(s.y)) *
                    std::uint64_t(samples.x) +
                std::uint64_t(s.x)) *
                   3u +
               std::uint64_t(axis);
    }
    //! The edge's entry, or null when the evaluator recorded no crossing on it.
    const HermiteEdge* find(const glm::ivec3& s, int axis) const;
    //! Sorts `edges` by key (call once after filling).
    void sort();
};

} // namespace rtlab
