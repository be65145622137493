#include "meshio/meshio.h"

#include "core/error.h"

#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

namespace rtlab::meshio {
namespace {

//! The extension of `path` including the dot, lower-cased; empty when there is none.
std::string getLowerExtension(const std::string& path)
{
    const std::size_t slash = path.find_last_of('/');
    const std::size_t dot = path.find_last_of('.');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash))
        return {};
    std::string ext = path.substr(dot);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

bool hasNormals(const TriangleMesh& mesh)
{
    return !mesh.normals.empty() && mesh.normals.size() == mesh.positions.size();
}

//! Appends the little-endian bytes of `value` (float or 32-bit integer).
template <class T>
void appendLittleEndian(std::vector<unsigned char>& bytes, T value)
{
    static_assert(sizeof(T) == 4);
    std::uint32_t bits = 0;
    std::memcpy(&bits, &value, 4);
    for (int k = 0; k < 4; ++k)
        bytes.push_back(static_cast<unsigned char>(bits >> (8 * k)));
}

void writePly(const TriangleMesh& mesh, const std::string& path)
{
    const bool normals = hasNormals(mesh);
    std::string header = "ply\nformat binary_little_endian 1.0\ncomment rtlab TriangleMesh\n";
    header += "element vertex " + std::to_string(mesh.vertexCount()) + "\n";
    header += "property float x\nproperty float y\nproperty float z\n";
    if (normals)
        header += "property float nx\nproperty float ny\nproperty float nz\n";
    header += "element face " + std::to_string(mesh.triangleCount()) + "\n";
    header += "property list uchar int vertex_indices\nend_header\n";

    std::vector<unsigned char> body;
    body.reserve(mesh.vertexCount() * (normals ? 24 : 12) + mesh.triangleCount() * 13);
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i) {
        for (int k = 0; k < 3; ++k)
            appendLittleEndian(body, mesh.positions[i][k]);
        if (normals)
            for (int k = 0; k < 3; ++k)
                appendLittleEndian(body, mesh.normals[i][k]);
    }
    for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
        body.push_back(3);
        for (int k = 0; k < 3; ++k)
            appendLittleEndian(body, std::int32_t(mesh.indices[3 * t + k]));
    }

    std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "wb"), &std::fclose);
    if (!f)
        throw Error(path + ": cannot open for writing");
    // An empty mesh has an empty body, whose data() may be null: fwrite must not be given it.
    if (std::fwrite(header.data(), 1, header.size(), f.get()) != header.size() ||
        (!body.empty() && std::fwrite(body.data(), 1, body.size(), f.get()) != body.size()) ||
        std::fflush(f.get()) != 0)
        throw Error(path + ": write failed");
}

void writeVtp(const TriangleMesh& mesh, const std::string& path)
{
    vtkNew<vtkFloatArray> pointData;
    pointData->SetNumberOfComponents(3);
    pointData->SetNumberOfTuples(vtkIdType(mesh.vertexCount()));
    for (std::size_t i = 0; i < mesh.vertexCount(); ++i)
        pointData->SetTypedTuple(vtkIdType(i), &mesh.positions[i].x);
    vtkNew<vtkPoints> points;
    points->SetData(pointData);

    vtkNew<vtkIdTypeArray> offsets;
    vtkNew<vtkIdTypeArray> connectivity;
    offsets->SetNumberOfValues(vtkIdType(mesh.triangleCount() + 1));
    connectivity->SetNumberOfValues(vtkIdType(3 * mesh.triangleCount()));
    for (std::size_t t = 0; t <= mesh.triangleCount(); ++t)
        offsets->SetValue(vtkIdType(t), vtkIdType(3 * t));
    for (std::size_t i = 0; i < 3 * mesh.triangleCount(); ++i)
        connectivity->SetValue(vtkIdType(i), vtkIdType(mesh.indices[i]));
    vtkNew<vtkCellArray> polys;
    polys->SetData(offsets, connectivity);

    vtkNew<vtkPolyData> poly;
    poly->SetPoints(points);
    poly->SetPolys(polys);
    if (hasNormals(mesh)) {
        vtkNew<vtkFloatArray> normals;
        normals->SetName("Normals");
        normals->SetNumberOfComponents(3);
        normals->SetNumberOfTuples(vtkIdType(mesh.vertexCount()));
        for (std::size_t i = 0; i < mesh.vertexCount(); ++i)
            normals->SetTypedTuple(vtkIdType(i), &mesh.normals[i].x);
        poly->GetPointData()->SetNormals(normals);
    }

    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetFileName(path.c_str());
    writer->SetInputData(poly);
    if (writer->Write() != 1)
        throw Error(path + ": vtkXMLPolyDataWriter could not write the file");
}

} // namespace

void writeMesh(const TriangleMesh& mesh, const std::string& path)
{
    const std::string ext = getLowerExtension(path);
    if (ext == ".obj")
        writeObj(mesh, path);
    else if (ext == ".ply")
        writePly(mesh, path);
    else if (ext == ".vtp")
        writeVtp(mesh, path);
    else
        throw InputError(SourceLocation{path},
                         "unknown mesh file extension '" + ext + "'; expected .obj, .ply or .vtp");
}

void writeFieldVti(const SampledField& field, const std::string& path)
{
    if (getLowerExtension(path) != ".vti")
        throw InputError(SourceLocation{path}, "a sampled field is written as VTK XML image data; "
                                               "expected the extension .vti");
    const glm::ivec3 s = field.samples;
    if (s.x < 0 || s.y < 0 || s.z < 0 ||
        field.values.size() != std::size_t(s.x) * std::size_t(s.y) * std::size_t(s.z))
        throw std::invalid_argument("writeFieldVti: " + std::to_string(field.values.size()) +
                                    " values for " + std::to_string(s.x) + " x " +
                                    std::to_string(s.y) + " x " + std::to_string(s.z) +
                                    " samples");
    vtkNew<vtkFloatArray> values;
    values->SetName("sdf");
    values->SetNumberOfComponents(1);
    // save = 1: VTK reads the caller's buffer and never frees it.
    values->SetArray(const_cast<float*>(field.values.data()), vtkIdType(field.values.size()), 1);
    vtkNew<vtkImageData> image;
    image->SetDimensions(s.x, s.y, s.z);
    image->SetOrigin(field.origin.x, field.origin.y, field.origin.z);
    image->SetSpacing(field.spacing, field.spacing, field.spacing);
    image->GetPointData()->SetScalars(values);

    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetFileName(path.c_str());
    writer->SetInputData(image);
    if (writer->Write() != 1)
        throw Error(path + ": vtkXMLImageDataWriter could not write the file");
}

} // namespace rtlab::meshio
