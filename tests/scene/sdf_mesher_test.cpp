// The incremental SDF mesher: a dig re-meshes only the cells it touched, and the mesh it patches
// is the mesh of meshing the whole grid again, bit for bit: the same triangles (positions,
// winding, material) and vertex normals (checked as sets, which says what differs when it
// fails), in the same order.

#include "scene/procedural.h"
#include "scene/sdf_mesher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <random>
#include <string>
#include <tuple>

using namespace rtlab::scene;

namespace {

using Bits = std::array<std::uint32_t, 3>;

Bits toBits(const glm::vec3& p)
{
    return {std::bit_cast<std::uint32_t>(p.x), std::bit_cast<std::uint32_t>(p.y),
            std::bit_cast<std::uint32_t>(p.z)};
}

// A triangle by its corners' bits, rotated so that the smallest corner comes first (the winding
// is kept), and its material.
using Triangle = std::tuple<Bits, Bits, Bits, std::uint32_t>;

std::vector<Triangle> getTriangles(const SdfMesh& m)
{
    std::vector<Triangle> out;
    for (std::size_t t = 0; t < m.triangleMaterial.size(); ++t) {
        std::array<Bits, 3> c;
        for (int k = 0; k < 3; ++k)
            c[std::size_t(k)] = toBits(m.mesh.positions[m.mesh.indices[3 * t + std::size_t(k)]]);
        const auto first = std::min_element(c.begin(), c.end()) - c.begin();
        std::rotate(c.begin(), c.begin() + first, c.end());
        out.emplace_back(c[0], c[1], c[2], m.triangleMaterial[t]);
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<std::pair<Bits, Bits>> getVertices(const SdfMesh& m)
{
    std::vector<std::pair<Bits, Bits>> out;
    for (std::size_t v = 0; v < m.mesh.positions.size(); ++v)
        out.emplace_back(toBits(m.mesh.positions[v]), toBits(m.mesh.normals[v]));
    std::sort(out.begin(), out.end());
    return out;
}

// The patched mesh against a full meshing: same triangles, same vertices with the same normals
// (so no vertex is left unused), indices in range.
void expectSameMesh(const SdfMesh& patched, const SdfMesh& full, const std::string& where)
{
    ASSERT_EQ(patched.mesh.normals.size(), patched.mesh.positions.size()) << where;
    ASSERT_EQ(patched.mesh.indices.size(), 3 * patched.triangleMaterial.size()) << where;
    for (const std::uint32_t i : patched.mesh.indices)
        ASSERT_LT(i, patched.mesh.positions.size()) << where;
    EXPECT_EQ(patched.triangleMaterial.size(), full.triangleMaterial.size()) << where;
    EXPECT_EQ(patched.mesh.positions.size(), full.mesh.positions.size()) << where;
    EXPECT_TRUE(getTriangles(patched) == getTriangles(full)) << where << ": the triangles differ";
    EXPECT_TRUE(getVertices(patched) == getVertices(full)) << where << ": the vertices differ";
    // And in the same order, byte for byte: the frame drawn from it is the full re-mesh's.
    EXPECT_TRUE(patched.mesh.indices == full.mesh.indices) << where << ": the indices differ";
    EXPECT_EQ(std::memcmp(patched.mesh.positions.data(), full.mesh.positions.data(),
                          std::min(patched.mesh.positions.size(), full.mesh.positions.size()) *
                              sizeof(glm::vec3)),
              0)
        << where << ": the positions' order differs";
    EXPECT_TRUE(patched.triangleMaterial == full.triangleMaterial) << where << ": the materials differ";
}

CsgEdit makeEdit(CsgShape shape, CsgOp op, glm::dvec3 center, glm::dvec3 size, double blend,
                 int frame, std::uint32_t material = 0)
{
    return {.shape = shape, .op = op, .center = center, .size = size, .blend = blend,
            .material = material, .frame = frame};
}

SdfModel makeGround()
{
    SdfModel m;
    m.name = "ground";
    m.boundsMin = {-4, -2, -4};
    m.boundsMax = {4, 2, 4};
    m.edits.push_back(makeEdit(CsgShape::Box, CsgOp::Add, {0, -1, 0}, {3.5, 0.8, 3.5}, 0.0, 0));
    m.edits.push_back(makeEdit(CsgShape::Sphere, CsgOp::Add, {1, 0, 1}, {1.2, 0, 0}, 0.4, 0, 1));
    return m;
}

} // namespace

TEST(SdfMesher, ADigOnTomorrowTownReMeshesOnlyWhatItTouchedAndGivesTheFullMesh)
{
    const Scene town = makeTomorrowTown();
    ASSERT_FALSE(town.sdfModels.empty());
    const SdfModel& land = town.sdfModels.front();
    ASSERT_TRUE(land.changesOverTime());
    SdfMesher mesher(land, {.resolution = land.resolution});
    const SdfMeshChange first = mesher.update(0);
    EXPECT_TRUE(first.full);
    expectSameMesh(mesher.getMesh(), meshSdfModel(land, {.resolution = land.resolution, .frame = 0}),
                   "frame 0");
    // The town's digs start at frames 2, 4 and 6; frame 3 has no new edit.
    for (const int frame : {2, 3, 4, 6, 7}) {
        const SdfMeshChange change = mesher.update(frame);
        const std::string where = "frame " + std::to_string(frame) + ": " + change.what;
        EXPECT_FALSE(change.full) << where;
        if (frame == 3 || frame == 7) {
            EXPECT_FALSE(change.changed) << where;
            EXPECT_EQ(change.cellsMeshed, 0u) << where;
            continue;
        }
        EXPECT_TRUE(change.changed) << where;
        // A dig of radius 1.2-1.6 m on a 0.25 m grid touches a few percent of the cells.
        EXPECT_GT(change.cellsMeshed, 0u) << where;
        EXPECT_LT(change.cellsMeshed * 20, change.cellCount) << where;
        EXPECT_LE(change.changedMin.x, change.changedMax.x) << where;
        expectSameMesh(mesher.getMesh(),
                       meshSdfModel(land, {.resolution = land.resolution, .frame = frame}), where);
    }
}

TEST(SdfMesher, RandomEditsOneOrTwoPerUpdateGiveTheFullMeshEveryTime)
{
    SdfModel m = makeGround();
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> pos(-3.5, 3.5), height(-1.5, 1.0), size(0.2, 1.1),
        blend(0.0, 0.3), unit(0.0, 1.0);
    const CsgShape shapes[] = {CsgShape::Sphere, CsgShape::Box,   CsgShape::RoundedBox,
                               CsgShape::Cylinder, CsgShape::Cone, CsgShape::Torus,
                               CsgShape::Capsule};
    for (int k = 0; k < 24; ++k) {
        CsgEdit e = makeEdit(shapes[k % 7], unit(rng) < 0.7 ? CsgOp::Subtract : CsgOp::Add,
                             {pos(rng), height(rng), pos(rng)},
                             {size(rng), size(rng), size(rng)}, unit(rng) < 0.5 ? 0.0 : blend(rng),
                             1 + k / 2 * 2 + (k % 2), std::uint32_t(k % 3));
        e.size.y = std::min(e.size.y, e.size.x); // the torus's minor radius below its major
        e.rounding = 0.5 * std::min({e.size.x, e.size.y, e.size.z});
        e.rotation = glm::normalize(glm::dquat(unit(rng), unit(rng), unit(rng), unit(rng)));
        m.edits.push_back(e);
    }
    SdfMesher mesher(m, {.resolution = 40});
    mesher.update(0);
    int incremental = 0;
    // Every frame, then every second frame (two edits at once) on a second mesher.
    for (const int stride : {1, 2}) {
        SdfMesher walk(m, {.resolution = 40});
        walk.update(0);
        for (int frame = stride; frame <= 25; frame += stride) {
            const SdfMeshChange change = walk.update(frame);
            incremental += change.full ? 0 : 1;
            expectSameMesh(walk.getMesh(), meshSdfModel(m, {.resolution = 40, .frame = frame}),
                           "stride " + std::to_string(stride) + " frame " + std::to_string(frame) +
                               ": " + change.what);
        }
    }
    EXPECT_EQ(incremental, 25 + 12);
}

TEST(SdfMesher, MeshesInFullWhenAnEditCannotBeFollowedAndSaysWhy)
{
    SdfModel m = makeGround();
    m.edits.push_back(makeEdit(CsgShape::Sphere, CsgOp::Subtract, {0, 0, 0}, {1, 0, 0}, 0.1, 2));
    m.edits.push_back(makeEdit(CsgShape::Box, CsgOp::Intersect, {0, 0, 0}, {3, 3, 3}, 0.0, 4));
    m.edits.push_back(makeEdit(CsgShape::Ellipsoid, CsgOp::Subtract, {-2, 0, -2}, {1, 0.5, 0.7}, 0.0, 6));
    // Listed after the ellipsoid, applied before it.
    m.edits.push_back(makeEdit(CsgShape::Sphere, CsgOp::Subtract, {2, 0, -2}, {0.6, 0, 0}, 0.0, 5));
    SdfMesher mesher(m, {.resolution = 32});
    EXPECT_NE(mesher.update(0).what.find("first meshing"), std::string::npos);
    EXPECT_FALSE(mesher.update(2).full);
    const SdfMeshChange intersect = mesher.update(4);
    EXPECT_TRUE(intersect.full);
    EXPECT_NE(intersect.what.find("no bounded reach"), std::string::npos) << intersect.what;
    // Frame 5's sphere is incremental; frame 6's ellipsoid is listed before it.
    EXPECT_FALSE(mesher.update(5).full);
    const SdfMeshChange ellipsoid = mesher.update(6);
    EXPECT_TRUE(ellipsoid.full);
    EXPECT_NE(ellipsoid.what.find("comes before an applied edit"), std::string::npos) << ellipsoid.what;
    const SdfMeshChange back = mesher.update(1);
    EXPECT_TRUE(back.full);
    EXPECT_NE(back.what.find("is not applied at frame 1"), std::string::npos) << back.what;
    expectSameMesh(mesher.getMesh(), meshSdfModel(m, {.resolution = 32, .frame = 1}), "back to frame 1");
    EXPECT_TRUE(mesher.update(1, true).full);
}

TEST(SdfMesher, AnEditOutsideTheModelOrBuriedDeepChangesNothing)
{
    SdfModel m = makeGround();
    // Far outside the model's box, and a hole wholly inside the solid (no surface near it).
    m.edits.push_back(makeEdit(CsgShape::Sphere, CsgOp::Subtract, {40, 0, 40}, {1, 0, 0}, 0.2, 1));
    m.edits.push_back(makeEdit(CsgShape::Sphere, CsgOp::Add, {-2, -1, -2}, {0.3, 0, 0}, 0.0, 2));
    SdfMesher mesher(m, {.resolution = 32});
    mesher.update(0);
    const SdfMesh before = mesher.getMesh();
    for (const int frame : {1, 2}) {
        const SdfMeshChange change = mesher.update(frame);
        EXPECT_FALSE(change.full) << change.what;
        EXPECT_FALSE(change.changed) << "frame " << frame << ": " << change.what;
        EXPECT_GT(change.changedMin.x, change.changedMax.x) << change.what; // no triangle moved
        EXPECT_TRUE(mesher.getMesh().mesh.positions == before.mesh.positions);
        EXPECT_TRUE(mesher.getMesh().mesh.indices == before.mesh.indices);
    }
}
