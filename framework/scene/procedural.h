#pragma once
// Procedural scenes registered by name: the scenes studies and tests share, defined in one place
// (framework/scene/procedural/). A scene file may use them by name like files.

#include "scene/scene.h"

#include <functional>
#include <string>
#include <vector>

namespace rtlab::scene {

struct ProceduralScene {
    std::string name;                 //!< registry key used in experiment and scene files
    std::string summary;              //!< one line
    std::function<Scene()> build;
};

const std::vector<ProceduralScene>& getProceduralScenes();
std::vector<std::string> getProceduralSceneNames();
//! Builds the named scene; throws rtlab::Error listing the valid names when it is unknown.
Scene makeProceduralScene(const std::string& name);

// The generators (one file each in procedural/).
Scene makeCornellBox();
Scene makeTomorrowTown();
Scene makeCsgGallery();
Scene makeAoTestbed();

// Helpers for generators: an axis-aligned or oriented quad, and a box, appended to a mesh with
// its faces' normals pointing away from `inside` (for a room: toward the room's inside).
void appendQuad(MeshInstance& mesh, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                const glm::vec3& d, std::uint32_t material, const glm::vec3& facing);
void appendBox(MeshInstance& mesh, const glm::vec3& lo, const glm::vec3& hi, std::uint32_t material);

} // namespace rtlab::scene
