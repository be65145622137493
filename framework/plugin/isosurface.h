#pragma once
// Family `isosurface`: extract a triangle mesh from a sampled signed distance field.
// Ground truth: the analytic SDF of the model the field was sampled from.

#include "core/mesh.h"
#include "plugin/technique.h"

#include <glm/vec3.hpp>

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

//! What every isosurface technique receives.
struct IsosurfaceInput {
    const SampledField* field = nullptr;  //!< never null
    double isoValue = 0.0;                //!< extract {p : f(p) = isoValue}
    //! Exact field and gradient, when the model is analytic (Hermite data for dual contouring:
    //! edge crossings refined on the true field, and its normals). May be empty.
    std::function<double(const glm::dvec3&)> exactValue;
    std::function<glm::dvec3(const glm::dvec3&)> exactGradient;
};

class IsosurfaceTechnique : public Technique {
public:
    static constexpr const char* kFamily = "isosurface";
    //! Replaces `out` with the extracted surface. Triangles wind counter-clockwise seen from
    //! outside (positive side).
    virtual void extract(const IsosurfaceInput& input, TriangleMesh& out) = 0;
};

} // namespace rtlab::plugin
