// The isosurface family's stress cases (plugin/stress.h). Each case is a field sampled from an
// analytic SDF (the exact value and gradient are passed too, as the harness does for analytic
// models) or written sample by sample so that zeros are exact. The checks:
// - every case: indices in range, no triangle repeating a vertex, positions and normals finite,
//   every vertex inside the grid's box up to float rounding (computeBoundsTolerance);
// - closed shapes well inside their grids: watertight (every edge shared by exactly two
//   triangles), consistently oriented, positive enclosed volume (counter-clockwise from outside);
// - closed forms: the two-sided distance between the mesh and the true surface of a sphere and a
//   torus is at most the cell diagonal sqrt(3) h (see kDistanceTolerance);
// - extreme scales (spacing 1e-5, origin 1e6 with spacing 1e3): a non-empty valid mesh;
// - exact zeros on sample planes, features thinner than a cell: valid output;
// - a positive field: an empty mesh; random sphere unions from the seed: closed and valid.

#include "families/isosurface/stress_cases.h"

#include "core/error.h"
#include "core/mesh.h"
#include "families/isosurface/isosurface.h"
#include "metrics/mesh_metrics.h"

#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>

namespace rtlab::isosurface {
namespace {

using plugin::StressCase;
using plugin::StressOutcome;
using plugin::StressSettings;
using plugin::TechniqueEntry;
using Sdf = std::function<double(const glm::dvec3&)>;

double computeSphereSdf(const glm::dvec3& p, const glm::dvec3& c, double r) { return glm::length(p - c) - r; }

double computeTorusSdf(const glm::dvec3& p, const glm::dvec3& c, double major, double minor)
{
    const glm::dvec3 q = p - c;
    return glm::length(glm::dvec2(glm::length(glm::dvec2(q.x, q.z)) - major, q.y)) - minor;
}

double computeBoxSdf(const glm::dvec3& p, const glm::dvec3& c, const glm::dvec3& half)
{
    const glm::dvec3 d = glm::abs(p - c) - half;
    return glm::length(glm::max(d, 0.0)) + std::min(std::max(d.x, std::max(d.y, d.z)), 0.0);
}

double computeRodSdf(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, double radius)
{
    const glm::dvec3 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    return glm::length(p - (a + t * ab)) - radius;
}

struct Input {
    SampledField field;
    Sdf sdf; //!< exact field; empty when the samples are written directly
};

//! n^3 samples spanning origin + [0, (n - 1) h]^3.
Input sample(int n, glm::dvec3 origin, double h, Sdf sdf)
{
    Input in;
    in.field.samples = glm::ivec3(n);
    in.field.origin = origin;
    in.field.spacing = h;
    in.field.values.resize(std::size_t(n) * n * n);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                in.field.values[in.field.index(x, y, z)] = float(sdf(in.field.position(x, y, z)));
    in.sdf = std::move(sdf);
    return in;
}

//! Samples written from sample indices, so that zeros are exact.
Input sampleIndices(glm::ivec3 n, double h, const std::function<double(int, int, int)>& value)
{
    Input in;
    in.field.samples = n;
    in.field.spacing = h;
    in.field.values.resize(std::size_t(n.x) * n.y * n.z);
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x)
                in.field.values[in.field.index(x, y, z)] = float(value(x, y, z));
    return in;
}

//! Central differences of the SDF, 1e-3 of a cell apart.
std::function<glm::dvec3(const glm::dvec3&)> makeGradient(const Sdf& sdf, double h)
{
    const double step = 1e-3 * h;
    return [sdf, step](const glm::dvec3& p) {
        glm::dvec3 g;
        for (int axis = 0; axis < 3; ++axis) {
            glm::dvec3 d(0.0);
            d[axis] = step;
            g[axis] = (sdf(p + d) - sdf(p - d)) / (2.0 * step);
        }
        return g;
    };
}

TriangleMesh extract(const TechniqueEntry& entry, const Input& in)
{
    const std::unique_ptr<plugin::Technique> technique =
        entry.create(config::ParamSet::defaultsOf(entry.schema));
    auto* iso = dynamic_cast<plugin::IsosurfaceTechnique*>(technique.get());
    if (iso == nullptr)
        throw Error(entry.info.name + " is not an isosurface technique");
    plugin::IsosurfaceInput input;
    input.field = &in.field;
    input.isoValue = 0.0;
    if (in.sdf) {
        input.exactValue = in.sdf;
        input.exactGradient = makeGradient(in.sdf, in.field.spacing);
    }
    TriangleMesh mesh;
    mesh.positions.assign(2, glm::vec3(1e30f)); // stale content must be replaced
    mesh.indices = {0, 1, 1};
    iso->extract(input, mesh);
    return mesh;
}

//! A vertex may lie outside the grid's box only by the float rounding of its coordinates: 2^-22
//! (four float ulps) of the largest coordinate magnitude of the box, plus 1e-6 of a cell.
double computeBoundsTolerance(const SampledField& field)
{
    const glm::dvec3 far = field.origin + field.spacing * glm::dvec3(field.samples - 1);
    const double magnitude = std::max(glm::length(glm::abs(field.origin)), glm::length(glm::abs(far)));
    return std::ldexp(magnitude, -22) + 1e-6 * field.spacing;
}

//! Indices in range, no repeated vertex, positions and normals finite, vertices in the grid box.
void checkMesh(const TriangleMesh& mesh, const SampledField& field, StressOutcome& o)
{
    if (mesh.indices.size() % 3 != 0) {
        o.fail("index count " + std::to_string(mesh.indices.size()) + " is not a multiple of 3");
        return;
    }
    if (!mesh.normals.empty() && mesh.normals.size() != mesh.positions.size())
        o.fail(std::to_string(mesh.normals.size()) + " normals for " + std::to_string(mesh.positions.size()) +
               " positions");
    std::size_t badIndex = 0, repeated = 0;
    for (std::size_t f = 0; f + 2 < mesh.indices.size(); f += 3) {
        const std::uint32_t a = mesh.indices[f], b = mesh.indices[f + 1], c = mesh.indices[f + 2];
        if (a >= mesh.vertexCount() || b >= mesh.vertexCount() || c >= mesh.vertexCount())
            ++badIndex;
        else if (a == b || b == c || a == c)
            ++repeated;
    }
    o.check(badIndex == 0, std::to_string(badIndex) + " triangle(s) with an index out of range");
    o.check(repeated == 0, std::to_string(repeated) + " triangle(s) repeating a vertex");
    const double tolerance = computeBoundsTolerance(field);
    const glm::dvec3 low = field.origin - tolerance;
    const glm::dvec3 high = field.origin + field.spacing * glm::dvec3(field.samples - 1) + tolerance;
    std::size_t bad = 0, outside = 0;
    for (const glm::vec3& p : mesh.positions) {
        const bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
        bad += finite ? 0 : 1;
        const glm::dvec3 q(p);
        if (finite && (glm::any(glm::lessThan(q, low)) || glm::any(glm::greaterThan(q, high))))
            ++outside;
    }
    for (const glm::vec3& n : mesh.normals)
        bad += std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z) ? 0 : 1;
    o.countValues(3 * (mesh.positions.size() + mesh.normals.size()), bad, outside,
                  "vertices (outside the grid box counts as out of range)");
}

//! Watertight, consistently oriented, positive volume.
void checkClosed(const TriangleMesh& mesh, StressOutcome& o)
{
    o.check(mesh.triangleCount() > 0, "no triangles for a closed surface inside the grid");
    if (mesh.triangleCount() == 0)
        return;
    const metrics::MeshTopology t = metrics::analyzeTopology(mesh);
    o.check(t.boundaryEdges == 0, std::to_string(t.boundaryEdges) + " edge(s) used by one triangle (holes)");
    o.check(t.nonManifoldEdges == 0, std::to_string(t.nonManifoldEdges) + " edge(s) used by three or more triangles");
    o.check(t.inconsistentEdges == 0, std::to_string(t.inconsistentEdges) + " edge(s) with inconsistent orientation");
    o.check(metrics::computeEnclosedVolume(mesh) > 0.0, "negative enclosed volume (triangles face inward)");
}

StressCase makeCase(std::string name, std::string group, std::string description, std::function<Input()> make,
                    std::function<void(const TriangleMesh&, const Input&, StressOutcome&)> more = {})
{
    return {std::move(name), std::move(group), std::move(description),
            [make, more](const TechniqueEntry& e, const StressSettings&) {
                const Input in = make();
                StressOutcome o;
                const TriangleMesh mesh = extract(e, in);
                checkMesh(mesh, in.field, o);
                if (more)
                    more(mesh, in, o);
                return o;
            }};
}

void expectClosed(const TriangleMesh& mesh, const Input&, StressOutcome& o) { checkClosed(mesh, o); }

void expectNonEmpty(const TriangleMesh& mesh, const Input&, StressOutcome& o)
{
    o.check(mesh.triangleCount() > 0, "no triangles for a sphere inside the grid");
}

//! The two-sided distance between the mesh and the exact surface, against the cell diagonal.
//! Why sqrt(3) h bounds both directions for a mesher of this family: every triangle lies in
//! the cells around the crossed edges it was made for (marching cubes: inside the crossed cell;
//! dual contouring: a quad joining the four cells around a crossed edge, each vertex clamped in
//! its cell), so each mesh point is within sqrt(3) h of a crossing of the surface; and each
//! surface point lies in a cell the surface crosses, which holds mesh within sqrt(3) h. The
//! shapes here curve slowly (radii >= 3 cells), so no crossing is missed between samples.
void expectNearTheSurface(const TriangleMesh& mesh, const Input& in, StressOutcome& o)
{
    checkClosed(mesh, o);
    if (mesh.triangleCount() == 0)
        return;
    const SampledField& f = in.field;
    const glm::dvec3 far = f.origin + f.spacing * glm::dvec3(f.samples - 1);
    const auto points = metrics::sampleSdfSurface(in.sdf, makeGradient(in.sdf, f.spacing), f.origin, far, 4000);
    metrics::MeshDistanceOptions options;
    options.meshSamples = 20000;
    const metrics::MeshDistance d = metrics::measureMeshDistance(mesh, in.sdf, points, options);
    o.compare(d.hausdorff / f.spacing, std::sqrt(3.0),
              "Hausdorff distance to the exact surface in cells (cell diagonal allowed)");
}

//! A sphere of radius 9.3 cells on 24^3 samples at the given placement.
Input makeScaledSphere(glm::dvec3 origin, double h)
{
    const glm::dvec3 center = origin + h * glm::dvec3(11.6, 11.3, 11.9);
    return sample(24, origin, h, [=](const glm::dvec3& p) { return computeSphereSdf(p, center, 9.3 * h); });
}

} // namespace

std::vector<plugin::StressCase> makeIsosurfaceStressCases()
{
    std::vector<StressCase> cases;
    const double h32 = 2.0 / 31.0; // 32^3 samples over [-1, 1]^3
    const glm::dvec3 o(-1.0);

    // Closed surfaces well inside their grids.
    cases.push_back(makeCase(
        "sphere", "closed_form", "sphere r = 0.7 on 32^3: closed, oriented, within the cell diagonal of the surface",
        [=] { return sample(32, o, h32, [](const glm::dvec3& p) { return computeSphereSdf(p, glm::dvec3(0.0), 0.7); }); },
        expectNearTheSurface));
    cases.push_back(makeCase(
        "sphere_off_centre", "closed_form", "an off-centre sphere on 29^3: as `sphere`",
        [=] {
            return sample(29, o, 2.0 / 28.0, [](const glm::dvec3& p) {
                return computeSphereSdf(p, glm::dvec3(0.113, -0.071, 0.037), 0.41);
            });
        },
        expectNearTheSurface));
    cases.push_back(makeCase(
        "torus", "closed_form", "a torus on 40^3: as `sphere`",
        [=] {
            return sample(40, o, 2.0 / 39.0, [](const glm::dvec3& p) {
                return computeTorusSdf(p, glm::dvec3(0.01, -0.02, 0.03), 0.55, 0.2);
            });
        },
        expectNearTheSurface));
    cases.push_back(makeCase(
        "box_between_sample_planes", "closed", "a box whose faces lie halfway between sample planes: closed, oriented",
        [] {
            return sample(10, glm::dvec3(0.0), 1.0,
                          [](const glm::dvec3& p) { return computeBoxSdf(p, glm::dvec3(4.0), glm::dvec3(1.5)); });
        },
        expectClosed));
    cases.push_back(makeCase(
        "box_rotated_off_grid", "closed", "a box rotated 0.3 rad about z: closed, oriented",
        [=] {
            return sample(32, o, h32, [](const glm::dvec3& p) {
                const double c = std::cos(0.3), s = std::sin(0.3);
                const glm::dvec3 q(c * p.x + s * p.y, -s * p.x + c * p.y, p.z);
                return computeBoxSdf(q, glm::dvec3(0.02, -0.03, 0.01), glm::dvec3(0.5, 0.4, 0.45));
            });
        },
        expectClosed));

    // Exact zeros on whole sample planes.
    const glm::ivec3 n(12, 11, 10);
    const double h = 0.1;
    cases.push_back(makeCase("plane_z_on_samples", "exact_zeros", "a plane through a layer of samples (exact zeros)",
                             [=] { return sampleIndices(n, h, [=](int, int, int z) { return (z - 4) * h; }); }));
    cases.push_back(makeCase("plane_x_on_samples_negated", "exact_zeros", "the same across x, sign flipped",
                             [=] { return sampleIndices(n, h, [=](int x, int, int) { return (5 - x) * h; }); }));
    cases.push_back(makeCase("plane_diagonal_on_samples", "exact_zeros", "a diagonal plane through samples", [=] {
        return sampleIndices(n, h, [=](int x, int y, int) { return (x + y - 9) * h / std::sqrt(2.0); });
    }));
    cases.push_back(makeCase("plane_on_the_first_sample_layer", "exact_zeros", "zeros on the grid's first layer",
                             [=] { return sampleIndices(n, h, [=](int, int y, int) { return y * h; }); }));
    cases.push_back(makeCase("plane_on_the_last_sample_layer", "exact_zeros", "zeros on the grid's last layer",
                             [=] { return sampleIndices(n, h, [=](int, int, int z) { return (z - 9) * h; }); }));
    cases.push_back(makeCase("box_faces_on_samples", "exact_zeros", "a box whose faces are sample planes", [] {
        return sampleIndices(glm::ivec3(10), 1.0, [](int x, int y, int z) {
            return computeBoxSdf(glm::dvec3(x, y, z), glm::dvec3(4.0), glm::dvec3(2.0));
        });
    }));
    cases.push_back(makeCase("all_zero", "exact_zeros", "every sample exactly 0",
                             [] { return sampleIndices(glm::ivec3(6), 1.0, [](int, int, int) { return 0.0; }); }));

    // Extreme scales.
    cases.push_back(makeCase("tiny_spacing_1e-5", "scale", "a sphere on a grid of spacing 1e-5: non-empty, valid",
                             [] { return makeScaledSphere(glm::dvec3(0.0), 1e-5); }, expectNonEmpty));
    cases.push_back(makeCase("tiny_spacing_1e-5_offset", "scale", "the same at (0.25, -0.5, 3)",
                             [] { return makeScaledSphere(glm::dvec3(0.25, -0.5, 3.0), 1e-5); }, expectNonEmpty));
    cases.push_back(makeCase("huge_origin_1e6_spacing_1e3", "scale", "a sphere at 1e6 on spacing 1e3",
                             [] { return makeScaledSphere(glm::dvec3(1e6), 1e3); }, expectNonEmpty));
    cases.push_back(makeCase("huge_negative_origin", "scale", "a sphere at (-1e6, 1e6, -1e6)",
                             [] { return makeScaledSphere(glm::dvec3(-1e6, 1e6, -1e6), 1e3); }, expectNonEmpty));

    // Features thinner than a cell (16^3 samples over [0, 1]^3).
    const double t = 1.0 / 15.0;
    const glm::dvec3 zero(0.0);
    cases.push_back(makeCase("plate_between_samples", "thin", "a plate 0.4 cells thick between sample planes", [=] {
        return sample(16, zero, t, [=](const glm::dvec3& p) { return std::abs(p.z - 7.5 * t) - 0.2 * t; });
    }));
    cases.push_back(makeCase("plate_through_samples", "thin", "a plate 0.4 cells thick around a sample plane", [=] {
        return sample(16, zero, t, [=](const glm::dvec3& p) { return std::abs(p.z - 7.0 * t) - 0.2 * t; });
    }));
    cases.push_back(makeCase("plate_oblique", "thin", "an oblique plate 0.3 cells thick", [=] {
        return sample(16, zero, t, [=](const glm::dvec3& p) {
            return std::abs(glm::dot(p - glm::dvec3(0.5), glm::normalize(glm::dvec3(1.0, 2.0, 3.0)))) - 0.15 * t;
        });
    }));
    cases.push_back(makeCase("rod_on_sample_line", "thin", "a rod of radius 0.3 cells along a sample line", [=] {
        return sample(16, zero, t, [=](const glm::dvec3& p) {
            return computeRodSdf(p, glm::dvec3(2 * t, 5 * t, 6 * t), glm::dvec3(13 * t, 5 * t, 6 * t), 0.3 * t);
        });
    }));
    cases.push_back(makeCase("rod_oblique", "thin", "an oblique rod of radius 0.3 cells", [=] {
        return sample(16, zero, t, [=](const glm::dvec3& p) {
            return computeRodSdf(p, glm::dvec3(0.1, 0.15, 0.2), glm::dvec3(0.9, 0.8, 0.75), 0.3 * t);
        });
    }));
    cases.push_back(makeCase("sphere_inside_one_cell", "thin", "a sphere smaller than a cell, between samples", [=] {
        return sample(16, zero, t, [=](const glm::dvec3& p) { return computeSphereSdf(p, glm::dvec3(7.5 * t), 0.3 * t); });
    }));
    cases.push_back(makeCase("sphere_around_one_sample", "thin", "a sphere smaller than a cell around a sample", [=] {
        return sample(16, zero, t, [=](const glm::dvec3& p) {
            return computeSphereSdf(p, glm::dvec3(7.0 * t, 8.0 * t, 9.0 * t), 0.3 * t);
        });
    }));
    cases.push_back(makeCase("isolated_samples", "thin", "single negative samples in a positive field", [] {
        return sampleIndices(glm::ivec3(9), 1.0,
                             [](int x, int y, int z) { return (x % 2 == 1 && y % 2 == 1 && z % 2 == 1) ? -0.5 : 0.5; });
    }));

    cases.push_back(
        {"non_finite_samples", "degenerate",
         "a sphere on 24^3 with NaN (every 13th sample), +inf (every 17th) and -inf (every 19th) samples: a "
         "valid mesh, or a clear error (rtlab::Error, std::invalid_argument)",
         [](const TechniqueEntry& e, const StressSettings&) {
             Input in = sample(24, glm::dvec3(-1.0), 2.0 / 23.0,
                               [](const glm::dvec3& p) { return computeSphereSdf(p, glm::dvec3(0.0), 0.6); });
             in.sdf = {}; // the samples no longer are the SDF's
             for (std::size_t i = 0; i < in.field.values.size(); ++i) {
                 if (i % 13 == 0)
                     in.field.values[i] = std::numeric_limits<float>::quiet_NaN();
                 else if (i % 17 == 0)
                     in.field.values[i] = std::numeric_limits<float>::infinity();
                 else if (i % 19 == 0)
                     in.field.values[i] = -std::numeric_limits<float>::infinity();
             }
             StressOutcome o;
             plugin::runOrRefuse(o, [&] { checkMesh(extract(e, in), in.field, o); });
             return o;
         }});
    cases.push_back(makeCase(
        "all_positive", "degenerate", "a field positive everywhere: an empty mesh",
        [] { return sampleIndices(glm::ivec3(7, 6, 5), 0.5, [](int x, int y, int z) { return 0.25 + 0.1 * (x + y + z); }); },
        [](const TriangleMesh& mesh, const Input&, StressOutcome& o) {
            o.check(mesh.vertexCount() == 0 && mesh.triangleCount() == 0,
                    "a positive field gave " + std::to_string(mesh.triangleCount()) + " triangle(s)");
        }));

    // Random unions of spheres from the seed, well inside a 24^3 grid.
    for (int index = 0; index < 3; ++index)
        cases.push_back({"random_spheres_" + std::to_string(index), "random",
                         "1-6 random spheres (radii 2-6 cells, 3 cells apart) on 24^3 from the seed: closed, oriented, valid",
                         [index](const TechniqueEntry& e, const StressSettings& s) {
                             std::mt19937_64 rng(s.seed * 1000003u + 17u * std::uint64_t(index + 1));
                             std::uniform_real_distribution<double> unit(0.0, 1.0);
                             const double cell = 1.0 / 23.0;
                             std::vector<std::pair<glm::dvec3, double>> spheres;
                             const int count = 1 + int(unit(rng) * 6.0);
                             // Spheres at least 3 cells apart: separate components, no
                             // near-touching pair (a feature thinner than a cell, which the
                             // `thin` cases cover without asking for a closed surface).
                             for (int i = 0, tries = 0; i < count && tries < 1000; ++tries) {
                                 const double r = (2.0 + 4.0 * unit(rng)) * cell;
                                 const glm::dvec3 c(0.3 + 0.4 * unit(rng), 0.3 + 0.4 * unit(rng), 0.3 + 0.4 * unit(rng));
                                 bool apart = true;
                                 for (const auto& [c2, r2] : spheres)
                                     apart = apart && glm::length(c - c2) > r + r2 + 3.0 * cell;
                                 if (apart) {
                                     spheres.emplace_back(c, r);
                                     ++i;
                                 }
                             }
                             const Input in = sample(24, glm::dvec3(0.0), cell, [spheres](const glm::dvec3& p) {
                                 double d = 1e30;
                                 for (const auto& [c, r] : spheres)
                                     d = std::min(d, computeSphereSdf(p, c, r));
                                 return d;
                             });
                             StressOutcome o;
                             const TriangleMesh mesh = extract(e, in);
                             checkMesh(mesh, in.field, o);
                             checkClosed(mesh, o);
                             return o;
                         }});
    return cases;
}

} // namespace rtlab::isosurface
