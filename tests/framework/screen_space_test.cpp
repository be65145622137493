// Screen-space conversions agree with the projection matrix, jitter included.

#include "plugin/screen_space.h"
#include "scene/camera.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

using namespace rtlab;

TEST(ScreenSpace, RoundTripsThroughTheProjectionMatrix)
{
    scene::Camera camera;
    camera.verticalFovDegrees = 60.0f;
    const int w = 37, h = 21;
    for (glm::vec2 jitter : {glm::vec2(0.0f), glm::vec2(0.25f, -0.4f)}) {
        const glm::mat4 p = camera.projectionMatrix(float(w) / float(h), jitter, {w, h});
        const auto sp = plugin::ScreenProjection::fromMatrix(p, w, h);
        for (const glm::vec3 v : {glm::vec3(0.3f, -0.2f, -2.0f), glm::vec3(-1.0f, 0.7f, -5.5f)}) {
            // The matrix's own projection, to pixels.
            const glm::vec4 clip = p * glm::vec4(v, 1.0f);
            const glm::vec2 ndc = glm::vec2(clip) / clip.w;
            const glm::vec2 pixel = (ndc + 1.0f) * 0.5f * glm::vec2(w, h);
            EXPECT_NEAR(glm::distance(sp.toPixel(v), pixel), 0.0f, 1e-4f);
            EXPECT_NEAR(glm::distance(sp.toView(pixel, -v.z), v), 0.0f, 1e-5f);
        }
        // The pixel centre's sample is at centre + jitter: the point seen there projects back to it.
        const glm::vec3 seen = sp.toView(glm::vec2(10.5f, 5.5f) + jitter, 3.0f);
        EXPECT_NEAR(glm::distance(sp.toPixel(seen), glm::vec2(10.5f, 5.5f) + jitter), 0.0f, 1e-4f);
    }
}
