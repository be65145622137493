// Procedural scenes: each builds, renders to triangles and declares the right features.

#include "core/error.h"
#include "metrics/mesh_metrics.h"
#include "scene/procedural.h"
#include "scene/sdf_mesher.h"

#include <glm/geometric.hpp>
#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>

using namespace rtlab::scene;

TEST(ProceduralScenes, EveryOneBuildsToFiniteTriangles)
{
    for (const auto& name : getProceduralSceneNames()) {
        const Scene scene = makeProceduralScene(name);
        EXPECT_EQ(scene.name, name);
        const RenderScene r = scene.buildRenderScene(0);
        EXPECT_GT(r.triangleCount(), 10u) << name;
        EXPECT_EQ(r.triangleMaterial.size(), r.triangleCount()) << name;
        EXPECT_EQ(r.normals.size(), r.positions.size()) << name;
        for (std::size_t i = 0; i < r.positions.size(); ++i) {
            ASSERT_TRUE(std::isfinite(r.positions[i].x + r.positions[i].y + r.positions[i].z)) << name;
            ASSERT_NEAR(glm::length(r.normals[i]), 1.0f, 1e-3f) << name << " vertex " << i;
        }
        for (auto m : r.triangleMaterial)
            ASSERT_LT(m, r.materials.size()) << name;
        EXPECT_EQ(r.computeContentHash(), scene.buildRenderScene(0).computeContentHash()) << name;
    }
}

TEST(ProceduralScenes, UnknownNameSuggestsTheClosest)
{
    try {
        makeProceduralScene("cornel_box");
        FAIL();
    } catch (const rtlab::Error& e) {
        EXPECT_NE(std::string(e.what()).find("did you mean cornell_box?"), std::string::npos) << e.what();
    }
}

TEST(ProceduralScenes, CornellBoxHasItsClassicDimensionsAndLight)
{
    const Scene s = makeProceduralScene("cornell_box");
    const RenderScene r = s.buildRenderScene();
    EXPECT_NEAR(r.boundsMax.x, 0.556f, 1e-6f);
    EXPECT_NEAR(r.boundsMax.y, 0.5488f, 1e-6f);
    EXPECT_NEAR(r.boundsMax.z, 0.5592f, 1e-6f);
    const FeatureSet f = s.computeFeatures();
    EXPECT_TRUE(f.has(SceneFeature::Emissive));
    EXPECT_FALSE(f.has(SceneFeature::PointLights));
    EXPECT_FALSE(f.has(SceneFeature::Characters));
    EXPECT_FALSE(f.has(SceneFeature::MovingCamera));
    // Every face of the room faces its inside: the floor up, the ceiling down.
    for (std::size_t t = 0; t < r.triangleCount(); ++t) {
        const glm::vec3 a = r.positions[r.indices[3 * t]], b = r.positions[r.indices[3 * t + 1]],
                        c = r.positions[r.indices[3 * t + 2]];
        const glm::vec3 n = glm::cross(b - a, c - a);
        if (a.y == 0.0f && b.y == 0.0f && c.y == 0.0f) {
            EXPECT_GT(n.y, 0.0f) << "floor triangle " << t;
        }
        // The geometric normal agrees with the shading normal.
        EXPECT_GT(glm::dot(n, r.normals[r.indices[3 * t]]), 0.0f) << t;
    }
}

TEST(ProceduralScenes, TomorrowTownHasEveryFeatureAndChangesOverFrames)
{
    const Scene s = makeProceduralScene("tomorrow_town");
    const FeatureSet f = s.computeFeatures();
    for (SceneFeature feature : FeatureSet::getAll())
        EXPECT_TRUE(f.has(feature)) << FeatureSet::getName(feature);
    EXPECT_GE(s.characters.size(), 2u);
    // Characters walk and the camera moves.
    const auto a = s.characters[0].getCapsulesAt(s.getFrameTime(0));
    const auto b = s.characters[0].getCapsulesAt(s.getFrameTime(7));
    EXPECT_GT(glm::distance(a[0].a, b[0].a), 0.1f);
    EXPECT_GT(glm::distance(s.getCameraAt(0).position, s.getCameraAt(7).position), 0.5f);
    // A dig at frame 2 removes ground: the landscape has fewer solid points after it.
    const SdfModel& land = s.sdfModels[0];
    EXPECT_LT(land.evaluate({-2, -0.5, 6}, 1), 0.0);
    EXPECT_GT(land.evaluate({-2, -0.5, 6}, 2), 0.0);
    // The tunnel goes through the hill; the arch overhangs.
    EXPECT_GT(land.evaluate({-8, 1.2, -7}), 0.0);
    EXPECT_LT(land.evaluate({-8, 4.0, -7}), 0.0);
    EXPECT_GT(land.evaluate({6, 1.0, 5}), 0.0);   // under the arch: air
    EXPECT_LT(land.evaluate({6, 4.0, 5}), 0.0);   // the arch above it: rock
    EXPECT_NE(s.buildRenderScene(0).computeContentHash(), s.buildRenderScene(2).computeContentHash());
}

TEST(ProceduralScenes, CsgGalleryShapesAreClosedMeshes)
{
    const Scene s = makeProceduralScene("csg_gallery");
    std::vector<std::string> names;
    for (const auto& m : s.sdfModels) {
        names.push_back(m.name);
        const auto topology = rtlab::metrics::analyzeTopology(meshSdfModel(m, {.resolution = 48}).mesh);
        // Closed: no boundary edges, so rays cannot leak into a shape. Surface nets may join two
        // sheets at a sharp edge that is not aligned with the grid (a few non-manifold edges on
        // the rotated cube), which rendering tolerates; every other shape is a closed 2-manifold
        // of the right genus.
        EXPECT_EQ(topology.boundaryEdges, 0u) << m.name;
        EXPECT_GT(topology.triangles, 100u) << m.name;
        if (m.name != "rotated_cube") {
            EXPECT_TRUE(topology.watertight()) << m.name << ": " << topology.nonManifoldEdges;
            EXPECT_EQ(topology.eulerCharacteristic, m.name == "torus" ? 0 : 2) << m.name;
        }
    }
    EXPECT_EQ(names, (std::vector<std::string>{"cube", "rotated_cube", "cylinder", "box_minus_sphere", "thin_wall",
                                               "soft_spheres", "torus", "chamfered_cube"}));
}

TEST(ProceduralScenes, CsgGalleryFeatureCurvesLieOnTheSurfaceAtCreases)
{
    // Every declared feature segment lies on the zero set. Circles are polylines of 512 chords,
    // which sag by r (1 - cos(pi / 512)) <= 1.13e-5 for the largest circle (r < 0.6), hence the
    // tolerance of 1.2e-5 at chord midpoints; endpoints are exact up to rounding.
    const Scene s = makeProceduralScene("csg_gallery");
    int withFeatures = 0;
    for (const auto& m : s.sdfModels) {
        ASSERT_TRUE(m.featuresKnown) << m.name;
        if (m.featureEdges.empty())
            continue;
        ++withFeatures;
        for (const auto& [a, b] : m.featureEdges) {
            EXPECT_LT(std::abs(m.evaluate(a)), 1e-9) << m.name;
            EXPECT_LT(std::abs(m.evaluate(b)), 1e-9) << m.name;
            const glm::dvec3 mid = 0.5 * (a + b);
            EXPECT_LT(std::abs(m.evaluate(mid)), 1.2e-5) << m.name;
        }
    }
    EXPECT_EQ(withFeatures, 6) << "cube, rotated_cube, cylinder, box_minus_sphere, thin_wall, chamfered_cube";
    const auto& chamfered = *std::find_if(s.sdfModels.begin(), s.sdfModels.end(),
                                          [](const SdfModel& m) { return m.name == "chamfered_cube"; });
    EXPECT_EQ(chamfered.featureEdges.size(), 48u);
}
