// Normals as mesh files mean them (scene/mesh_loader.h, "Normals"): an OBJ's vn, else its
// smoothing groups, else flat faces; the scene file's overrides (flat, smooth, a crease angle).

#include "scene/mesh_loader.h"

#include "mesh_loader_test_support.h"

#include <glm/geometric.hpp>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>

using namespace rtlab::scene;
using namespace rtlab::scene::test;
using ::testing::HasSubstr;

namespace {

// Two triangles sharing vertex 1: a large one facing +z and a small one facing +x.
const char kHingeObj[] = "v 0 0 0\n"
                         "v 2 0 0\n"
                         "v 0 2 0\n"
                         "v 0 -1 0\n"
                         "v 0 0 1\n";

TEST(MeshLoaderObj, WithoutNormalsOrSmoothingGroupsFacesAreFlat)
{
    // No vn and no `s`: the file means flat faces (Blender, Assimp and tinyobjloader read it
    // so), so the shared vertex becomes one vertex per face, each with its face's normal.
    TempDir dir("flat");
    const LoadedMesh mesh = loadMesh(dir.write("flat.obj", std::string(kHingeObj) + "f 1 2 3\nf 1 5 4\n"));
    ASSERT_EQ(mesh.triangleCount(), 2u);
    EXPECT_EQ(mesh.positions.size(), 6u);
    for (int c = 0; c < 3; ++c) {
        expectVec3Near(mesh.normals[mesh.indices[c]], {0, 0, 1});
        expectVec3Near(mesh.normals[mesh.indices[3 + c]], {1, 0, 0});
    }
    EXPECT_EQ(mesh.normalsSource, "flat (no vn, no smoothing groups)");
}

TEST(MeshLoaderObj, SmoothingGroupNormalsAreAreaWeighted)
{
    // In one smoothing group the shared vertex's normal leans towards +z in proportion to the
    // areas (2 and 0.5: cross lengths 4 and 1).
    TempDir dir("area");
    const LoadedMesh mesh =
        loadMesh(dir.write("area.obj", std::string(kHingeObj) + "s 1\nf 1 2 3\nf 1 5 4\n"));
    ASSERT_EQ(mesh.positions.size(), 5u);
    expectVec3Near(mesh.normals[0], glm::normalize(glm::vec3(1, 0, 4)));
    expectVec3Near(mesh.normals[1], {0, 0, 1});
    expectVec3Near(mesh.normals[3], {1, 0, 0});
    EXPECT_EQ(mesh.normalsSource, "smoothing groups");
}

TEST(MeshLoaderObj, SmoothingGroupsSeparateAndOffIsFlat)
{
    TempDir dir("groups");
    // Different groups: no smoothing across the shared edge.
    const LoadedMesh two =
        loadMesh(dir.write("two.obj", std::string(kHingeObj) + "s 1\nf 1 2 3\ns 2\nf 1 5 4\n"));
    EXPECT_EQ(two.positions.size(), 6u);
    expectVec3Near(two.normals[two.indices[0]], {0, 0, 1});
    expectVec3Near(two.normals[two.indices[3]], {1, 0, 0});
    // `s off` and `s 0` are flat; faces before the first `s` too.
    for (const char* off : {"s off\n", "s 0\n"}) {
        const LoadedMesh flat =
            loadMesh(dir.write("off.obj", std::string(kHingeObj) + off + "f 1 2 3\nf 1 5 4\n"));
        EXPECT_EQ(flat.positions.size(), 6u) << off;
    }
    const LoadedMesh before =
        loadMesh(dir.write("before.obj", std::string(kHingeObj) + "f 1 2 3\ns 1\nf 1 5 4\n"));
    EXPECT_EQ(before.positions.size(), 6u);
    // A malformed group names its line.
    const std::string bad = dir.write("bad.obj", std::string(kHingeObj) + "s smooth\nf 1 2 3\n");
    EXPECT_THAT(expectInputError(bad).what(), HasSubstr("bad.obj:6"));
    EXPECT_THAT(expectInputError(bad).what(), HasSubstr("expected a number >= 0 or 'off'"));
}

TEST(MeshLoaderObj, NormalModesOverrideTheFile)
{
    // A unit cube (8 shared corners, 12 triangles, no vn, no s).
    TempDir dir("modes");
    const std::string cube = dir.write("cube.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                                   "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                                   "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\n"
                                                   "f 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n");
    // Flat (the file's meaning): four vertices per face, each with the face's normal.
    const LoadedMesh flat = loadMesh(cube);
    EXPECT_EQ(flat.positions.size(), 24u);
    // Smooth: one vertex per corner, its normal the area-weighted mean of its three faces' (a
    // face's fan apex counts both of its triangles), so within 20 degrees of the diagonal:
    // cos = 4 / (sqrt 6 sqrt 3) = 0.943 at worst, where one face counts twice.
    const LoadedMesh smooth = loadMesh(cube, {.normals = {NormalMode::Kind::Smooth}});
    ASSERT_EQ(smooth.positions.size(), 8u);
    for (std::size_t v = 0; v < 8; ++v) {
        const glm::vec3 diagonal = glm::normalize(smooth.positions[v] - glm::vec3(0.5f));
        EXPECT_NEAR(glm::length(smooth.normals[v]), 1.0f, 1e-6f);
        EXPECT_GE(glm::dot(smooth.normals[v], diagonal), 0.94f) << "corner " << v;
    }
    EXPECT_EQ(smooth.normalsSource, "smooth");
    // A crease angle below the cube's 90-degree edges keeps them sharp; above, smooths them.
    const LoadedMesh sharp = loadMesh(cube, {.normals = {NormalMode::Kind::CreaseAngle, 60.0}});
    EXPECT_EQ(sharp.positions.size(), 24u);
    EXPECT_EQ(sharp.normalsSource, "crease angle 60");
    const LoadedMesh soft = loadMesh(cube, {.normals = {NormalMode::Kind::CreaseAngle, 100.0}});
    EXPECT_EQ(soft.positions.size(), 8u);
    // Flat overrides the file's own normals.
    const LoadedMesh given = loadMesh(dir.write("given.obj", std::string(kQuadObj) +
                                                                 "vn 0 1 1\nf 1//1 2//1 3//1\n"),
                                      {.normals = {NormalMode::Kind::Flat}});
    for (const glm::vec3& n : given.normals)
        expectVec3Near(n, {0, 0, 1});
}

TEST(MeshLoaderObj, FileNormalsAreUsedAndSplitVerticesWhereTheyDiffer)
{
    // Vertex 1 appears with two different normals: it becomes two vertices. Normals are
    // normalised; texture coordinates are accepted and ignored.
    TempDir dir("normals");
    const std::string path =
        dir.write("normals.obj", std::string(kQuadObj) + "vt 0 0\n"
                                                         "vn 0 0 2\n"
                                                         "vn 0 1 1\n"
                                                         "f 1/1/1 2/1/1 3/1/1\n"
                                                         "f 1//2 3//2 4//2\n");
    const LoadedMesh mesh = loadMesh(path);
    ASSERT_EQ(mesh.positions.size(), 6u);
    ASSERT_EQ(mesh.triangleCount(), 2u);
    for (int c = 0; c < 3; ++c) {
        expectVec3Near(mesh.normals[mesh.indices[c]], {0, 0, 1});
        expectVec3Near(mesh.normals[mesh.indices[3 + c]], glm::normalize(glm::vec3(0, 1, 1)));
    }
    expectVec3Near(mesh.positions[mesh.indices[0]], {0, 0, 0});
    expectVec3Near(mesh.positions[mesh.indices[3]], {0, 0, 0});
    EXPECT_NE(mesh.indices[0], mesh.indices[3]);
}

} // namespace
