// Round trips of rtlab::meshio's files through VTK's own readers (vtkPLYReader,
// vtkXMLPolyDataReader, vtkXMLImageDataReader): counts, coordinates, normals, indices, field
// values, origin and spacing come back unchanged (all are written as floats or doubles, so
// exactly).

#include "meshio/meshio.h"

#include "core/error.h"

#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPLYReader.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

using namespace rtlab;

namespace {

std::string makeTempPath(const std::string& name)
{
    const std::filesystem::path dir =
        std::filesystem::path(::testing::TempDir()) / "rtlab_meshio_test";
    std::filesystem::create_directories(dir);
    return (dir / name).string();
}

//! An octahedron with unit normals and a vertex at a non-representable-in-decimal coordinate.
TriangleMesh makeOctahedron(bool normals)
{
    TriangleMesh mesh;
    mesh.positions = {{1.0f, 0.0f, 0.0f}, {-1.0f, 0.0f, 0.0f}, {0.0f, 1.1f, 0.0f},
                      {0.0f, -1.0f, 0.0f}, {0.0f, 0.0f, 1.0f / 3.0f}, {0.0f, 0.0f, -1e6f}};
    if (normals)
        for (const glm::vec3& p : mesh.positions)
            mesh.normals.push_back(glm::vec3(p.x != 0.0f ? p.x / std::abs(p.x) : 0.0f,
                                             p.y != 0.0f ? p.y / std::abs(p.y) : 0.0f,
                                             p.z != 0.0f ? p.z / std::abs(p.z) : 0.0f));
    mesh.indices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    return mesh;
}

void expectSameMesh(vtkPolyData* poly, const TriangleMesh& mesh, bool normals)
{
    ASSERT_NE(poly, nullptr);
    ASSERT_EQ(poly->GetNumberOfPoints(), vtkIdType(mesh.vertexCount()));
    ASSERT_EQ(poly->GetNumberOfPolys(), vtkIdType(mesh.triangleCount()));
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i) {
        double p[3];
        poly->GetPoint(vtkIdType(i), p);
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(p[k], double(mesh.positions[i][k])) << "point " << i;
    }
    vtkCellArray* polys = poly->GetPolys();
    vtkIdType count = 0;
    const vtkIdType* ids = nullptr;
    std::size_t t = 0;
    for (polys->InitTraversal(); polys->GetNextCell(count, ids); ++t) {
        ASSERT_EQ(count, 3);
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(ids[k], vtkIdType(mesh.indices[3 * t + k])) << "triangle " << t;
    }
    EXPECT_EQ(t, mesh.triangleCount());
    vtkDataArray* normalArray = poly->GetPointData()->GetNormals();
    if (!normals) {
        EXPECT_EQ(normalArray, nullptr);
        return;
    }
    ASSERT_NE(normalArray, nullptr);
    ASSERT_EQ(normalArray->GetNumberOfTuples(), vtkIdType(mesh.vertexCount()));
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i)
        for (int k = 0; k < 3; ++k)
            EXPECT_EQ(normalArray->GetComponent(vtkIdType(i), k), double(mesh.normals[i][k]));
}

class MeshioNormals : public ::testing::TestWithParam<bool> {};

TEST_P(MeshioNormals, PlyRoundTripThroughVtkPlyReader)
{
    const bool normals = GetParam();
    const TriangleMesh mesh = makeOctahedron(normals);
    const std::string path = makeTempPath(normals ? "octa_n.ply" : "octa.ply");
    meshio::writeMesh(mesh, path);
    std::ifstream file(path, std::ios::binary);
    std::string line;
    std::getline(file, line);
    EXPECT_EQ(line, "ply");
    std::getline(file, line);
    EXPECT_EQ(line, "format binary_little_endian 1.0");

    vtkNew<vtkPLYReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    expectSameMesh(reader->GetOutput(), mesh, normals);
}

TEST_P(MeshioNormals, VtpRoundTripThroughVtkXmlPolyDataReader)
{
    const bool normals = GetParam();
    const TriangleMesh mesh = makeOctahedron(normals);
    const std::string path = makeTempPath(normals ? "octa_n.vtp" : "octa.vtp");
    meshio::writeMesh(mesh, path);
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    expectSameMesh(reader->GetOutput(), mesh, normals);
}

INSTANTIATE_TEST_SUITE_P(WithAndWithout, MeshioNormals, ::testing::Bool());

TEST(Meshio, ObjGoesThroughWriteObj)
{
    const TriangleMesh mesh = makeOctahedron(true);
    const std::string path = makeTempPath("octa.OBJ");
    meshio::writeMesh(mesh, path);
    std::ifstream file(path);
    std::string line;
    std::size_t vertices = 0, normals = 0, faces = 0;
    while (std::getline(file, line)) {
        vertices += line.rfind("v ", 0) == 0;
        normals += line.rfind("vn ", 0) == 0;
        faces += line.rfind("f ", 0) == 0;
    }
    EXPECT_EQ(vertices, mesh.vertexCount());
    EXPECT_EQ(normals, mesh.vertexCount());
    EXPECT_EQ(faces, mesh.triangleCount());
}

TEST(Meshio, EmptyMeshWritesReadableFiles)
{
    const TriangleMesh empty;
    for (const char* name : {"empty.ply", "empty.vtp"}) {
        const std::string path = makeTempPath(name);
        meshio::writeMesh(empty, path);
        EXPECT_TRUE(std::filesystem::exists(path)) << name;
    }
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(makeTempPath("empty.vtp").c_str());
    reader->Update();
    EXPECT_EQ(reader->GetOutput()->GetNumberOfPoints(), 0);
}

TEST(Meshio, UnknownExtensionIsAnInputErrorNamingPathAndChoices)
{
    const TriangleMesh mesh = makeOctahedron(false);
    for (const std::string& path : {makeTempPath("octa.stl"), makeTempPath("no_extension"),
                                   makeTempPath("dir.ply/octa")}) {
        try {
            meshio::writeMesh(mesh, path);
            ADD_FAILURE() << path << " was accepted";
        } catch (const InputError& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(path), std::string::npos) << what;
            for (const char* ext : {".obj", ".ply", ".vtp"})
                EXPECT_NE(what.find(ext), std::string::npos) << what;
        }
    }
    SampledField field;
    EXPECT_THROW(meshio::writeFieldVti(field, makeTempPath("field.vtk")), InputError);
}

TEST(Meshio, UnwritablePathIsAnError)
{
    const TriangleMesh mesh = makeOctahedron(false);
    EXPECT_THROW(meshio::writeMesh(mesh, "/nonexistent_rtlab_dir/octa.ply"), Error);
}

TEST(Meshio, FieldVtiRoundTripThroughVtkXmlImageDataReader)
{
    SampledField field;
    field.samples = glm::ivec3(5, 4, 3);
    field.origin = glm::dvec3(1e6, -2.5, 1.0 / 3.0);
    field.spacing = 1e-3 / 3.0;
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 5; ++x)
                field.values.push_back(float(x) * 0.1f - float(y) / 7.0f + float(z * z) * 1e3f);
    const std::string path = makeTempPath("field.vti");
    meshio::writeFieldVti(field, path);

    vtkNew<vtkXMLImageDataReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    vtkImageData* image = reader->GetOutput();
    ASSERT_NE(image, nullptr);
    int dims[3];
    image->GetDimensions(dims);
    EXPECT_EQ(dims[0], 5);
    EXPECT_EQ(dims[1], 4);
    EXPECT_EQ(dims[2], 3);
    double origin[3];
    double spacing[3];
    image->GetOrigin(origin);
    image->GetSpacing(spacing);
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(origin[k], field.origin[k]) << "axis " << k;
        EXPECT_EQ(spacing[k], field.spacing) << "axis " << k;
    }
    vtkDataArray* values = image->GetPointData()->GetScalars();
    ASSERT_NE(values, nullptr);
    EXPECT_STREQ(values->GetName(), "sdf");
    ASSERT_EQ(values->GetNumberOfTuples(), vtkIdType(field.values.size()));
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 5; ++x) {
                const int ijk[3] = {x, y, z};
                EXPECT_EQ(values->GetComponent(image->ComputePointId(const_cast<int*>(ijk)), 0),
                          double(field.at(x, y, z)));
            }

    field.values.pop_back();
    EXPECT_THROW(meshio::writeFieldVti(field, path), std::invalid_argument);
}

} // namespace
