#pragma once
// Scenes, G-buffers and statistics shared by the reference tests.

#include "reference/reference.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace rtlab::reference::test {

//! Appends a material; returns its index.
std::uint32_t addMaterial(scene::RenderScene& scene, glm::vec3 albedo,
                          glm::vec3 emission = glm::vec3(0.0f));
//! Appends the parallelogram corner, corner + u, corner + u + v, corner + v (two triangles,
//! normal along cross(u, v), flat normals).
void addQuad(scene::RenderScene& scene, glm::vec3 corner, glm::vec3 u, glm::vec3 v,
             std::uint32_t material);
//! Appends an icosphere (subdivided icosahedron) with flat normals and unshared vertices;
//! `inward` turns the faces and normals toward the centre.
void addIcosphere(scene::RenderScene& scene, glm::vec3 centre, float radius, int subdivisions,
                  bool inward, std::uint32_t material);
//! Appends an axis-aligned box (12 triangles, normals outward).
void addBox(scene::RenderScene& scene, glm::vec3 lo, glm::vec3 hi, std::uint32_t material);

//! A G-buffer whose pixel (x, y) is the surface point `place(x, y, position, normal)` (return
//! false for no surface), with the given albedo, emission and material 0.
scene::GBuffer makePointGBuffer(int width, int height,
                                const std::function<bool(int, int, glm::vec3&, glm::vec3&)>& place,
                                glm::vec3 albedo = glm::vec3(0.5f),
                                glm::vec3 emission = glm::vec3(0.0f));

//! Settings for tests: no cache unless asked.
ReferenceSettings makeSettings(Quantity quantity);
//! A fresh empty folder under the system's temporary folder.
std::string makeTemporaryFolder(const std::string& name);

//! A box room with an inner block, a point light, an emissive patch and an SRBF sky seen through
//! an opening in the ceiling; a G-buffer of it from a camera inside.
scene::RenderScene makeRoomScene();
scene::GBuffer makeRoomGBuffer(const scene::RenderScene& room, int width, int height);

//! Upper regularised incomplete gamma Q(a, x): the chi-square survival function is Q(k/2, x/2).
double computeGammaQ(double a, double x);
//! Gauss-Legendre nodes and weights on [-1, 1].
void getGaussLegendre(int n, std::vector<double>& nodes, std::vector<double>& weights);
//! Integral of f over [a, b] by composite Gauss-Legendre (panels x 16 points).
double integrate(const std::function<double(double)>& f, double a, double b, int panels = 64);

} // namespace rtlab::reference::test
