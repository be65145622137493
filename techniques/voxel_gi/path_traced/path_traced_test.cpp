// Unit test of path_traced: its error against the ground truth falls like 1/sqrt(paths), and it
// refuses to run without a scene.

#include "families/voxel_gi/voxel_gi.h"
#include "families/voxel_gi/voxel_gi_test_scenes.h"

#include "core/error.h"
#include "metrics/image_metrics.h"
#include "reference/reference.h"

#include <gtest/gtest.h>

void rtlabRegisterTechnique_voxel_gi_path_traced(rtlab::plugin::Registry&);

using namespace rtlab;
using namespace rtlab::voxelgi::testing;

namespace {

std::unique_ptr<plugin::Technique> make(int samples)
{
    return createTechnique(rtlabRegisterTechnique_voxel_gi_path_traced, "path_traced",
                           {{"samples_per_pixel", std::int64_t(samples)}});
}

TEST(PathTraced, ErrorFallsLikeOneOverRootOfThePaths)
{
    // A room lit by a point light: the floor's indirect light comes from the lit walls.
    scene::RenderScene s;
    addRoom(s, glm::vec3(-1.0f), glm::vec3(1.0f), 0.1f, addMaterial(s, glm::vec3(0.7f)));
    s.pointLights.push_back({glm::vec3(0.3f, 0.6f, 0.2f), glm::vec3(2.0f)});
    scene::Camera camera;
    camera.position = {0.0f, 0.5f, 0.9f};
    camera.target = {0.0f, -1.0f, 0.0f};
    const scene::GBuffer g = reference::castGBuffer(s, camera, 24, 16);
    reference::ReferenceSettings truthSettings;
    truthSettings.quantity = reference::Quantity::Indirect;
    truthSettings.useCache = false;
    truthSettings.maxSamples = 4096;
    truthSettings.targetStdErr = 0.001;
    truthSettings.targetRelStdErr = 0.002;
    const auto truth = reference::computeReference(s, g, truthSettings).irradiance;
    double rmse[2];
    int i = 0;
    for (const int n : {4, 64}) {
        auto t = make(n);
        auto& gi = dynamic_cast<plugin::VoxelGiTechnique&>(*t);
        plugin::VoxelGiInput input;
        input.gbuffer = &g;
        input.scene = &s;
        Image<glm::vec3> e;
        gi.gather(input, e);
        rmse[i++] = metrics::computeRmse(e, truth);
    }
    // 16x the paths: 1/4 of the noise in theory; 1/2.5 leaves room for the reference's own
    // noise and for the estimate of an RMSE from 384 pixels.
    EXPECT_GT(rmse[0], 0.0);
    EXPECT_LT(rmse[1], rmse[0] / 2.5);
}

TEST(PathTraced, NeedsTheScene)
{
    auto t = make(1);
    auto& gi = dynamic_cast<plugin::VoxelGiTechnique&>(*t);
    scene::GBuffer g;
    plugin::VoxelGiInput input;
    input.gbuffer = &g;
    Image<glm::vec3> e;
    EXPECT_THROW(gi.gather(input, e), Error);
}

} // namespace
