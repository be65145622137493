#pragma once
// Camera rays of a G-buffer's pixels (internal to rtlab_reference), from its own view and
// projection matrices so that they match what the rasteriser drew, jitter included.

#include "scene/gbuffer.h"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace rtlab::reference {

class CameraRays {
public:
    explicit CameraRays(const scene::GBuffer& gbuffer);

    //! Point on the near plane through the centre of pixel (x, y).
    glm::dvec3 getOrigin(int x, int y) const;
    //! Unit direction through the centre of pixel (x, y), away from the camera.
    glm::dvec3 getDirection(int x, int y) const;

private:
    glm::dvec3 unproject(int x, int y, double depth) const;

    glm::dmat4 mClipToWorld{1.0};
    int mWidth = 1;
    int mHeight = 1;
};

} // namespace rtlab::reference
