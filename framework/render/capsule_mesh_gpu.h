#pragma once
// The characters' capsules meshed on the device (shaders/capsule_mesh.comp): a frame where only
// the characters moved sends their poses (80 bytes a capsule: ends, radius, frame) instead of
// their vertices (238 a capsule), and one dispatch writes the vertices where the vertex buffer
// holds them, as scene.cpp's appendCapsule meshed them into the RenderScene (scene::CapsuleMesh),
// bit for bit. The G-buffer and shadow passes use it for the span of their vertex buffers that
// the characters fill.

#include "gpu/context.h"
#include "scene/render_scene.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rtlab::render {

//! Whether a pass that holds `heldVertices` vertices of its last upload can patch to `scene`
//! (`nextVertices` vertices) with the characters' vertices meshed on the device: the same count
//! (so the capsules' vertices are where the held ones were), and some capsules.
bool canMeshCapsulesOnDevice(const scene::RenderScene& scene, std::size_t heldVertices, std::size_t nextVertices);

//! Whether `next` differs from `held` (what a pass uploaded last) only by where its characters
//! are: the same static part (RenderScene::staticKey, known), vertex and index counts, and
//! capsules (their first vertices and materials). Then only the capsules' vertices changed.
bool onlyCharactersMoved(const scene::RenderScene& next, const std::string& heldStaticKey, std::size_t heldVertices,
                         std::size_t heldIndices, const std::vector<scene::CapsuleMesh>& heldCapsules);

//! Calls `visit(v)` for every vertex index v of the scene's capsules.
template <class Visit>
void forEachCapsuleVertex(const scene::RenderScene& scene, const Visit& visit)
{
    const std::size_t perCapsule = scene::getCapsuleVertexCount();
    for (const scene::CapsuleMesh& c : scene.capsules)
        for (std::size_t i = 0; i < perCapsule; ++i)
            visit(std::size_t(c.firstVertex) + i);
}

class CapsuleMeshGpu {
public:
    //! Writes every vertex of `capsules` into `vertices`, a buffer of vertices of `floatsPerVertex`
    //! floats each: the position at float 0 and, with `normals`, the normal at float 3. One
    //! dispatch in its own submission (the next one's leading barrier orders the draw after it).
    //! Returns the bytes uploaded (the capsules; the template once per context).
    std::size_t write(gpu::Context& context, const std::vector<scene::CapsuleMesh>& capsules, gpu::Buffer& vertices,
                      std::uint32_t floatsPerVertex, bool normals);

private:
    gpu::Context* mContext = nullptr;
    gpu::ComputePipeline mPipeline;
    gpu::Buffer mTemplate, mCapsules;
};

} // namespace rtlab::render
