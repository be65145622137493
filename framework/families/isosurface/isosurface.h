#pragma once
// Family `isosurface`: extract a triangle mesh from a sampled signed distance field.
// Ground truth: the analytic SDF of the model the field was sampled from.

#include "core/mesh.h"
#include "core/sampled_field.h"
#include "plugin/technique.h"

#include <glm/vec3.hpp>

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <functional>
#include <string>
#include <vector>

namespace rtlab::plugin {

// The field types live in core/sampled_field.h (the SDF evaluator and meshio use them too).
using rtlab::HermiteData;
using rtlab::HermiteEdge;
using rtlab::SampledField;

//! What every isosurface technique receives.
struct IsosurfaceInput {
    const SampledField* field = nullptr; //!< never null
    double isoValue = 0.0;               //!< extract {p : f(p) = isoValue}
    //! Exact field and gradient, when the model is analytic (Hermite data for dual contouring:
    //! edge crossings refined on the true field, and its normals). May be empty.
    std::function<double(const glm::dvec3&)> exactValue;
    std::function<glm::dvec3(const glm::dvec3&)> exactGradient;
    //! Edge crossings and normals from the SDF evaluator, when the run has them. May be null;
    //! techniques that need Hermite data fall back to exactValue/exactGradient, then to the
    //! samples.
    const HermiteData* hermite = nullptr;
    //! Material id per sample (same layout as field->values), when the model has materials. May be
    //! empty. Dual contouring's elastic relaxation uses it to find material boundaries.
    std::vector<std::uint32_t> const* materials = nullptr;
};

//! Throws std::invalid_argument naming `technique`, the value and its sample index (x, y, z) at
//! the first NaN or infinite sample of `field`: for techniques whose library needs finite samples
//! (marching_cubes and dual_contouring read +-inf as signs and refuse NaN themselves).
inline void requireFiniteSamples(const SampledField& field, const std::string& technique)
{
    for (std::size_t i = 0; i < field.values.size(); ++i)
        if (!std::isfinite(field.values[i])) {
            const std::size_t nx = std::size_t(field.samples.x > 0 ? field.samples.x : 1);
            const std::size_t ny = std::size_t(field.samples.y > 0 ? field.samples.y : 1);
            throw std::invalid_argument(technique + ": sample (" + std::to_string(i % nx) + ", " +
                                        std::to_string(i / nx % ny) + ", " + std::to_string(i / (nx * ny)) +
                                        ") is " + std::to_string(field.values[i]) + "; the field must be finite");
        }
}

class IsosurfaceTechnique : public Technique {
public:
    static constexpr const char* kFamily = "isosurface";
    //! Replaces `out` with the extracted surface. Triangles wind counter-clockwise seen from
    //! outside (positive side).
    virtual void extract(const IsosurfaceInput& input, TriangleMesh& out) = 0;
};

} // namespace rtlab::plugin
