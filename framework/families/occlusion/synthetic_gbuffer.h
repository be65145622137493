#pragma once
// Analytic G-buffers for the occlusion family's stress cases and tests: the camera sits at the
// origin looking down -z (view = world), and pixel (x, y) sees whatever a hit function returns
// for the ray through its centre. No scene or rasteriser is involved, so the exact occlusion of
// every pixel can be integrated from the same planes (integrateOcclusion).

#include "core/image.h"
#include "families/occlusion/occlusion.h"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <functional>
#include <utility>
#include <vector>

namespace rtlab::occlusion {

struct SyntheticGBuffer {
    Image<float> depth;       //!< linear view depth, inf = sky
    Image<glm::vec3> normal;  //!< view-space unit normals facing the camera, zero on sky
    glm::mat4 projection{1.0f};
    glm::mat4 view{1.0f};
};

//! The technique input viewing `g` (valid while g lives), on `gpu` or, when null, the C++ path.
plugin::OcclusionInput makeOcclusionInput(const SyntheticGBuffer& g, gpu::Context* gpu);

//! An infinite plane through `point` with unit normal `normal`.
struct Plane {
    glm::dvec3 point{0.0};
    glm::dvec3 normal{0.0, 1.0, 0.0};
};

//! (distance along the unit ray from the origin, normal facing the ray's origin); distance <= 0
//! or not finite: no hit.
using HitFunction = std::function<std::pair<float, glm::vec3>(const glm::vec3& direction)>;

//! A w x h G-buffer whose pixels see `hit`, vertical field of view in degrees.
SyntheticGBuffer makeSyntheticGBuffer(int w, int h, float fovDegrees, const HitFunction& hit);

//! The nearest of `planes` along a ray from the origin (as a HitFunction does).
std::pair<float, glm::vec3> hitPlanes(const glm::vec3& direction, const std::vector<Plane>& planes);

//! A G-buffer seeing the nearest of `planes`.
SyntheticGBuffer makePlanesGBuffer(int w, int h, float fovDegrees, const std::vector<Plane>& planes);

//! A floor 1 unit below the camera and a wall 4 units ahead: a crease across the image.
std::vector<Plane> makeFloorAndWall();

//! The occlusion quantity of `definition` at every surface pixel of `g`, integrated over the
//! hemisphere against the planes (the occluders are the planes alone, seen or not): a midpoint
//! rule on a `k` x `k` grid of the unit disk (cosine-weighted quantities, Malley's method) or of
//! (cos theta, phi) (uniform AO). 1 where there is no surface.
Image<float> integrateOcclusion(const SyntheticGBuffer& g, const std::vector<Plane>& planes,
                                const plugin::OcclusionDefinition& definition, int k = 64);
//! The same at given points (`positions`, in the planes' space) with their normals (zero: no
//! surface, 1 there).
Image<float> integrateOcclusion(const Image<glm::vec3>& positions, const Image<glm::vec3>& normals,
                                const std::vector<Plane>& planes, const plugin::OcclusionDefinition& definition,
                                int k = 64);

} // namespace rtlab::occlusion
