#pragma once
// What dual contouring's test files share: analytic SDFs with gradients (sphere, box, torus),
// sampling, extraction with parameter overrides, and the watertightness, manifoldness and
// sharp-box checks.

#include "dual_contouring.h"
#include "extraction.h"
#include "isosurface/case_table.h"
#include "isosurface_test_support.h"
#include "plugin/technique.h"
#include "qef.h"
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <tbb/task_arena.h>
#include <unordered_map>
#include <vector>

namespace rtlab::isosurface::dc_test {

using namespace rtlab::test;
using Overrides = ParamOverrides;
//! A signed distance function with its gradient, written here so the tests do not depend on the
//! framework's SDF evaluator.
struct Sdf {
    std::function<double(const glm::dvec3&)> value;
    std::function<glm::dvec3(const glm::dvec3&)> gradient;
};

inline Sdf makeSphere(glm::dvec3 center, double radius)
{
    return {[=](const glm::dvec3& p) { return glm::length(p - center) - radius; },
            [=](const glm::dvec3& p) {
                const glm::dvec3 d = p - center;
                const double l = glm::length(d);
                return l > 0.0 ? d / l : glm::dvec3(0.0, 0.0, 1.0);
            }};
}

//! Rotation by angles about x, then y, then z.
inline glm::dmat3 makeRotation(double ax, double ay, double az)
{
    const glm::dmat3 rx(1, 0, 0, 0, std::cos(ax), std::sin(ax), 0, -std::sin(ax), std::cos(ax));
    const glm::dmat3 ry(std::cos(ay), 0, -std::sin(ay), 0, 1, 0, std::sin(ay), 0, std::cos(ay));
    const glm::dmat3 rz(std::cos(az), std::sin(az), 0, -std::sin(az), std::cos(az), 0, 0, 0, 1);
    return rz * ry * rx;
}

//! Box of half extents `half` centred at `center`, rotated by `rotation` (box frame to world).
struct Box {
    glm::dvec3 center{0.0};
    glm::dvec3 half{0.5};
    glm::dmat3 rotation{1.0};

    glm::dvec3 toLocal(const glm::dvec3& p) const
    {
        return glm::transpose(rotation) * (p - center);
    }
    double value(const glm::dvec3& p) const
    {
        const glm::dvec3 q = glm::abs(toLocal(p)) - half;
        return glm::length(glm::max(q, 0.0)) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
    }
    glm::dvec3 gradient(const glm::dvec3& p) const
    {
        const glm::dvec3 local = toLocal(p);
        const glm::dvec3 q = glm::abs(local) - half;
        const glm::dvec3 sign(local.x < 0 ? -1.0 : 1.0, local.y < 0 ? -1.0 : 1.0,
                              local.z < 0 ? -1.0 : 1.0);
        glm::dvec3 g(0.0);
        if (std::max(q.x, std::max(q.y, q.z)) > 0.0) {
            g = glm::normalize(glm::max(q, 0.0)) * sign;
        } else {
            const int k = q.x >= q.y && q.x >= q.z ? 0 : (q.y >= q.z ? 1 : 2);
            g[k] = sign[k];
        }
        return rotation * g;
    }
    Sdf sdf() const
    {
        const Box box = *this;
        return {[box](const glm::dvec3& p) { return box.value(p); },
                [box](const glm::dvec3& p) { return box.gradient(p); }};
    }
    std::array<glm::dvec3, 8> corners() const
    {
        std::array<glm::dvec3, 8> c;
        for (int k = 0; k < 8; ++k) {
            const glm::dvec3 s(k & 1 ? 1.0 : -1.0, k & 2 ? 1.0 : -1.0, k & 4 ? 1.0 : -1.0);
            c[k] = center + rotation * (s * half);
        }
        return c;
    }
    //! Distance from p to the plane of face (axis, side), in world units.
    double distanceToFacePlane(const glm::dvec3& p, int axis, int side) const
    {
        const double coordinate = toLocal(p)[axis];
        return std::abs(coordinate - (side ? half[axis] : -half[axis]));
    }
};

//! Torus around the z axis.
inline Sdf makeTorus(double major, double minor)
{
    return {[=](const glm::dvec3& p) {
                const double ring = std::sqrt(p.x * p.x + p.y * p.y) - major;
                return std::sqrt(ring * ring + p.z * p.z) - minor;
            },
            [=](const glm::dvec3& p) {
                const double rho = std::sqrt(p.x * p.x + p.y * p.y);
                const double ring = rho - major;
                const double l = std::sqrt(ring * ring + p.z * p.z);
                if (!(rho > 0.0) || !(l > 0.0))
                    return glm::dvec3(0.0);
                return glm::dvec3(ring / l * p.x / rho, ring / l * p.y / rho, p.z / l);
            }};
}

//! n^3 samples spanning [-1, 1]^3 (spacing 2 / (n - 1)).
inline plugin::SampledField sampleUnitCube(int n, const Sdf& sdf)
{
    return test::sampleUnitCube(n, sdf.value);
}

inline config::ParamSet makeParams(const Overrides& overrides = {})
{
    return test::makeParams<DualContouring>(overrides);
}

struct Extraction {
    TriangleMesh mesh;
    dc::ExtractionStats stats;
    std::map<std::string, double> counters;
};

//! Runs the technique; `sdf` (when given) supplies exactValue and exactGradient.
inline Extraction extract(const plugin::SampledField& field, const Sdf* sdf,
                          const Overrides& overrides = {},
                          const std::vector<std::uint32_t>* materials = nullptr,
                          const plugin::HermiteData* hermite = nullptr)
{
    DualContouring technique(makeParams(overrides));
    plugin::IsosurfaceInput input;
    input.field = &field;
    if (sdf != nullptr) {
        input.exactValue = sdf->value;
        input.exactGradient = sdf->gradient;
    }
    input.materials = materials;
    input.hermite = hermite;
    Extraction result;
    technique.extract(input, result.mesh);
    result.stats = technique.stats();
    for (const auto& [name, value] : technique.counters())
        result.counters[name] = value;
    return result;
}

//! Watertight in the weaker sense that holds at non-manifold edges too: every directed edge is
//! matched by as many reverse uses.
inline void expectWatertight(const Topology& t)
{
    EXPECT_EQ(t.badIndices, 0u);
    EXPECT_EQ(t.unbalancedEdges, 0u) << "holes or inconsistent orientation";
    EXPECT_EQ(t.unreferencedVertices, 0u);
}

//! Vertices whose triangles do not form one closed fan (a single cycle of opposite edges): the
//! vertex-manifold condition that edge-manifoldness alone does not imply.
inline std::size_t countNonManifoldVertices(const TriangleMesh& mesh)
{
    std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> link(mesh.vertexCount());
    for (std::size_t f = 0; f < mesh.triangleCount(); ++f) {
        const std::uint32_t v[3] = {mesh.indices[3 * f], mesh.indices[3 * f + 1],
                                    mesh.indices[3 * f + 2]};
        for (int k = 0; k < 3; ++k)
            link[v[k]].push_back({v[(k + 1) % 3], v[(k + 2) % 3]});
    }
    std::size_t bad = 0;
    for (const auto& fan : link) {
        if (fan.empty())
            continue;
        std::unordered_map<std::uint32_t, std::uint32_t> next;
        bool ok = true;
        for (const auto& [a, b] : fan)
            ok = next.emplace(a, b).second && ok;
        std::size_t steps = 0;
        std::uint32_t at = fan.front().first;
        do {
            const auto it = next.find(at);
            if (it == next.end()) {
                ok = false;
                break;
            }
            at = it->second;
            ++steps;
        } while (at != fan.front().first && steps <= fan.size());
        bad += !(ok && steps == fan.size());
    }
    return bad;
}

//! Checks that the mesh of `box` has a vertex on each corner, every vertex on the surface and
//! every triangle in one face plane, all within `tolerance` world units.
inline void expectSharpBox(const TriangleMesh& mesh, const Box& box, double tolerance)
{
    for (const glm::dvec3& corner : box.corners()) {
        double nearest = std::numeric_limits<double>::infinity();
        for (const glm::vec3& p : mesh.positions)
            nearest = std::min(nearest, glm::length(glm::dvec3(p) - corner));
        EXPECT_LE(nearest, tolerance)
            << "corner " << corner.x << " " << corner.y << " " << corner.z;
    }
    double worstSurface = 0.0;
    for (const glm::vec3& p : mesh.positions)
        worstSurface = std::max(worstSurface, std::abs(box.value(glm::dvec3(p))));
    EXPECT_LE(worstSurface, tolerance);
    // Faces stay planar: each triangle lies in the plane of one face.
    std::size_t offPlane = 0;
    double worstTriangle = 0.0;
    for (std::size_t f = 0; f < mesh.triangleCount(); ++f) {
        double best = std::numeric_limits<double>::infinity();
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                double d = 0.0;
                for (int k = 0; k < 3; ++k)
                    d = std::max(
                        d, box.distanceToFacePlane(
                               glm::dvec3(mesh.positions[mesh.indices[3 * f + k]]), axis, side));
                best = std::min(best, d);
            }
        worstTriangle = std::max(worstTriangle, best);
        offPlane += best > tolerance;
    }
    EXPECT_EQ(offPlane, 0u) << "worst triangle is " << worstTriangle << " off every face plane";
}

} // namespace rtlab::isosurface::dc_test
