#pragma once
// Analytic signed distance shapes with exact distances: the ground truth of the isosurface family.
// One place for the procedural shapes that tests and studies share.

#include <glm/vec3.hpp>

#include <string>
#include <vector>

namespace rtlab::scene {

//! The kinds of analytic shape; parameters below are read according to the kind.
enum class ShapeKind { Sphere, Box, Torus };

struct AnalyticShape {
    std::string name;        //!< registry key used in experiment files
    std::string doc;         //!< one line
    ShapeKind kind = ShapeKind::Sphere;
    glm::dvec3 center{0.0};  //!< world units
    glm::dvec3 size{1.0};    //!< sphere: x = radius; box: half extents; torus: x = major, y = minor radius
    glm::dvec3 boundsMin{-1.0};  //!< a box that contains the shape with a margin
    glm::dvec3 boundsMax{1.0};

    //! Exact signed distance (negative inside).
    double distance(const glm::dvec3& p) const;
    //! Unit gradient of the distance (the outward normal on the surface).
    glm::dvec3 gradient(const glm::dvec3& p) const;
    //! Enclosed volume, exact.
    double volume() const;
};

//! The named shapes: sphere, box, torus.
const std::vector<AnalyticShape>& analyticShapes();
const AnalyticShape* findAnalyticShape(const std::string& name);
std::vector<std::string> analyticShapeNames();

} // namespace rtlab::scene
