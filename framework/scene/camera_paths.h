#pragma once
// Camera paths an experiment can choose by name (the base key `camera_path`, also a sweep axis):
//   scene    the scene's own path (the default; the canonical camera when it has none)
//   static   the canonical camera, held for every frame
//   orbit    the canonical camera turned 45 degrees about the vertical axis through its target
//   dolly    the canonical camera moved 30 % of the way toward its target
//   strafe   camera and target moved sideways by 20 % of their distance
// plus the named paths of the scene (`camera_paths:` in scene files). Generated paths span the
// run's frames at the scene's frame rate, so a study can put any scene on a moving camera (e.g. to
// measure flicker); the scene's own animation (edits, characters) holds after its last frame.

#include "scene/scene.h"

#include <string>
#include <vector>

namespace rtlab::scene {

const std::vector<std::string>& getBuiltinCameraPathNames();
bool isBuiltinCameraPathName(const std::string& name);
//! The built-in names followed by the scene's own named paths.
std::vector<std::string> getCameraPathNames(const Scene& scene);

//! Makes `name` the path of `scene` for a run of `frames` frames (scene.cameraPath, and
//! scene.frameCount raised to `frames` for every path but "scene"). Throws rtlab::Error naming the
//! valid paths when `name` is neither built in nor one of the scene's.
void selectCameraPath(Scene& scene, const std::string& name, int frames);

} // namespace rtlab::scene
