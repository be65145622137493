#include "render/capsule_mesh_gpu.h"

#include "core/error.h"
#include "gpu/shader_compiler.h"
#include "render/gbuffer_pass.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <bit>

namespace rtlab::render {

namespace {

struct Constants {
    glm::uvec4 counts{0u}; // capsules, vertices per capsule, floats per vertex, normals
};

} // namespace

bool canMeshCapsulesOnDevice(const scene::RenderScene& scene, std::size_t heldVertices, std::size_t nextVertices)
{
    if (scene.capsules.empty() || heldVertices != nextVertices)
        return false;
    const std::size_t perCapsule = scene::getCapsuleVertexCount();
    for (const scene::CapsuleMesh& c : scene.capsules)
        if (std::size_t(c.firstVertex) + perCapsule > nextVertices || c.firstVertex >= scene.positions.size())
            return false;
    return true;
}

bool onlyCharactersMoved(const scene::RenderScene& next, const std::string& heldStaticKey, std::size_t heldVertices,
                         std::size_t heldIndices, const std::vector<scene::CapsuleMesh>& heldCapsules)
{
    if (next.staticKey.empty() || next.staticKey != heldStaticKey || next.positions.size() != heldVertices ||
        next.indices.size() != heldIndices || next.capsules.size() != heldCapsules.size() || next.capsules.empty())
        return false;
    for (std::size_t i = 0; i < next.capsules.size(); ++i)
        if (next.capsules[i].firstVertex != heldCapsules[i].firstVertex ||
            next.capsules[i].material != heldCapsules[i].material)
            return false;
    return true;
}

std::size_t CapsuleMeshGpu::write(gpu::Context& context, const std::vector<scene::CapsuleMesh>& capsules,
                                  gpu::Buffer& vertices, std::uint32_t floatsPerVertex, bool normals)
{
    if (capsules.empty())
        return 0;
    if (floatsPerVertex < (normals ? 6u : 3u))
        throw Error("CapsuleMeshGpu: " + std::to_string(floatsPerVertex) + " floats per vertex cannot hold a " +
                    (normals ? "position and a normal" : "position"));
    const std::size_t perCapsule = scene::getCapsuleVertexCount();
    std::size_t end = 0;
    for (const scene::CapsuleMesh& c : capsules)
        end = std::max(end, std::size_t(c.firstVertex) + perCapsule);
    if (end * floatsPerVertex * sizeof(float) > vertices.getSize())
        throw Error("CapsuleMeshGpu: the capsules' vertices end at vertex " + std::to_string(end) +
                    ", past the buffer '" + vertices.getName() + "' (" + std::to_string(vertices.getSize()) +
                    " bytes)");
    std::size_t uploaded = 0;
    if (mContext != &context || !mPipeline.isValid()) {
        mContext = &context;
        gpu::ComputePipelineDesc desc;
        desc.name = "capsule_mesh";
        desc.spirv = gpu::ShaderCompiler().compileFile(getRenderShaderDir() / "capsule_mesh.comp").spirv;
        desc.bindings = {{0, gpu::BindingType::StorageBuffer},
                         {1, gpu::BindingType::StorageBuffer},
                         {2, gpu::BindingType::StorageBuffer}};
        desc.pushConstantSize = sizeof(Constants);
        mPipeline = context.createPipeline(desc);
        const std::vector<glm::vec4>& unit = scene::getCapsuleTemplate();
        mTemplate = context.createBuffer({unit.size() * sizeof(glm::vec4), "capsule_mesh.template"});
        mTemplate.uploadSpan<glm::vec4>(unit);
        uploaded += unit.size() * sizeof(glm::vec4);
        mCapsules = gpu::Buffer();
    }
    std::vector<glm::vec4> packed;
    packed.reserve(capsules.size() * 5);
    for (const scene::CapsuleMesh& c : capsules) {
        packed.emplace_back(c.a, c.radius);
        packed.emplace_back(c.b, std::bit_cast<float>(c.firstVertex));
        packed.emplace_back(c.t0, 0.0f);
        packed.emplace_back(c.t1, 0.0f);
        packed.emplace_back(c.up, 0.0f);
    }
    const std::size_t bytes = packed.size() * sizeof(glm::vec4);
    if (!mCapsules.isValid() || mCapsules.getSize() < bytes)
        // Written for every use: where the device cannot map its memory, read over the bus.
        mCapsules = context.createBuffer({bytes, "capsule_mesh.capsules", false, true});
    mCapsules.uploadSpan<glm::vec4>(packed);
    uploaded += bytes;
    Constants constants;
    constants.counts = {std::uint32_t(capsules.size()), std::uint32_t(perCapsule), floatsPerVertex, normals ? 1u : 0u};
    context.run([&](gpu::CommandList& cmd) {
        cmd.dispatch(mPipeline,
                     {gpu::Binding::storageBuffer(0, mTemplate), gpu::Binding::storageBuffer(1, mCapsules),
                      gpu::Binding::storageBuffer(2, vertices)},
                     gpu::PushConstants(constants),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(capsules.size() * perCapsule), 64), 1, 1},
                     "capsule_mesh");
    });
    return uploaded;
}

} // namespace rtlab::render
