#pragma once
// Family `isosurface`: extract a triangle mesh from a sampled signed distance field.
// Ground truth: the analytic SDF of the model the field was sampled from.

#include "core/mesh.h"
#include "plugin/technique.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <vector>

namespace rtlab::plugin {

//! Samples of a signed distance field on a regular grid (negative inside, positive outside).
struct SampledField {
    glm::ivec3 samples{0};      //!< sample count per axis; cells per axis = samples - 1
    glm::dvec3 origin{0.0};     //!< world position of sample (0, 0, 0)
    double spacing = 1.0;       //!< world distance between neighbouring samples
    std::vector<float> values;  //!< samples.x * samples.y * samples.z, x fastest

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
    glm::ivec3 sample{0};  //!< lower end of the edge (a sample index)
    int axis = 0;          //!< 0 = x, 1 = y, 2 = z: the edge runs from `sample` to sample + e_axis
    double t = 0.5;        //!< crossing at sample + t * e_axis, t in [0, 1]
    glm::dvec3 normal{0.0};  //!< unit outward normal at the crossing; zero when undefined (kink)
};

struct HermiteData {
    //! Sorted by key(sample, axis) so find() is a binary search.
    std::vector<HermiteEdge> edges;
    double precision = 0.0;  //!< bound on |t - t_true| * spacing, world units
    glm::ivec3 samples{0};   //!< of the field the edges refer to

    std::uint64_t key(const glm::ivec3& s, int axis) const
    {
        return ((std::uint64_t(s.z) * std::uint64_t(samples.y) + std::uint64_t(s.y)) * std::uint64_t(samples.x) +
                std::uint64_t(s.x)) * 3u + std::uint64_t(axis);
    }
    //! The edge's entry, or null when the evaluator recorded no crossing on it.
    const HermiteEdge* find(const glm::ivec3& s, int axis) const;
    //! Sorts `edges` by key (call once after filling).
    void sort();
};

//! What every isosurface technique receives.
struct IsosurfaceInput {
    const SampledField* field = nullptr;  //!< never null
    double isoValue = 0.0;                //!< extract {p : f(p) = isoValue}
    //! Exact field and gradient, when the model is analytic (Hermite data for dual contouring:
    //! edge crossings refined on the true field, and its normals). May be empty.
    std::function<double(const glm::dvec3&)> exactValue;
    std::function<glm::dvec3(const glm::dvec3&)> exactGradient;
    //! Edge crossings and normals from the SDF evaluator, when the run has them. May be null;
    //! techniques that need Hermite data fall back to exactValue/exactGradient, then to the samples.
    const HermiteData* hermite = nullptr;
    //! Material id per sample (same layout as field->values), when the model has materials. May be
    //! empty. Dual contouring's elastic relaxation uses it to find material boundaries.
    std::vector<std::uint32_t> const* materials = nullptr;
};

class IsosurfaceTechnique : public Technique {
public:
    static constexpr const char* kFamily = "isosurface";
    //! Replaces `out` with the extracted surface. Triangles wind counter-clockwise seen from
    //! outside (positive side).
    virtual void extract(const IsosurfaceInput& input, TriangleMesh& out) = 0;
};

} // namespace rtlab::plugin
