#pragma once
// The scene model every family shares: triangle meshes with materials, SDF models (CSG edit
// lists, dug over frames), lights (sky, point lights, emissive materials), characters made of
// capsules walking along paths, a canonical camera and a camera path. From its contents a scene
// derives its feature set, which lets the frame pipeline skip passes a scene does not need.

#include "scene/camera.h"
#include "scene/csg.h"
#include "scene/render_scene.h"
#include "scene/sdf_mesher.h"

#include <glm/vec3.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace rtlab::scene {

//! A triangle mesh in world space (transforms are applied when the scene is built).
struct MeshInstance {
    std::string name;
    std::string sourceFile;                        //!< "" for procedural meshes
    std::vector<glm::vec3> positions;              //!< world units
    std::vector<glm::vec3> normals;                //!< per vertex, may be empty (then computed)
    //! Where a loaded mesh's normals came from (LoadedMesh::normalsSource), "" for procedural ones.
    std::string normalsSource;
    std::vector<std::uint32_t> indices;            //!< three per triangle
    std::vector<std::uint32_t> triangleMaterial;   //!< index into Scene::materials
};

struct Capsule {
    glm::vec3 a{0.0f};    //!< segment end, character-local, world units
    glm::vec3 b{0.0f, 1.0f, 0.0f};
    float radius = 0.25f; //!< world units, > 0
};

struct CharacterKey {
    float time = 0.0f;          //!< seconds
    glm::vec3 position{0.0f};   //!< world position of the character's local origin
    float headingDegrees = 0.0f;  //!< rotation about +y
};

//! A dynamic occluder made of capsules (the Tomorrow Children's capsule characters).
struct Character {
    std::string name;
    std::vector<Capsule> capsules;  //!< in the character's local frame
    std::vector<CharacterKey> path; //!< sorted by time; linear interpolation, holds at the ends
    std::uint32_t material = 0;

    //! The capsules in world space at `time`.
    std::vector<Capsule> getCapsulesAt(float time) const;
};

//! A character's capsule at one frame.
struct PosedCapsule {
    Capsule capsule;
    std::uint32_t material = 0;
    std::string character;  //!< name, for messages
};

//! What a scene contains; passes declare which features they need.
enum class SceneFeature : std::uint32_t {
    Triangles = 1u << 0,
    PointLights = 1u << 1,
    Emissive = 1u << 2,
    Sky = 1u << 3,
    Characters = 1u << 4,
    SdfModels = 1u << 5,
    EditsOverTime = 1u << 6,
    MovingCamera = 1u << 7,
};

class FeatureSet {
public:
    void add(SceneFeature f) { mBits |= std::uint32_t(f); }
    bool has(SceneFeature f) const { return (mBits & std::uint32_t(f)) != 0; }
    std::uint32_t bits() const { return mBits; }
    //! "triangles, point_lights, sky" (the names used in reports and skip reasons).
    std::string toString() const;
    static const char* getName(SceneFeature f);
    static const std::vector<SceneFeature>& getAll();

private:
    std::uint32_t mBits = 0;
};

struct Scene {
    std::string name;
    std::string source;  //!< file it was loaded from, or "procedural"
    std::vector<Material> materials;
    std::vector<MeshInstance> meshes;
    std::vector<SdfModel> sdfModels;
    std::vector<PointLight> pointLights;
    Sky sky;
    std::vector<Character> characters;
    Camera camera;         //!< the canonical camera
    CameraPath cameraPath; //!< may be empty (then the canonical camera is used)
    //! More paths by name, chosen by an experiment's camera_path (scene/camera_paths.h).
    std::map<std::string, CameraPath> namedCameraPaths;
    int frameCount = 1;    //!< frames in the scene's animation (edits, characters, camera)
    //! Numbers describing the scene that a study plots against (scene files' `parameters`);
    //! every row of a run on the scene carries them as columns scene.<name>.
    std::map<std::string, double> parameters;
    float frameRate = 30.0f;
    //! What loading replaced by a default instead of refusing (a missing .mtl of a mesh whose
    //! material the scene file assigns, ...), one line each naming the file.
    std::vector<std::string> warnings;

    FeatureSet computeFeatures() const;
    float getFrameTime(int frame) const { return float(frame) / frameRate; }
    Camera getCameraAt(int frame) const;

    //! Flattens frame `frame` into triangles: meshes, meshed SDF models (edits up to the frame),
    //! tessellated character capsules. Throws rtlab::Error when the result has no triangles.
    RenderScene buildRenderScene(int frame = 0) const;

    // The parts of buildRenderScene, for frame pipelines that rebuild only what changed.
    //! Every SDF model meshed with the edits up to `frame` (one per model, in order).
    std::vector<SdfMesh> meshSdfModels(int frame) const;
    //! Every character's capsules at `frame`.
    std::vector<PosedCapsule> poseCharacters(int frame) const;
    //! Changes exactly when the set of applied edits changes (the number of edits started by
    //! `frame`): two frames with the same key mesh to the same SDF meshes.
    std::uint64_t getEditStateKey(int frame) const;
    //! Joins the static meshes with the given parts (as buildRenderScene does):
    //! assembleStaticGeometry, then appendCharacters, then the check for triangles.
    RenderScene assembleRenderScene(const std::vector<SdfMesh>& sdfMeshes, const std::vector<PosedCapsule>& capsules,
                                    int frame) const;
    //! The part of a frame that changes only with the SDF meshes: the meshes and meshed SDF
    //! models with the materials, lights and sky, and their bounds (may have no triangles).
    RenderScene assembleStaticGeometry(const std::vector<SdfMesh>& sdfMeshes) const;
    //! Appends the tessellated capsules to `geometry` (after its triangles) and extends its
    //! bounds over them.
    void appendCharacters(RenderScene& geometry, const std::vector<PosedCapsule>& capsules) const;
};

} // namespace rtlab::scene
