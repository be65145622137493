#pragma once
// Mesh and field exports for inspection in ParaView, Blender, MeshLab: OBJ, binary PLY, VTK XML.

#include "core/mesh.h"
#include "core/sampled_field.h"

#include <string>

namespace rtlab::meshio {

//! Writes `mesh` in the format its extension names (case-insensitive):
//!   .obj  Wavefront OBJ (rtlab::writeObj): positions, normals when present, 1-based faces;
//!   .ply  binary little-endian PLY: float x y z [nx ny nz], faces as uchar-counted int lists;
//!   .vtp  VTK XML PolyData (vtkXMLPolyDataWriter): float points, triangles, "Normals" when present.
//! Normals are written when there is one per position. Throws rtlab::InputError naming the path
//! and the valid extensions for any other extension, rtlab::Error when the file cannot be written.
void writeMesh(const TriangleMesh& mesh, const std::string& path);

//! Writes the samples of `field` as VTK XML ImageData (vtkXMLImageDataWriter): dimensions = sample
//! counts, origin and spacing of the field, point scalars "sdf" (float). `path` must end in .vti
//! (else rtlab::InputError); std::invalid_argument when the value count does not match the sample
//! counts; rtlab::Error when the file cannot be written.
void writeFieldVti(const SampledField& field, const std::string& path);

} // namespace rtlab::meshio
