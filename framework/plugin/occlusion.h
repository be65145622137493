#pragma once
// Family `occlusion`: screen-space ambient occlusion / obscurance from a G-buffer.
// Ground truth: rays from the same G-buffer points against the full scene, computing exactly the
// quantity the technique declares (cosine-weighted AO, or obscurance with its falloff and radius).

#include "core/image.h"
#include "plugin/technique.h"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <array>
#include <string>

namespace rtlab::plugin {

//! Which integral a technique estimates; the ground truth integrates the same one.
enum class OcclusionQuantity {
    CosineAo,    //!< 1/pi * integral of V(w) cos(theta) over the hemisphere, V=1 if unoccluded in radius
    UniformAo,   //!< 1/(2 pi) * integral of V(w) over the hemisphere
    Obscurance,  //!< cosine-weighted, occluders at distance d weighted by falloff(d / radius)
};

struct OcclusionDefinition {
    OcclusionQuantity quantity = OcclusionQuantity::CosineAo;
    double radius = 1.0;  //!< world units; occluders farther than this do not count
};

//! A view of the G-buffer. View space: camera at the origin looking down -z.
struct OcclusionInput {
    const Image<float>* linearDepth = nullptr;  //!< view-space distance along -z, world units; inf = sky
    const Image<glm::vec3>* normal = nullptr;   //!< view-space unit normals (zero where no surface)
    glm::mat4 projection{1.0f};                 //!< view -> clip
    int frameIndex = 0;                          //!< for techniques that rotate samples over frames
};

struct OcclusionOutput {
    Image<float> ambient;            //!< AO or obscurance in [0, 1], 1 = unoccluded
    Image<glm::vec3> bentNormal;     //!< view space, unit length
    Image<float> coneAperture;       //!< half-angle in radians, [0, pi/2]
    std::vector<Image<float>> coneVisibility;  //!< optional: per fixed cone direction, in [0, 1]
};

class OcclusionTechnique : public Technique {
public:
    static constexpr const char* kFamily = "occlusion";
    //! The quantity and radius this instance estimates (depends on its parameters).
    virtual OcclusionDefinition definition() const = 0;
    virtual void compute(const OcclusionInput& input, OcclusionOutput& out) = 0;
};

} // namespace rtlab::plugin
