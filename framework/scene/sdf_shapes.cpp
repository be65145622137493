#include "scene/sdf_shapes.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>

namespace rtlab::scene {

double AnalyticShape::distance(const glm::dvec3& pw) const
{
    const glm::dvec3 p = pw - center;
    switch (kind) {
    case ShapeKind::Sphere:
        return glm::length(p) - size.x;
    case ShapeKind::Box: {
        // Exact box distance: outside part plus (negative) inside part.
        const glm::dvec3 q = glm::abs(p) - size;
        return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
    }
    case ShapeKind::Torus: {
        // Torus around the y axis: distance to the core circle minus the tube radius.
        const double ring = std::sqrt(p.x * p.x + p.z * p.z) - size.x;
        return std::sqrt(ring * ring + p.y * p.y) - size.y;
    }
    }
    return 0.0;
}

glm::dvec3 AnalyticShape::gradient(const glm::dvec3& p) const
{
    // Central differences on the exact distance: exact up to O(h^2) away from the medial axis,
    // and defined everywhere (the analytic gradient is undefined on the medial axis).
    const double h = 1e-6 * std::max({1.0, std::abs(size.x), std::abs(size.y), std::abs(size.z)});
    glm::dvec3 g(distance(p + glm::dvec3(h, 0, 0)) - distance(p - glm::dvec3(h, 0, 0)),
                 distance(p + glm::dvec3(0, h, 0)) - distance(p - glm::dvec3(0, h, 0)),
                 distance(p + glm::dvec3(0, 0, h)) - distance(p - glm::dvec3(0, 0, h)));
    const double len = glm::length(g);
    return len > 0 ? g / len : glm::dvec3(0.0, 1.0, 0.0);
}

double AnalyticShape::volume() const
{
    const double pi = glm::pi<double>();
    switch (kind) {
    case ShapeKind::Sphere: return 4.0 / 3.0 * pi * size.x * size.x * size.x;
    case ShapeKind::Box: return 8.0 * size.x * size.y * size.z;
    case ShapeKind::Torus: return 2.0 * pi * pi * size.x * size.y * size.y;
    }
    return 0.0;
}

const std::vector<AnalyticShape>& analyticShapes()
{
    static const std::vector<AnalyticShape> shapes = {
        {.name = "sphere", .doc = "sphere of radius 0.7 at the origin", .kind = ShapeKind::Sphere,
         .size = {0.7, 0, 0}},
        {.name = "box", .doc = "box with half extents 0.6, 0.45, 0.3 (sharp edges and corners)",
         .kind = ShapeKind::Box, .size = {0.6, 0.45, 0.3}},
        {.name = "torus", .doc = "torus around y, major radius 0.6, minor radius 0.25 (genus 1)",
         .kind = ShapeKind::Torus, .size = {0.6, 0.25, 0}},
    };
    return shapes;
}

const AnalyticShape* findAnalyticShape(const std::string& name)
{
    for (const auto& s : analyticShapes())
        if (s.name == name)
            return &s;
    return nullptr;
}

std::vector<std::string> analyticShapeNames()
{
    std::vector<std::string> names;
    for (const auto& s : analyticShapes())
        names.push_back(s.name);
    return names;
}

} // namespace rtlab::scene
