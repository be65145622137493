#pragma once
// SDF models as CSG edit lists, after the Dreams model: an ordered list of primitive edits, each
// adding, subtracting or intersecting a primitive with the result so far, optionally with a soft
// blend of a given radius. The soft blend reverts exactly to the hard min/max once the two
// distances differ by more than the radius, so that far-away edits can be culled.
// Seed: shared/seeds/001_5c6096db92814698.txt (Dreams, "CSG edit list", "soft blend breaks all the
// culling"); digs over frames: shared/seeds/000_3da000e866ebc485.txt (the landscape is dug and
// built at run time).

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace rtlab::scene {

enum class CsgShape { Sphere, Box, RoundedBox, Cylinder, Cone, Torus, Ellipsoid, Capsule };
enum class CsgOp { Add, Subtract, Intersect };

//! "sphere", "box", ... (the names used in scene files).
const char* toString(CsgShape shape);
const char* toString(CsgOp op);
const std::vector<std::string>& getCsgShapeNames();
const std::vector<std::string>& getCsgOpNames();

//! One edit. Shapes are defined in their local frame (centre at the origin, axis along y), then
//! rotated and moved to `center`.
struct CsgEdit {
    CsgShape shape = CsgShape::Sphere;
    CsgOp op = CsgOp::Add;
    glm::dvec3 center{0.0};                 //!< world units
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  //!< local -> world
    //! sphere: x = radius; box / rounded box: half extents; cylinder: x = radius, y = half height;
    //! cone: x = base radius, y = half height (apex up); torus: x = major, y = minor radius;
    //! ellipsoid: semi-axes; capsule: x = radius, y = half length of the segment.
    glm::dvec3 size{1.0};
    double rounding = 0.0;      //!< rounded box corner radius, world units, < min half extent
    double blend = 0.0;         //!< soft blend radius, world units; 0 = hard
    std::uint32_t material = 0; //!< index into the scene's materials
    int frame = 0;              //!< first frame the edit is applied in (digs over time)

    //! Signed distance to this primitive alone. Exact for every shape except the ellipsoid, for
    //! which it is the common first-order bound (|value| <= true distance near the surface).
    double evaluatePrimitive(const glm::dvec3& p) const;
    //! A bound on the primitive's extent: every point with distance <= 0 lies in this box.
    void getBounds(glm::dvec3& lo, glm::dvec3& hi) const;
    //! The field after this edit at p, given the field d before it (SdfModel::evaluate folds
    //! this over its edits in list order; the incremental mesher folds new edits the same way).
    double applyTo(double d, const glm::dvec3& p) const;
};

//! Polynomial smooth minimum with blend radius k [Quilez 2013]: equal to min(a, b) when
//! |a - b| >= k, so a soft edit has no influence farther than k from its own surface.
double computeSmoothMin(double a, double b, double k);

//! An edit list with the box in which it is meshed.
struct SdfModel {
    std::string name;
    std::vector<CsgEdit> edits;
    glm::dvec3 boundsMin{-1.0};  //!< region the model lives in, world units
    glm::dvec3 boundsMax{1.0};
    int resolution = 96;         //!< samples along the longest side when meshed for rendering
    //! The model's sharp feature curves as straight segments (world units; curved features as
    //! fine polylines), for the edge metrics of isosurface studies. Meaningful when featuresKnown:
    //! then it is the complete list (empty for a smooth model).
    std::vector<std::pair<glm::dvec3, glm::dvec3>> featureEdges;
    bool featuresKnown = false;

    //! Field after every edit whose frame <= `frame` (negative inside). An empty list is +inf.
    double evaluate(const glm::dvec3& p, int frame = 1 << 30) const;
    //! Unit gradient by central differences of evaluate() (step relative to the bounds).
    glm::dvec3 evaluateGradient(const glm::dvec3& p, int frame = 1 << 30) const;
    //! Material of the edit that determines the surface at p (the last additive edit that is
    //! within its blend radius of the final value; 0 when none).
    std::uint32_t evaluateMaterial(const glm::dvec3& p, int frame = 1 << 30) const;
    //! True when some edit starts after frame 0.
    bool changesOverTime() const;
};

} // namespace rtlab::scene
