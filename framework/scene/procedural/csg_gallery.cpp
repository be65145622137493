// Sharp-feature shapes for isosurface studies: each is its own SDF model (so a study can pick one
// by name), laid out on a grid for rendering. Every shape fits a 1.6 m box around its centre.

#include "scene/procedural.h"

#include <glm/gtc/quaternion.hpp>

#include <cmath>

namespace rtlab::scene {

namespace {

using Segment = std::pair<glm::dvec3, glm::dvec3>;

// The 12 edges of the box {rotation * x : |x_i| <= h_i} (model space).
std::vector<Segment> makeBoxEdges(glm::dvec3 h, glm::dquat rotation)
{
    std::vector<Segment> out;
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int su = -1; su <= 1; su += 2)
            for (int sv = -1; sv <= 1; sv += 2) {
                glm::dvec3 a(0.0), b(0.0);
                a[axis] = -h[axis];
                b[axis] = h[axis];
                a[u] = b[u] = su * h[u];
                a[v] = b[v] = sv * h[v];
                out.push_back({rotation * a, rotation * b});
            }
    }
    return out;
}

// The parts of a curve c(u), u in [0, 1], where `keep` holds, as a polyline of `pieces` segments;
// a piece that `keep` cuts is cut where it does, found by bisection on u (to double precision).
template <class Curve, class Keep>
void appendPolyline(std::vector<Segment>& out, Curve curve, int pieces, Keep keep)
{
    auto boundary = [&](double inside, double outside) {
        for (int i = 0; i < 80; ++i) {
            const double mid = 0.5 * (inside + outside);
            (keep(curve(mid)) ? inside : outside) = mid;
        }
        return inside;
    };
    for (int i = 0; i < pieces; ++i) {
        double u0 = double(i) / pieces, u1 = double(i + 1) / pieces;
        const bool k0 = keep(curve(u0)), k1 = keep(curve(u1));
        if (!k0 && !k1)
            continue;
        if (!k0)
            u0 = boundary(u1, u0);
        if (!k1)
            u1 = boundary(u0, u1);
        out.push_back({curve(u0), curve(u1)});
    }
}

constexpr int kCirclePieces = 512;  // chord sag r (1 - cos(pi / 512)) ~ 2e-5 r

} // namespace

Scene makeCsgGallery()
{
    Scene s;
    s.materials = {{"clay", glm::vec3(0.7f), glm::vec3(0.0f)}, {"floor", glm::vec3(0.5f), glm::vec3(0.0f)}};
    auto model = [&](const char* name, int slot, std::vector<CsgEdit> edits, std::vector<Segment> features = {}) {
        const glm::dvec3 c(3.0 * (slot % 4) - 4.5, 0.8, 3.0 * (slot / 4) - 1.5);
        SdfModel m{.name = name};
        for (auto& e : edits) {
            e.center += c;
            m.edits.push_back(e);
        }
        m.boundsMin = c - glm::dvec3(0.8);
        m.boundsMax = c + glm::dvec3(0.8);
        m.resolution = 64;
        for (const auto& [a, b] : features)
            m.featureEdges.push_back({a + c, b + c});
        m.featuresKnown = true;
        s.sdfModels.push_back(std::move(m));
    };
    // Spelled out: a value-initialised glm quaternion is all zeros, not the identity.
    const glm::dquat kNoRotation(1.0, 0.0, 0.0, 0.0);
    auto edit = [](CsgShape shape, CsgOp op, glm::dvec3 size, glm::dquat rot = glm::dquat(1, 0, 0, 0),
                   glm::dvec3 offset = glm::dvec3(0.0), double blend = 0.0) {
        CsgEdit e;
        e.shape = shape;
        e.op = op;
        e.size = size;
        e.rotation = rot;
        e.center = offset;
        e.blend = blend;
        return e;
    };
    const glm::dquat tilt = glm::angleAxis(glm::radians(30.0), glm::normalize(glm::dvec3(1, 1, 0))) *
                            glm::angleAxis(glm::radians(20.0), glm::dvec3(0, 0, 1));
    const double pi = 3.14159265358979323846;
    model("cube", 0, {edit(CsgShape::Box, CsgOp::Add, glm::dvec3(0.5))}, makeBoxEdges(glm::dvec3(0.5), kNoRotation));
    model("rotated_cube", 1, {edit(CsgShape::Box, CsgOp::Add, glm::dvec3(0.45), tilt)},
          makeBoxEdges(glm::dvec3(0.45), tilt));
    {
        // Two rims of radius 0.45 at y = +-0.6.
        std::vector<Segment> rims;
        for (double y : {-0.6, 0.6})
            appendPolyline(
                rims, [&](double u) { return glm::dvec3(0.45 * std::cos(2 * pi * u), y, 0.45 * std::sin(2 * pi * u)); },
                kCirclePieces, [](const glm::dvec3&) { return true; });  // keep every piece
        model("cylinder", 2, {edit(CsgShape::Cylinder, CsgOp::Add, {0.45, 0.6, 0})}, rims);
    }
    {
        // Box edges outside the sphere, and the sphere's circles on the three faces it cuts.
        const glm::dvec3 sc(0.35), h(0.5);
        const double r = 0.6;
        auto outsideSphere = [&](const glm::dvec3& p) { return glm::length(p - sc) >= r; };
        auto onBox = [&](const glm::dvec3& p) {
            return std::abs(p.x) <= h.x + 1e-12 && std::abs(p.y) <= h.y + 1e-12 && std::abs(p.z) <= h.z + 1e-12;
        };
        std::vector<Segment> features;
        for (const auto& edge : makeBoxEdges(h, kNoRotation)) {
            // Not a structured binding: lambdas may not capture those before clang 16.
            const glm::dvec3 a = edge.first, b = edge.second;
            appendPolyline(features, [&](double u) { return a + u * (b - a); }, 1, outsideSphere);
        }
        for (int axis = 0; axis < 3; ++axis) {
            const int u = (axis + 1) % 3, v = (axis + 2) % 3;
            const double rho = std::sqrt(r * r - (h[axis] - sc[axis]) * (h[axis] - sc[axis]));
            appendPolyline(
                features,
                [&](double t) {
                    glm::dvec3 p(0.0);
                    p[axis] = h[axis];
                    p[u] = sc[u] + rho * std::cos(2 * pi * t);
                    p[v] = sc[v] + rho * std::sin(2 * pi * t);
                    return p;
                },
                kCirclePieces, onBox);
        }
        model("box_minus_sphere", 3,
              {edit(CsgShape::Box, CsgOp::Add, h), edit(CsgShape::Sphere, CsgOp::Subtract, {r, 0, 0}, kNoRotation, sc)},
              features);
    }
    model("thin_wall", 4, {edit(CsgShape::Box, CsgOp::Add, {0.6, 0.6, 0.02})},  // 4 cm thick
          makeBoxEdges({0.6, 0.6, 0.02}, kNoRotation));
    // Smooth shapes: no sharp features at all (the blend of the soft spheres is smooth).
    model("soft_spheres", 5, {edit(CsgShape::Sphere, CsgOp::Add, {0.35, 0, 0}, kNoRotation, {-0.25, 0, 0}),
                              edit(CsgShape::Sphere, CsgOp::Add, {0.3, 0, 0}, kNoRotation, {0.3, 0.1, 0}, 0.25)});
    model("torus", 6, {edit(CsgShape::Torus, CsgOp::Add, {0.5, 0.18, 0})});
    // Chamfered cube: a cube intersected with three slabs rotated 45 degrees about x, y and z,
    // which cut its twelve edges into 45-degree chamfers of width 0.15 on each face.
    const double h = 0.5, chamfer = 0.15;
    const double a = (2.0 * h - chamfer) / std::sqrt(2.0);
    std::vector<CsgEdit> chamfered = {edit(CsgShape::Box, CsgOp::Add, glm::dvec3(h))};
    chamfered.push_back(edit(CsgShape::Box, CsgOp::Intersect, {1.0, a, a}, glm::angleAxis(glm::radians(45.0), glm::dvec3(1, 0, 0))));
    chamfered.push_back(edit(CsgShape::Box, CsgOp::Intersect, {a, 1.0, a}, glm::angleAxis(glm::radians(45.0), glm::dvec3(0, 1, 0))));
    chamfered.push_back(edit(CsgShape::Box, CsgOp::Intersect, {a, a, 1.0}, glm::angleAxis(glm::radians(45.0), glm::dvec3(0, 0, 1))));
    {
        // Each face keeps a square of half side h - chamfer (4 edges, 24 in all); at each corner
        // s = (+-1, +-1, +-1) three chamfer planes x_i + x_j = 2h - chamfer meet at s (h - chamfer/2),
        // joined to the three adjacent face-square corners (24 edges).
        const double k = h - chamfer;
        std::vector<Segment> features;
        for (int axis = 0; axis < 3; ++axis)
            for (int side = -1; side <= 1; side += 2) {
                glm::dvec3 inset(k);
                inset[axis] = h;
                for (const auto& [p, q] : makeBoxEdges(inset, kNoRotation))
                    if (p[axis] == q[axis] && p[axis] == side * h)  // edges in that face's plane
                        features.push_back({p, q});
            }
        for (int corner = 0; corner < 8; ++corner) {
            const glm::dvec3 sign(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
            const glm::dvec3 apex = sign * (h - 0.5 * chamfer);
            for (int axis = 0; axis < 3; ++axis) {
                glm::dvec3 q = sign * k;
                q[axis] = sign[axis] * h;
                features.push_back({apex, q});
            }
        }
        model("chamfered_cube", 7, chamfered, features);
    }

    MeshInstance floor{.name = "floor"};
    appendQuad(floor, {-7, 0, -4}, {7, 0, -4}, {7, 0, 4}, {-7, 0, 4}, 1, {0, 1, 0});
    s.meshes.push_back(std::move(floor));
    s.sky.kind = Sky::Kind::Gradient;
    s.sky.zenith = glm::vec3(1.0f);
    s.sky.horizon = glm::vec3(0.6f);
    s.sky.ground = glm::vec3(0.2f);
    s.camera.position = {0.0f, 4.5f, 9.0f};
    s.camera.target = {0.0f, 0.6f, 0.0f};
    s.camera.verticalFovDegrees = 45.0f;
    s.camera.farPlane = 40.0f;
    return s;
}

} // namespace rtlab::scene
