#pragma once
// Cube shadow maps of point lights, rasterised with Vulkan. For every scene::PointLight the
// scene's triangles are drawn into the six faces of a cube around the light; each texel stores
// the Euclidean distance from the light to the nearest surface along its direction (R32F, +inf
// where nothing was drawn). The lighting pass (render/lighting_pass.h) compares a receiver's
// distance against it with a filtered lookup.
//
//   render::ShadowPass shadows(ctx);
//   shadows.render(scene);                   // every light
//   std::size_t moved[] = {2};
//   shadows.render(scene, moved);            // only light 2 (it moved)
//   std::uint8_t faces[] = {0x01, 0x00, 0x3F};
//   shadows.renderFaces(scene, faces);       // face +x of light 0, every face of light 2
//
// Storage. rtlab's images have a single array layer and no cube views, so the maps live in one
// 3D R32Float image, the atlas: getFaceSize() x getFaceSize() x 6 * lightCount, slice
// 6 * light + face. Faces follow the Vulkan cube-map convention (face = major axis +x, -x, +y,
// -y, +z, -z; face coordinates (s, t) of the Vulkan specification's cube-map table, t = texel
// row), so that the atlas could become a cube array without changing a lookup:
// computeCubeFace / computeCubeFaceCoords below are the CPU twins of shaders/cube_shadow.glsl.
//
// Each face is drawn into a faceSize^2 render target (perspective, 90 degree field of view,
// depth test, no culling: triangles cast shadows from both sides) and copied on the GPU into
// its atlas slice. Near plane: nearPlaneScale * the scene's bounding-box diagonal (a caster
// closer than that to the light casts no shadow); far plane: beyond the farthest corner of the
// scene's bounds.
//
// Per-light state. The pass remembers, per light, whether its map was rendered, from where and
// with which planes, so a caller (a frame graph) can re-render only the lights, and of those only
// the faces, whose casters or position changed: computeCubeFacesTouching tells which faces see a
// box of changed triangles. The planes depend only on the scene's bounds and the light's
// position, so a face that is not re-rendered holds exactly what re-rendering it would give as
// long as its casters, the bounds and the light stay the same. All faces of a light share one
// projection: a partial face mask is widened to every face when the light's position or planes
// differ from its last rendering. When the number of lights changes, the atlas is reallocated
// and every face of every light is rendered.

#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "scene/render_scene.h"

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/image.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

namespace rtlab::render {

//! Number of faces of a cube map.
inline constexpr int kCubeFaceCount = 6;

//! The push constants of shadow.vert/.frag.
struct ShadowFaceConstants {
    glm::mat4 relativeFaceProjection{1.0f}; //!< (p - light) -> clip space of the face
    glm::vec4 lightPosition{0.0f};          //!< xyz: world units
};
static_assert(sizeof(ShadowFaceConstants) == 80, "must match shadow.vert");

//! Settings of a ShadowPass.
struct ShadowPassOptions {
    int faceSize = 256;                  //!< texels per face side, 1..4096
    float nearPlaneScale = 1e-4f;        //!< near plane / scene bounding-box diagonal, in (0, 0.1]
    gpu::ShaderCompilerOptions compiler; //!< SPIR-V cache etc.; the shader dir is searched too
};

//! Face mask with every face of a cube (bit f = face f, see computeCubeFace).
inline constexpr std::uint8_t kAllCubeFaces = 0x3F;

//! What the pass knows about the map of one light.
struct ShadowLightState {
    bool rendered = false;         //!< its atlas slices hold a rendering
    glm::vec3 position{0.0f};      //!< where the light was when it was last rendered
    float nearPlane = 0.0f;        //!< of that rendering, world units
    float farPlane = 0.0f;         //!< of that rendering, world units
    std::uint64_t renderCount = 0; //!< renderings (of one face or more) so far
    //! Renderings of each face so far (index = face).
    std::array<std::uint64_t, kCubeFaceCount> faceRenderCounts{};
    std::uint8_t lastFaceMask = 0; //!< faces drawn by the last render call, 0: none
};

//! Major-axis face of direction `d` (!= 0): 0 +x, 1 -x, 2 +y, 3 -y, 4 +z, 5 -z (ties go to x,
//! then y).
int computeCubeFace(glm::vec3 d);
//! Face coordinates (s, t) in [-1, 1] of direction `d` on `face` (Vulkan cube-map table: for
//! face +x, s = -z / |x| and t = -y / |x|, ...). Texel column (s + 1) / 2 * size, row
//! (t + 1) / 2 * size.
glm::vec2 computeCubeFaceCoords(glm::vec3 d, int face);
//! The (unnormalised) direction of face coordinates `st` on `face`: the inverse of the above.
glm::vec3 computeCubeFaceDirection(int face, glm::vec2 st);
//! (p - light) -> clip space of `face` for the given planes: x = s, y = t, w = distance along
//! the face's axis, depth in [0, 1] from near to far.
glm::mat4 computeCubeFaceProjection(int face, float nearPlane, float farPlane);
//! Mask (bit f = face f) of the faces of a cube map at `light` whose 90 degree pyramid (the
//! points whose major axis is the face's: |other coordinates| <= the face's coordinate) meets
//! the box [boxMin, boxMax]. Conservative: a face may be reported that the box misses (it tests
//! the pyramid's four planes against the box's corners, with a little slack for rounding), a
//! face the box meets never is left out. kAllCubeFaces when the light is inside the box, 0 for
//! an empty box (a min coordinate above the max).
std::uint8_t computeCubeFacesTouching(glm::vec3 light, glm::vec3 boxMin, glm::vec3 boxMax);

//! Renders cube shadow maps for the point lights of a scene. Move-only; the Context must
//! outlive it.
class ShadowPass {
public:
    //! Label of each face's draw in gpu::RunResult.
    static constexpr std::string_view kDrawLabel = "shadow";
    //! Label of each face's copy into the atlas.
    static constexpr std::string_view kCopyLabel = "shadow copy";

    //! Compiles the shaders and creates the pipeline. Throws rtlab::Error for a bad option or
    //! when the device cannot draw.
    explicit ShadowPass(gpu::Context& context, ShadowPassOptions options = {});
    //! The next rendering uploads the scene's geometry whole (by default a scene with as many
    //! vertices and indices as the last uploads only the span that differs).
    void forgetGeometry();
    ~ShadowPass();
    ShadowPass(ShadowPass&&) noexcept;
    ShadowPass& operator=(ShadowPass&&) noexcept;

    //! Renders the maps of every light of `scene`.
    gpu::RunResult render(const scene::RenderScene& scene);
    //! Renders every face of the lights `lightIndices` (into scene.pointLights; duplicates are
    //! drawn once), as renderFaces with kAllCubeFaces for them and 0 for the others. Throws
    //! rtlab::Error for an index out of range (and as renderFaces).
    gpu::RunResult render(const scene::RenderScene& scene,
                          std::span<const std::size_t> lightIndices);
    //! Uploads the scene's triangles when they differ from the last call's and renders, per
    //! light, the faces of its mask (faceMasks[i] for scene.pointLights[i], bit f = face f;
    //! lights with mask 0 keep their maps and state). A partial mask is widened to every face
    //! when the light was not rendered yet, or its position or planes differ from its last
    //! rendering. When the number of lights differs from the last call, every face of every
    //! light is rendered. Throws rtlab::Error when faceMasks.size() != scene.pointLights.size(),
    //! for a mask with bits above kAllCubeFaces, an inconsistent scene, or more lights than a
    //! 3D image can hold.
    gpu::RunResult renderFaces(const scene::RenderScene& scene,
                               std::span<const std::uint8_t> faceMasks);

    //! The atlas for `lightCount` lights of faceSize x faceSize faces (see the file comment).
    static gpu::ImageDesc makeAtlasDesc(int faceSize, std::size_t lightCount);
    //! Renders into `atlas` from now on: an image the caller owns (the frame graph's,
    //! pipeline/compose.h), made from makeAtlasDesc(getFaceSize(), n) for at most n lights; it
    //! must outlive this pass's use of it. Every light's maps are drawn again on the next
    //! render. Throws rtlab::Error for an image of another kind.
    void useAtlas(const gpu::Image& atlas);

    int getFaceSize() const;
    //! Lights of the last render() or renderFaces() (0 before the first).
    std::size_t getLightCount() const;
    //! The state of light `light` (< getLightCount()).
    const ShadowLightState& getLightState(std::size_t light) const;
    //! The atlas (see the file comment); a 1 x 1 x 1 image before the first render().
    const gpu::Image& getAtlas() const;
    //! Reads back face `face` of light `light`'s map (distance, +inf where nothing was drawn);
    //! row t, column s as described above.
    Image<float> readBackFace(std::size_t light, int face) const;
    //! GPU time of the draws and copies of the last render() in milliseconds; empty before the
    //! first or without timestamps.
    std::optional<double> getLastGpuMs() const;

private:
    struct State;
    std::unique_ptr<State> mState;
};

} // namespace rtlab::render
