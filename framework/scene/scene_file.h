#pragma once
// Scene files: YAML documents describing a scene, validated like experiment configs (every error
// names file:line:column, what was found and what is valid). The parser checks and reads the
// document; the builder assembles a Scene from it, loading the OBJ / glTF meshes it references
// (paths relative to the scene file). A scene file may also start from a procedural scene:
//
//   scene: my_room
//   base: cornell_box                # optional: start from a procedural scene
//   materials:
//     - {name: white, albedo: [0.8, 0.8, 0.8]}
//     - {name: lamp, albedo: [0, 0, 0], emission: [4, 4, 4]}
//   meshes:
//     - {file: models/bunny.obj, material: white, translate: [0, 0, 0], scale: 1, rotate_y: 0,
//        normals: from_file}          # from_file (default: what the file means, mesh_loader.h),
//                                     # flat, smooth, or {crease_angle: 60} (degrees, (0, 180])
//   sdf_models:
//     - name: rock
//       bounds: [[-1, -1, -1], [1, 1, 1]]
//       resolution: 64
//       edits:
//         - {shape: box, op: add, center: [0, 0, 0], size: [0.5, 0.5, 0.5], material: white}
//         - {shape: sphere, op: subtract, center: [0.5, 0.5, 0.5], size: [0.4], blend: 0.1, frame: 2}
//   point_lights:
//     - {position: [0, 2, 0], intensity: [5, 5, 5]}
//   sky: {kind: gradient, zenith: [1, 1, 1], horizon: [0.5, 0.5, 0.5], ground: [0.1, 0.1, 0.1]}
//   characters:
//     - name: walker
//       material: white
//       capsules: [{a: [0, 0.2, 0], b: [0, 1.4, 0], radius: 0.25}]
//       path: [{time: 0, position: [0, 0, 0], heading: 0}, {time: 1, position: [2, 0, 0]}]
//   camera: {position: [0, 1, 4], target: [0, 1, 0], fov: 50, near: 0.05, far: 100}
//   camera_path:
//     - {time: 0, position: [0, 1, 4], target: [0, 1, 0]}
//     - {time: 1, position: [2, 1, 4], target: [0, 1, 0]}
//   camera_paths:                       # more named paths; experiments pick one with camera_path
//     low_pass:
//       - {time: 0, position: [0, 0.3, 3], target: [0, 0.3, 0]}
//       - {time: 1, position: [1, 0.3, 3], target: [0, 0.3, 0]}
//   frames: 8
//   frame_rate: 30
//   parameters: {wall_voxels: 0.25}    # numbers a study plots against (row columns scene.<name>)

#include "scene/scene.h"

#include <string>

namespace rtlab::scene {

//! Loads and validates a scene file. Throws rtlab::InputError with file:line:column.
Scene loadSceneFile(const std::string& path);
//! Same from text; `label` stands for the path (relative mesh paths resolve against its folder).
Scene parseSceneFile(const std::string& text, const std::string& label);

//! A scene by name or path: a procedural scene name, or a path to a .yaml scene file.
Scene loadScene(const std::string& nameOrPath);

} // namespace rtlab::scene
