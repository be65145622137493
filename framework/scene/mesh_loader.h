#pragma once
// Triangle meshes from Wavefront OBJ (+ MTL) and glTF 2.0 (.gltf, .glb) files, validated.
//
// Policy for bad input (every refusal is an rtlab::InputError naming the file, the line where the
// format has lines, and the element):
//   - a NaN or infinite vertex coordinate, or one beyond single precision: error;
//   - an index that refers to no vertex: error;
//   - a triangle with a repeated vertex index or zero area (computed in double): dropped and
//     counted in degenerateTrianglesDropped, not an error;
//   - no triangle left after dropping: error "contains no triangles";
//   - an edge shared by more than two triangles: accepted, nonManifold is set;
//   - a missing, unreadable or malformed file: error with the parser's message.
//
// OBJ: `v`, `vn`, `vt`, `f`, `o`, `g`, `s`, `usemtl` and `mtllib` are read; other statements
// (`l`, `p`, free-form geometry, ...) are ignored. Polygons are fan-triangulated from their first
// corner. Indices may be negative (relative). Every `mtllib` must exist and every `usemtl` name
// must be defined by one of them; an MTL gives Kd (albedo) and Ke (emission), RGB only. With
// MeshLoadOptions::materialsOptional (a scene file that assigns its own material to the mesh) a
// missing or unreadable MTL and an undefined `usemtl` name are warnings (LoadedMesh::warnings,
// naming the file, the line and the default used) instead of errors.
//
// glTF: every triangle primitive of every mesh instance in the default scene (scene 0 when the
// file names none; the parentless nodes when it has no scenes) with the node transforms applied,
// so positions are in the file's world space. Indexed and non-indexed primitives are read;
// other primitive modes, sparse accessors, quantized (non-float) positions or normals and
// required extensions other than KHR_materials_emissive_strength are refused. Skins and morph
// targets are ignored (rest pose); textures are ignored.
//
// Normals, as the files mean them (NormalMode::FromFile): a corner's normal is the file's (OBJ
// `vn`, glTF NORMAL) where given and non-zero; otherwise, in an OBJ with smoothing groups, the
// area-weighted mean of the normals of the triangles around the vertex in the same group (`s 1`,
// `s 2`, ...), and the triangle's own normal under `s off` / `s 0`; otherwise flat, the triangle's
// own normal: an OBJ without `vn` and without `s` has flat faces, as Blender, Assimp and
// tinyobjloader read it, and a glTF primitive without NORMAL is flat by the glTF 2.0
// specification ("client implementations must calculate flat normals"). A scene file may
// override this per mesh (NormalMode::Flat, Smooth, or CreaseAngle: smooth across edges whose
// faces meet at less than the angle, as Blender's auto smooth), replacing the file's normals.

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace rtlab::scene {

struct LoadedMesh {
    //! Vertex positions. OBJ: as in the file; glTF: with node transforms applied. Vertices that no
    //! kept triangle uses are left out; an OBJ position used with several `vn` is repeated once per
    //! normal. Otherwise the file's order is kept.
    std::vector<glm::vec3> positions;
    //! Unit normal per vertex, chosen by MeshLoadOptions::normals (see the header comment; file
    //! normals: glTF NORMAL transformed by the inverse transpose of the node matrix). A position
    //! with several normals is repeated once per normal.
    std::vector<glm::vec3> normals;
    //! Where the normals came from, for `rtlab scene`: "file (vn)", "smoothing groups", "flat (no
    //! vn, no smoothing groups)", "flat (no NORMAL)", or the override ("flat", "smooth",
    //! "crease angle 60"); "file (vn) and flat" and the like when a mesh mixes them.
    std::string normalsSource;
    //! Three per triangle, counter-clockwise seen from the front (glTF: also under a mirroring
    //! node transform, whose triangles are flipped back).
    std::vector<std::uint32_t> indices;
    //! Material name per triangle; "" for triangles without a material.
    std::vector<std::string> triangleMaterial;
    //! The distinct names of triangleMaterial in first-use order ("" included when used).
    std::vector<std::string> materialNames;
    //! Diffuse colour per materialNames entry: OBJ Kd, glTF baseColorFactor (rgb); 0.8 for an OBJ
    //! material without Kd and for triangles without a material.
    std::vector<glm::vec3> materialAlbedo;
    //! Emitted radiance per materialNames entry: OBJ Ke, glTF emissiveFactor times
    //! KHR_materials_emissive_strength; 0 when absent.
    std::vector<glm::vec3> materialEmission;
    //! Triangles dropped for a repeated vertex index or zero area.
    std::size_t degenerateTrianglesDropped = 0;
    //! Some edge (between bitwise-equal positions) is used by more than two kept triangles.
    bool nonManifold = false;
    //! What was replaced by a default instead of refused (see MeshLoadOptions), one line each,
    //! "file:line: what; default used".
    std::vector<std::string> warnings;

    std::size_t triangleCount() const { return indices.size() / 3; }
};

//! How a mesh's normals are made (see the header comment).
struct NormalMode {
    enum class Kind { FromFile, Flat, Smooth, CreaseAngle };
    Kind kind = Kind::FromFile;
    double creaseAngleDegrees = 180.0; //!< CreaseAngle: in (0, 180]
    //! "from file", "flat", "smooth", "crease angle 60".
    std::string describe() const;
};

struct MeshLoadOptions {
    //! The caller assigns its own material: a missing MTL or material definition is a warning,
    //! and the triangles get the default material (albedo 0.8, no emission).
    bool materialsOptional = false;
    NormalMode normals;
};

//! Loads the mesh at `path`, chosen by extension (case-insensitive): .obj, .gltf or .glb.
//! Throws rtlab::InputError for another extension and for bad input (see the policy above).
LoadedMesh loadMesh(const std::string& path, const MeshLoadOptions& options = {});

namespace detail {

//! A material as a format reader found it.
struct RawMaterial {
    std::string name;
    glm::vec3 albedo{0.8f};
    glm::vec3 emission{0.0f};
};

//! Triangles as a format reader found them, indices already checked against the arrays.
struct RawMesh {
    std::vector<glm::vec3> positions;            //!< finite
    std::vector<glm::vec3> normals;              //!< finite, possibly zero or not unit
    std::vector<std::uint32_t> cornerPosition;   //!< three per triangle, into positions
    std::vector<std::int64_t> cornerNormal;      //!< three per triangle, into normals; -1 for none
    std::vector<std::uint32_t> triangleMaterial; //!< into materials
    //! Per triangle: its OBJ smoothing group, 0 for `s off` / `s 0` and before any `s`; empty
    //! when the file has no smoothing groups (then flat where it gives no normals).
    std::vector<std::uint32_t> triangleSmoothing;
    std::string formatFlatReason = "no vn, no smoothing groups"; //!< why missing normals are flat
    std::vector<RawMaterial> materials;
    std::vector<std::string> warnings; //!< see LoadedMesh::warnings
};

//! Reads OBJ text (the contents of `path`; MTL files are looked up next to it).
RawMesh readObj(const std::string& path, const std::string& text,
                const MeshLoadOptions& options = {});
//! Reads glTF JSON (`binary` false) or GLB (`binary` true) bytes (the contents of `path`).
RawMesh readGltf(const std::string& path, const std::string& bytes, bool binary);
//! Reads the whole file; InputError naming `path` when it is missing or unreadable.
std::string readWholeFile(const std::string& path);
//! Drops degenerate triangles, merges corners into vertices, computes missing normals, resolves
//! materials and checks manifoldness.
LoadedMesh finishMesh(const std::string& path, const RawMesh& raw, const NormalMode& normals = {});

} // namespace detail

} // namespace rtlab::scene
