#pragma once
// Mesh metrics against an analytic signed distance field, and topology counts.

#include "core/mesh.h"

#include <glm/vec3.hpp>

#include <functional>

namespace rtlab::metrics {

struct MeshTopology {
    std::size_t vertices = 0;
    std::size_t triangles = 0;
    std::size_t edges = 0;              //!< undirected
    std::size_t boundaryEdges = 0;      //!< used by one triangle
    std::size_t nonManifoldEdges = 0;   //!< used by three or more triangles
    std::size_t inconsistentEdges = 0;  //!< two triangles traverse it in the same direction
    std::size_t degenerateTriangles = 0;  //!< repeated index or zero area
    long long eulerCharacteristic = 0;  //!< V - E + F
    bool watertight() const { return boundaryEdges == 0 && nonManifoldEdges == 0; }
    bool orientable() const { return inconsistentEdges == 0; }
};

MeshTopology analyzeTopology(const TriangleMesh& mesh);

//! Distance of the mesh to the true surface, sampled at the vertices and at each triangle's
//! centroid: |sdf(p)| is the exact distance from p to the surface when sdf is a true distance.
struct SurfaceDeviation {
    double maxAbs = 0;   //!< world units (one-sided: mesh -> surface)
    double meanAbs = 0;  //!< world units
    double rms = 0;      //!< world units
    std::size_t samples = 0;
};

SurfaceDeviation measureSurfaceDeviation(const TriangleMesh& mesh,
                                         const std::function<double(const glm::dvec3&)>& sdf);

//! Volume enclosed by a closed, consistently oriented mesh (divergence theorem); positive when
//! triangles wind counter-clockwise seen from outside.
double computeEnclosedVolume(const TriangleMesh& mesh);

} // namespace rtlab::metrics
