#pragma once
// The fixture of the lighting and shadow pass tests (lighting_pass_test.cpp,
// shadow_pass_test.cpp): a G-buffer pass, a shadow pass and a lighting pass on one device, and
// the small helpers both use.

#include <glm/vec3.hpp>

#include <cstdint>
#include <optional>

#include "render/lighting_pass.h"
#include "render/shadow_pass.h"
#include "render_test_support.h"

namespace rtlab::render::test {

inline const glm::vec3 kAlbedo(0.8f, 0.6f, 0.4f);

inline scene::Camera makeCamera(glm::vec3 position, glm::vec3 target)
{
    scene::Camera c;
    c.position = position;
    c.target = target;
    c.up = {0.0f, 1.0f, 0.0f};
    c.verticalFovDegrees = 60.0f;
    c.nearPlane = 0.05f;
    c.farPlane = 100.0f;
    return c;
}

// A floor y = 0 over [-h, h]^2 facing up.
inline void addFloor(SceneBuilder& b, float h, std::uint32_t material)
{
    b.addQuad({-h, 0, h}, {h, 0, h}, {h, 0, -h}, {-h, 0, -h}, material);
}

class LightingPassTest : public RenderTest {
protected:
    void SetUp() override
    {
        RenderTest::SetUp();
        if (HasFatalFailure())
            return;
        ShadowPassOptions shadowOptions;
        shadowOptions.compiler = getCompiler().getOptions();
        mShadows.emplace(getContext(), shadowOptions);
        LightingPassOptions lightingOptions;
        lightingOptions.compiler = getCompiler().getOptions();
        mLighting.emplace(getContext(), lightingOptions);
    }
    void TearDown() override
    {
        mLighting.reset();
        mShadows.reset();
        RenderTest::TearDown();
    }

    ShadowPass& getShadows() { return *mShadows; }
    LightingPass& getLighting() { return *mLighting; }

    //! G-buffer, shadow maps and lighting of one frame; returns the CPU G-buffer.
    scene::GBuffer drawFrame(const scene::RenderScene& s, const scene::Camera& camera, int w, int h,
                             LightingInputs inputs = {})
    {
        getPass().setScene(s);
        getPass().draw(camera, w, h);
        getShadows().render(s);
        inputs.gbuffer = &getPass().getTarget();
        inputs.camera = camera;
        if (inputs.shadows == nullptr)
            inputs.shadows = &getShadows();
        getLighting().draw(s, inputs);
        return getPass().readBack();
    }

private:
    std::optional<ShadowPass> mShadows;
    std::optional<LightingPass> mLighting;
};

class ShadowPassTest : public LightingPassTest {
public:
    gpu::Context& getContextForTest() { return getContext(); }
};

} // namespace rtlab::render::test
