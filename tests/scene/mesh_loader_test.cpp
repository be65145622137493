// Mesh loading from OBJ and glTF files written to a temporary directory by each test: geometry,
// materials, and the policy for bad input (errors naming file, line and element; degenerate
// triangles dropped and counted; non-manifold meshes flagged). Normals: mesh_normals_test.cpp.

#include "scene/mesh_loader.h"

#include "mesh_loader_test_support.h"

#include "core/error.h"

#include <glm/geometric.hpp>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

using namespace rtlab::scene;
using namespace rtlab::scene::test;
using ::testing::HasSubstr;

namespace {

std::string encodeBase64(const std::string& bytes)
{
    static const char kAlphabet[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    std::size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const auto n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16 |
                       static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8 |
                       static_cast<unsigned char>(bytes[i + 2]);
        for (int s = 18; s >= 0; s -= 6)
            out += kAlphabet[(n >> s) & 63];
    }
    if (i < bytes.size()) {
        std::uint32_t n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16;
        if (i + 1 < bytes.size())
            n |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
        out += kAlphabet[(n >> 18) & 63];
        out += kAlphabet[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? kAlphabet[(n >> 6) & 63] : '=';
        out += '=';
    }
    return out;
}

template <typename T> void appendBytes(std::string& out, const std::vector<T>& values)
{
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

//! A one-mesh glTF: POSITION (and optionally indices, uint16) in one buffer, one node.
struct GltfFile {
    std::vector<float> positions;       //!< xyz per vertex
    std::vector<std::uint16_t> indices; //!< empty: a non-indexed primitive
    std::string material;               //!< JSON object, or empty for none
    std::string node = R"({"mesh": 0})";
    int mode = 4;

    std::string getBinary() const
    {
        std::string bin;
        appendBytes(bin, positions);
        appendBytes(bin, indices);
        while (bin.size() % 4 != 0)
            bin += '\0';
        return bin;
    }

    //! The JSON; `bufferUri` empty for a GLB (whose buffer is its BIN chunk).
    std::string getJson(const std::string& bufferUri) const
    {
        const std::size_t positionBytes = positions.size() * sizeof(float);
        const std::size_t indexBytes = indices.size() * sizeof(std::uint16_t);
        const std::string uri = bufferUri.empty() ? "" : R"("uri": ")" + bufferUri + R"(", )";
        std::string json = R"({"asset": {"version": "2.0"}, "scene": 0,
            "scenes": [{"nodes": [0]}], "nodes": [)" +
                           node + R"(],
            "meshes": [{"name": "Body", "primitives": [{"attributes": {"POSITION": 0})";
        if (!indices.empty())
            json += R"(, "indices": 1)";
        if (!material.empty())
            json += R"(, "material": 0)";
        json += R"(, "mode": )" + std::to_string(mode) + "}]}],";
        if (!material.empty())
            json += R"("materials": [)" + material + "],";
        json += R"("buffers": [{)" + uri + R"("byteLength": )" +
                std::to_string(getBinary().size()) + R"(}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": )" +
                std::to_string(positionBytes) + "}";
        if (!indices.empty())
            json += R"(, {"buffer": 0, "byteOffset": )" + std::to_string(positionBytes) +
                    R"(, "byteLength": )" + std::to_string(indexBytes) + "}";
        json += R"(], "accessors": [{"bufferView": 0, "componentType": 5126, "count": )" +
                std::to_string(positions.size() / 3) + R"(, "type": "VEC3"})";
        if (!indices.empty())
            json += R"(, {"bufferView": 1, "componentType": 5123, "count": )" +
                    std::to_string(indices.size()) + R"(, "type": "SCALAR"})";
        json += "]}";
        return json;
    }

    std::string getGltf() const
    {
        return getJson("data:application/octet-stream;base64," + encodeBase64(getBinary()));
    }

    std::string getGlb() const
    {
        std::string json = getJson("");
        while (json.size() % 4 != 0)
            json += ' ';
        const std::string bin = getBinary();
        auto appendWord = [](std::string& out, std::uint32_t word) {
            out.append(reinterpret_cast<const char*>(&word), 4);
        };
        std::string glb;
        appendWord(glb, 0x46546C67u); // "glTF"
        appendWord(glb, 2);
        appendWord(glb, static_cast<std::uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
        appendWord(glb, static_cast<std::uint32_t>(json.size()));
        appendWord(glb, 0x4E4F534Au); // "JSON"
        glb += json;
        appendWord(glb, static_cast<std::uint32_t>(bin.size()));
        appendWord(glb, 0x004E4942u); // "BIN\0"
        glb += bin;
        return glb;
    }
};

GltfFile makeTriangle()
{
    GltfFile file;
    file.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    file.indices = {0, 1, 2};
    return file;
}

} // namespace

// ---------------------------------------------------------------------------------------------
// OBJ

TEST(MeshLoaderObj, QuadWithMaterialsFromMtl)
{
    TempDir dir("quad");
    dir.write("quad.mtl", "# two materials\n"
                          "newmtl red\n"
                          "Kd 0.7 0.1 0.2\n"
                          "newmtl lamp\n"
                          "Ke 5 4 3\n");
    const std::string path = dir.write("quad.obj", std::string("mtllib quad.mtl\n") + kQuadObj +
                                                       "usemtl red\n"
                                                       "f 1 2 3\n"
                                                       "usemtl lamp\n"
                                                       "f 1 3 4\n");
    const LoadedMesh mesh = loadMesh(path);

    ASSERT_EQ(mesh.positions.size(), 4u);
    ASSERT_EQ(mesh.triangleCount(), 2u);
    EXPECT_EQ(mesh.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
    expectVec3Near(mesh.positions[2], {1, 1, 0});
    EXPECT_EQ(mesh.triangleMaterial, (std::vector<std::string>{"red", "lamp"}));
    EXPECT_EQ(mesh.materialNames, (std::vector<std::string>{"red", "lamp"}));
    ASSERT_EQ(mesh.materialAlbedo.size(), 2u);
    ASSERT_EQ(mesh.materialEmission.size(), 2u);
    expectVec3Near(mesh.materialAlbedo[0], {0.7f, 0.1f, 0.2f});
    expectVec3Near(mesh.materialEmission[0], {0, 0, 0});
    expectVec3Near(mesh.materialAlbedo[1], glm::vec3(0.8f)); // no Kd
    expectVec3Near(mesh.materialEmission[1], {5, 4, 3});
    // No vn in the file: computed from the counter-clockwise triangles, facing +z.
    ASSERT_EQ(mesh.normals.size(), 4u);
    for (const glm::vec3& n : mesh.normals)
        expectVec3Near(n, {0, 0, 1});
    EXPECT_EQ(mesh.degenerateTrianglesDropped, 0u);
    EXPECT_FALSE(mesh.nonManifold);
}

TEST(MeshLoaderObj, PentagonIsFanTriangulated)
{
    TempDir dir("pentagon");
    const std::string path = dir.write("pentagon.obj", "v 1 0 0\n"
                                                       "v 0.3 0.95 0\n"
                                                       "v -0.8 0.6 0\n"
                                                       "v -0.8 -0.6 0\n"
                                                       "v 0.3 -0.95 0\n"
                                                       "f 1 2 3 4 5\n");
    const LoadedMesh mesh = loadMesh(path);
    EXPECT_EQ(mesh.triangleCount(), 3u);
    EXPECT_EQ(mesh.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
    // Without usemtl every triangle has the unnamed material with the default albedo.
    EXPECT_EQ(mesh.triangleMaterial, std::vector<std::string>(3, ""));
    EXPECT_EQ(mesh.materialNames, std::vector<std::string>{""});
    expectVec3Near(mesh.materialAlbedo.at(0), glm::vec3(0.8f));
    expectVec3Near(mesh.materialEmission.at(0), glm::vec3(0.0f));
}

TEST(MeshLoaderObj, NegativeAndForwardIndicesAreResolved)
{
    // -1 is the latest vertex; a face may use vertices defined after it.
    TempDir dir("relative");
    const std::string path = dir.write("relative.obj", "v 0 0 0\n"
                                                       "v 1 0 0\n"
                                                       "v 1 1 0\n"
                                                       "f -3 -2 -1\n"
                                                       "f 1 3 4\n"
                                                       "v 0 1 0\n");
    const LoadedMesh mesh = loadMesh(path);
    EXPECT_EQ(mesh.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(MeshLoaderObj, NanVertexNamesFileLineAndVertex)
{
    TempDir dir("nan");
    const std::string path = dir.write("file.obj", "# a comment\n"
                                                   "v 0 0 0\n"
                                                   "\n"
                                                   "v 1 nan 0\n"
                                                   "v 0 1 0\n"
                                                   "f 1 2 3\n");
    const rtlab::InputError e = expectInputError(path);
    EXPECT_THAT(e.what(), HasSubstr("file.obj:4:"));
    EXPECT_THAT(e.what(), HasSubstr("vertex 2"));
    EXPECT_THAT(e.what(), HasSubstr("non-finite"));
    EXPECT_EQ(e.location().line, 4);
    EXPECT_EQ(e.location().column, 5); // the "nan" token
}

TEST(MeshLoaderObj, InfiniteVertexIsAnError)
{
    TempDir dir("inf");
    const std::string infinite = dir.write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n");
    const rtlab::InputError e = expectInputError(infinite);
    EXPECT_THAT(e.what(), HasSubstr("inf.obj:3:"));
    EXPECT_THAT(e.what(), HasSubstr("vertex 3"));

    // Finite in the text but beyond single precision: also refused.
    const std::string huge = dir.write("huge.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n");
    const rtlab::InputError h = expectInputError(huge);
    EXPECT_THAT(h.what(), HasSubstr("huge.obj:2:"));
    EXPECT_THAT(h.what(), HasSubstr("vertex 2"));
    EXPECT_THAT(h.what(), HasSubstr("single precision"));
}

TEST(MeshLoaderObj, MalformedNumberIsAnError)
{
    TempDir dir("malformed");
    const std::string path = dir.write("bad.obj", "v 0 0 0\nv 1 0x 0\nv 0 1 0\nf 1 2 3\n");
    const rtlab::InputError e = expectInputError(path);
    EXPECT_THAT(e.what(), HasSubstr("bad.obj:2:5:"));
    EXPECT_THAT(e.what(), HasSubstr("'0x'"));
}

TEST(MeshLoaderObj, OutOfRangeIndexIsAnError)
{
    TempDir dir("range");
    // Too large: the face's line, the group and the number of vertices.
    const std::string large = dir.write("large.obj", std::string(kQuadObj) + "g wall\n"
                                                                             "f 1 2 3\n"
                                                                             "f 1 3 9\n");
    const rtlab::InputError e = expectInputError(large);
    EXPECT_THAT(e.what(), HasSubstr("large.obj:7:"));
    EXPECT_THAT(e.what(), HasSubstr("vertex index 9 in face 2 of group 'wall' is out of range"));
    EXPECT_THAT(e.what(), HasSubstr("4 vertices"));

    // Negative beyond the vertices defined so far.
    const std::string negative = dir.write("negative.obj", std::string(kQuadObj) + "f 1 2 -5\n");
    EXPECT_THAT(expectInputError(negative).what(), HasSubstr("negative.obj:5:"));

    // Zero is never valid in OBJ.
    const std::string zero = dir.write("zero.obj", std::string(kQuadObj) + "f 0 1 2\n");
    EXPECT_THAT(expectInputError(zero).what(), HasSubstr("index 0"));

    // A normal index out of range is an error too.
    const std::string normal =
        dir.write("normal.obj", std::string(kQuadObj) + "f 1//1 2//1 3//1\n");
    EXPECT_THAT(expectInputError(normal).what(), HasSubstr("normal index 1"));

    // A face of two corners is malformed, not degenerate.
    const std::string twoCorners = dir.write("two.obj", std::string(kQuadObj) + "f 1 2\n");
    EXPECT_THAT(expectInputError(twoCorners).what(), HasSubstr("at least 3"));
}

TEST(MeshLoaderObj, DegenerateTrianglesAreDroppedAndCounted)
{
    TempDir dir("degenerate");
    const std::string path =
        dir.write("degenerate.obj", std::string(kQuadObj) + "v 2 2 0\n"
                                                            "v 0 0 0\n" // same point as v 1
                                                            "f 1 2 3\n"
                                                            "f 1 1 2\n" // repeated index
                                                            "f 1 3 5\n" // collinear
                                                            "f 1 6 2\n" // coincident points
                                                            "f 1 3 4\n");
    const LoadedMesh mesh = loadMesh(path);
    EXPECT_EQ(mesh.degenerateTrianglesDropped, 3u);
    EXPECT_EQ(mesh.triangleCount(), 2u);
    EXPECT_EQ(mesh.positions.size(), 4u); // vertices 5 and 6 are used by no kept triangle
    EXPECT_EQ(mesh.triangleMaterial.size(), 2u);
}

TEST(MeshLoaderObj, EmptyMeshIsAnError)
{
    TempDir dir("empty");
    const rtlab::InputError e = expectInputError(dir.write("empty.obj", ""));
    EXPECT_THAT(e.what(), HasSubstr("empty.obj"));
    EXPECT_THAT(e.what(), HasSubstr("contains no triangles"));

    // Vertices but no faces.
    EXPECT_THAT(expectInputError(dir.write("points.obj", kQuadObj)).what(),
                HasSubstr("contains no triangles"));

    // Only degenerate triangles.
    const rtlab::InputError d =
        expectInputError(dir.write("flat.obj", std::string(kQuadObj) + "f 1 1 2\nf 1 2 2\n"));
    EXPECT_THAT(d.what(), HasSubstr("contains no triangles"));
    EXPECT_THAT(d.what(), HasSubstr("all 2 triangles are degenerate"));
}

TEST(MeshLoaderObj, NonManifoldEdgeIsAcceptedAndFlagged)
{
    // Three triangles share the edge from (0,0,0) to (1,0,0).
    TempDir dir("fin");
    const std::string path = dir.write("fin.obj", "v 0 0 0\n"
                                                  "v 1 0 0\n"
                                                  "v 0 1 0\n"
                                                  "v 0 -1 0\n"
                                                  "v 0 0 1\n"
                                                  "f 1 2 3\n"
                                                  "f 2 1 4\n"
                                                  "f 1 2 5\n");
    const LoadedMesh mesh = loadMesh(path);
    EXPECT_EQ(mesh.triangleCount(), 3u);
    EXPECT_TRUE(mesh.nonManifold);

    // The same edge made of distinct but coincident vertices still counts.
    const std::string split = dir.write("split.obj", "v 0 0 0\n"
                                                     "v 1 0 0\n"
                                                     "v 0 1 0\n"
                                                     "v 0 -1 0\n"
                                                     "v 0 0 1\n"
                                                     "v 0 0 0\n"
                                                     "v 1 0 0\n"
                                                     "f 1 2 3\n"
                                                     "f 2 1 4\n"
                                                     "f 6 7 5\n");
    EXPECT_TRUE(loadMesh(split).nonManifold);
}

TEST(MeshLoaderObj, MaterialProblemsAreErrors)
{
    TempDir dir("materials");
    // mtllib naming a file that does not exist: the OBJ line and the missing file.
    const rtlab::InputError missing = expectInputError(
        dir.write("missing.obj", std::string("mtllib nowhere.mtl\n") + kQuadObj + "f 1 2 3\n"));
    EXPECT_THAT(missing.what(), HasSubstr("missing.obj:1:"));
    EXPECT_THAT(missing.what(), HasSubstr("nowhere.mtl"));

    // usemtl of a material no library defines.
    dir.write("lib.mtl", "newmtl red\nKd 1 0 0\n");
    const rtlab::InputError undefined = expectInputError(dir.write(
        "undefined.obj", std::string("mtllib lib.mtl\n") + kQuadObj + "usemtl blue\nf 1 2 3\n"));
    EXPECT_THAT(undefined.what(), HasSubstr("undefined.obj:6:"));
    EXPECT_THAT(undefined.what(), HasSubstr("'blue' is not defined"));

    // A NaN colour in the MTL names the MTL's line.
    dir.write("nan.mtl", "newmtl red\n\nKd 1 nan 0\n");
    const rtlab::InputError nanColour = expectInputError(dir.write(
        "nancolour.obj", std::string("mtllib nan.mtl\n") + kQuadObj + "usemtl red\nf 1 2 3\n"));
    EXPECT_THAT(nanColour.what(), HasSubstr("nan.mtl:3:"));
}

TEST(MeshLoaderObj, MaterialProblemsAreWarningsWhenTheCallerAssignsTheMaterial)
{
    // A scene file that gives the mesh its own material does not need the file's: a missing MTL
    // and an undefined usemtl name are warnings naming the file, the line and the default.
    TempDir dir("optional_materials");
    const MeshLoadOptions optional{.materialsOptional = true};
    const LoadedMesh missing = loadMesh(
        dir.write("missing.obj", std::string("mtllib nowhere.mtl\n") + kQuadObj +
                                     "usemtl red\nf 1 2 3\n"),
        optional);
    EXPECT_EQ(missing.triangleCount(), 1u);
    ASSERT_EQ(missing.warnings.size(), 2u);
    EXPECT_THAT(missing.warnings[0], HasSubstr("missing.obj:1:"));
    EXPECT_THAT(missing.warnings[0], HasSubstr("nowhere.mtl"));
    EXPECT_THAT(missing.warnings[0], HasSubstr("albedo 0.8"));
    EXPECT_THAT(missing.warnings[1], HasSubstr("missing.obj:6:"));
    EXPECT_THAT(missing.warnings[1], HasSubstr("'red' is not defined"));
    ASSERT_EQ(missing.materialAlbedo.size(), 1u);
    EXPECT_EQ(missing.materialAlbedo[0], glm::vec3(0.8f));
    EXPECT_EQ(missing.materialEmission[0], glm::vec3(0.0f));

    // A library that exists is still read, and a malformed one is still an error.
    dir.write("lib.mtl", "newmtl red\nKd 1 0 0\n");
    const LoadedMesh found = loadMesh(
        dir.write("found.obj", std::string("mtllib lib.mtl\n") + kQuadObj + "usemtl red\nf 1 2 3\n"),
        optional);
    EXPECT_TRUE(found.warnings.empty());
    EXPECT_EQ(found.materialAlbedo[0], glm::vec3(1, 0, 0));
    dir.write("nan.mtl", "newmtl red\n\nKd 1 nan 0\n");
    EXPECT_THROW(loadMesh(dir.write("nancolour.obj", std::string("mtllib nan.mtl\n") + kQuadObj +
                                                         "usemtl red\nf 1 2 3\n"),
                          optional),
                 rtlab::InputError);
}

// ---------------------------------------------------------------------------------------------
// Files in general

TEST(MeshLoader, MissingFileAndUnknownExtensionAreErrors)
{
    TempDir dir("files");
    const std::string missing = dir.path("absent.obj");
    const rtlab::InputError e = expectInputError(missing);
    EXPECT_THAT(e.what(), HasSubstr(missing));
    EXPECT_THAT(e.what(), HasSubstr("not found"));

    const rtlab::InputError stl = expectInputError(dir.write("mesh.stl", "solid x\n"));
    EXPECT_THAT(stl.what(), HasSubstr("mesh.stl"));
    EXPECT_THAT(stl.what(), HasSubstr(".obj, .gltf and .glb"));

    // The extension is matched case-insensitively.
    EXPECT_EQ(loadMesh(dir.write("upper.OBJ", std::string(kQuadObj) + "f 1 2 3\n")).triangleCount(),
              1u);
}

// ---------------------------------------------------------------------------------------------
// glTF

TEST(MeshLoaderGltf, TriangleWithMaterial)
{
    TempDir dir("gltf");
    GltfFile file = makeTriangle();
    file.material = R"({"name": "Glow",
        "pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.4, 0.6, 1.0]},
        "emissiveFactor": [1.0, 0.5, 0.0],
        "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}})";
    const LoadedMesh mesh = loadMesh(dir.write("triangle.gltf", file.getGltf()));

    ASSERT_EQ(mesh.positions.size(), 3u);
    EXPECT_EQ(mesh.indices, (std::vector<std::uint32_t>{0, 1, 2}));
    expectVec3Near(mesh.positions[1], {1, 0, 0});
    for (const glm::vec3& n : mesh.normals)
        expectVec3Near(n, {0, 0, 1});
    // No NORMAL: flat, as the glTF 2.0 specification prescribes.
    EXPECT_EQ(mesh.normalsSource, "flat (no NORMAL)");
    EXPECT_EQ(mesh.triangleMaterial, std::vector<std::string>{"Glow"});
    EXPECT_EQ(mesh.materialNames, std::vector<std::string>{"Glow"});
    expectVec3Near(mesh.materialAlbedo.at(0), {0.2f, 0.4f, 0.6f});
    expectVec3Near(mesh.materialEmission.at(0), {4.0f, 2.0f, 0.0f});
    EXPECT_EQ(mesh.degenerateTrianglesDropped, 0u);
    EXPECT_FALSE(mesh.nonManifold);
}

TEST(MeshLoaderGltf, GlbAndNonIndexedPrimitivesLoad)
{
    TempDir dir("glb");
    GltfFile file = makeTriangle();
    file.indices.clear(); // non-indexed: vertices taken three at a time
    const LoadedMesh mesh = loadMesh(dir.write("triangle.glb", file.getGlb()));
    EXPECT_EQ(mesh.triangleCount(), 1u);
    expectVec3Near(mesh.positions.at(2), {0, 1, 0});
    // No material: the unnamed default.
    EXPECT_EQ(mesh.materialNames, std::vector<std::string>{""});
    expectVec3Near(mesh.materialAlbedo.at(0), glm::vec3(0.8f));
}

TEST(MeshLoaderGltf, NodeTransformsAreApplied)
{
    TempDir dir("transform");
    GltfFile file = makeTriangle();
    // Rotate 90 degrees about +z, then translate by (10, 0, 0): (1,0,0) -> (10,1,0).
    file.node = R"({"mesh": 0, "translation": [10, 0, 0],
                    "rotation": [0, 0, 0.7071067811865476, 0.7071067811865476]})";
    const LoadedMesh rotated = loadMesh(dir.write("rotated.gltf", file.getGltf()));
    expectVec3Near(rotated.positions.at(0), {10, 0, 0}, 1e-5f);
    expectVec3Near(rotated.positions.at(1), {10, 1, 0}, 1e-5f);
    expectVec3Near(rotated.positions.at(2), {9, 0, 0}, 1e-5f);
    expectVec3Near(rotated.normals.at(0), {0, 0, 1}, 1e-5f);

    // A mirroring matrix (x -> -x) reverses the winding; the triangle is flipped back so that
    // its front (and computed normal) stays +z, as glTF prescribes.
    file.node = R"({"mesh": 0, "matrix": [-1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]})";
    const LoadedMesh mirrored = loadMesh(dir.write("mirrored.gltf", file.getGltf()));
    expectVec3Near(mirrored.positions.at(1), {-1, 0, 0});
    EXPECT_EQ(mirrored.indices, (std::vector<std::uint32_t>{0, 2, 1}));
    expectVec3Near(mirrored.normals.at(0), {0, 0, 1});
}

TEST(MeshLoaderGltf, OutOfRangeIndexNamesAccessorAndPrimitive)
{
    TempDir dir("gltf_range");
    GltfFile file = makeTriangle();
    file.indices = {0, 1, 5};
    const rtlab::InputError e = expectInputError(dir.write("range.gltf", file.getGltf()));
    EXPECT_THAT(e.what(), HasSubstr("range.gltf: error:"));
    EXPECT_THAT(e.what(), HasSubstr("index 2 of accessor 1 (indices of mesh 'Body' primitive 0)"));
    EXPECT_THAT(e.what(), HasSubstr("is 5, out of range: POSITION has 3 vertices"));
    EXPECT_EQ(e.location().line, 0);
}

TEST(MeshLoaderGltf, NanPositionIsAnError)
{
    TempDir dir("gltf_nan");
    GltfFile file = makeTriangle();
    file.positions[4] = std::numeric_limits<float>::quiet_NaN();
    const rtlab::InputError e = expectInputError(dir.write("nan.gltf", file.getGltf()));
    EXPECT_THAT(e.what(), HasSubstr("nan.gltf"));
    EXPECT_THAT(e.what(),
                HasSubstr("vertex 1 of accessor 0 (POSITION of mesh 'Body' primitive 0)"));
    EXPECT_THAT(e.what(), HasSubstr("non-finite"));
}

TEST(MeshLoaderGltf, AccessorBeyondItsBufferViewIsAnError)
{
    TempDir dir("gltf_bounds");
    GltfFile file = makeTriangle();
    std::string json = file.getGltf();
    const std::string count = R"("count": 3, "type": "VEC3")";
    ASSERT_NE(json.find(count), std::string::npos);
    json.replace(json.find(count), count.size(), R"("count": 4, "type": "VEC3")");
    const rtlab::InputError e = expectInputError(dir.write("bounds.gltf", json));
    EXPECT_THAT(e.what(), HasSubstr("accessor 0 (POSITION of mesh 'Body' primitive 0)"));
    EXPECT_THAT(e.what(), HasSubstr("does not fit"));
}

TEST(MeshLoaderGltf, NonTriangleModeIsAnError)
{
    TempDir dir("gltf_mode");
    GltfFile file = makeTriangle();
    file.mode = 1;
    const rtlab::InputError e = expectInputError(dir.write("lines.gltf", file.getGltf()));
    EXPECT_THAT(e.what(), HasSubstr("mesh 'Body' primitive 0 has mode LINES (1)"));
}

TEST(MeshLoaderGltf, MalformedFilesAreErrors)
{
    TempDir dir("gltf_malformed");
    const GltfFile file = makeTriangle();

    // A JSON syntax error.
    std::string json = file.getGltf();
    json.insert(json.find("\"meshes\""), "{{ ");
    const rtlab::InputError syntax = expectInputError(dir.write("syntax.gltf", json));
    EXPECT_THAT(syntax.what(), HasSubstr("syntax.gltf: error: cannot parse glTF"));

    // A GLB cut in half: the same bytes load when complete.
    const std::string glb = file.getGlb();
    EXPECT_EQ(loadMesh(dir.write("whole.glb", glb)).triangleCount(), 1u);
    const rtlab::InputError truncated =
        expectInputError(dir.write("truncated.glb", glb.substr(0, glb.size() / 2)));
    EXPECT_THAT(truncated.what(), HasSubstr("truncated.glb: error: cannot parse GLB"));

    // An unsupported required extension.
    json = file.getGltf();
    json.insert(1, R"("extensionsRequired": ["KHR_draco_mesh_compression"], )");
    EXPECT_THAT(expectInputError(dir.write("draco.gltf", json)).what(),
                HasSubstr("requires extension 'KHR_draco_mesh_compression'"));
}
