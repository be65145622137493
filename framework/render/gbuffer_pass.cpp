#include "render/gbuffer_pass.h"
#include "gpu/shader_compiler.h"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "render/capsule_mesh_gpu.h"
#include "render/gbuffer_geometry.h"

namespace rtlab::render {

namespace {

constexpr std::size_t kPositionDepth = 0;
constexpr std::size_t kNormal = 1;
constexpr std::size_t kAlbedo = 2;
constexpr std::size_t kEmission = 3;
constexpr std::size_t kMaterial = 4;

const std::vector<gpu::Format>& getAttachmentFormats()
{
    static const std::vector<gpu::Format> formats = {
        gpu::Format::RGBA32Float, gpu::Format::RGBA32Float, gpu::Format::RGBA32Float,
        gpu::Format::RGBA32Float, gpu::Format::R32Uint};
    return formats;
}

} // namespace

gpu::RenderTargetDesc GBufferPass::makeTargetDesc(int width, int height)
{
    if (width < 1 || height < 1)
        throw Error("GBufferPass: invalid size " + std::to_string(width) + "x" +
                    std::to_string(height));
    const float inf = std::numeric_limits<float>::infinity();
    gpu::RenderTargetDesc desc;
    desc.width = static_cast<std::uint32_t>(width);
    desc.height = static_cast<std::uint32_t>(height);
    desc.name = "gbuffer";
    const char* names[] = {"gbuffer position+depth", "gbuffer normal", "gbuffer albedo",
                           "gbuffer emission", "gbuffer material"};
    for (std::size_t i = 0; i < getAttachmentFormats().size(); ++i) {
        gpu::ColorAttachmentDesc color;
        color.format = getAttachmentFormats()[i];
        color.name = names[i];
        desc.colors.push_back(color);
    }
    desc.colors[kPositionDepth].clearFloat = {0.0f, 0.0f, 0.0f, inf};
    desc.colors[kMaterial].clearUint = {scene::kNoMaterial, 0, 0, 0};
    desc.depth = true;
    desc.depthClear = 1.0f;
    return desc;
}

namespace {

gpu::GraphicsPipeline createPipeline(gpu::Context& context, const GBufferPassOptions& options)
{
    gpu::ShaderCompilerOptions compilerOptions = options.compiler;
    compilerOptions.includeDirs.push_back(getRenderShaderDir());
    const gpu::ShaderCompiler compiler(compilerOptions);
    gpu::GraphicsPipelineDesc desc;
    desc.name = "gbuffer";
    desc.vertexSpirv = compiler.compileFile(getRenderShaderDir() / "gbuffer.vert").spirv;
    desc.fragmentSpirv = compiler.compileFile(getRenderShaderDir() / "gbuffer.frag").spirv;
    desc.vertexBindings = {{0, sizeof(GBufferVertex)}};
    desc.vertexAttributes = {
        {0, 0, gpu::VertexFormat::Float3, offsetof(GBufferVertex, position)},
        {1, 0, gpu::VertexFormat::Float3, offsetof(GBufferVertex, normal)},
        {2, 0, gpu::VertexFormat::Uint, offsetof(GBufferVertex, material)},
        {3, 0, gpu::VertexFormat::Float3, offsetof(GBufferVertex, albedo)},
        {4, 0, gpu::VertexFormat::Float3, offsetof(GBufferVertex, emission)},
    };
    desc.colorFormats = getAttachmentFormats();
    desc.depthTest = true;
    desc.cullMode = gpu::CullMode::None;
    desc.pushConstantSize = sizeof(GBufferFrameConstants);
    return context.createGraphicsPipeline(desc);
}

} // namespace

std::filesystem::path getRenderShaderDir()
{
    return gpu::findShaderDir("framework/render/shaders",
                              std::filesystem::path(RTLAB_RENDER_SHADER_DIR));
}

struct GBufferPass::State {
    gpu::Context* context = nullptr;
    gpu::GraphicsPipeline pipeline;
    gpu::Buffer vertices;
    gpu::Buffer indices;
    std::uint32_t indexCount = 0;
    std::size_t vertexCount = 0;
    bool hasScene = false;
    //! What the buffers hold (setScene uploads only what changed from it).
    GBufferGeometry uploaded;
    CapsuleMeshGpu capsules; //!< meshes the characters where they moved
    // The scene the buffers hold: its static part's key, counts and capsules
    // (onlyCharactersMoved).
    std::string staticKey;
    std::size_t scenePositions = 0, sceneIndices = 0;
    std::vector<scene::CapsuleMesh> sceneCapsules;
    void remember(const scene::RenderScene& scene)
    {
        staticKey = scene.staticKey;
        scenePositions = scene.positions.size();
        sceneIndices = scene.indices.size();
        sceneCapsules = scene.capsules;
    }
    gpu::RenderTarget target;               //!< own target of draw(camera, width, height)
    const gpu::RenderTarget* last = nullptr; //!< the target of the last draw
    bool drawn = false;
    scene::Camera camera;
    glm::vec2 jitter{0.0f};
    FrameMatrices matrices;
    std::optional<double> lastGpuMs;
};

GBufferPass::GBufferPass(gpu::Context& context, GBufferPassOptions options)
    : mState(std::make_unique<State>())
{
    mState->context = &context;
    mState->pipeline = createPipeline(context, options);
}

GBufferPass::~GBufferPass() = default;
GBufferPass::GBufferPass(GBufferPass&&) noexcept = default;
GBufferPass& GBufferPass::operator=(GBufferPass&&) noexcept = default;

void GBufferPass::setScene(const scene::RenderScene& scene, bool patch)
{
    State& s = *mState;
    // Only the characters moved: their vertices are meshed on the device from their poses, and
    // nothing else is rebuilt, compared or uploaded (what is held keeps their new positions, as
    // the vertex buffer will).
    if (patch && s.hasScene &&
        onlyCharactersMoved(scene, s.staticKey, s.scenePositions, s.sceneIndices, s.sceneCapsules)) {
        if (scene.capsules == s.sceneCapsules)
            return; // not even they moved
        forEachCapsuleVertex(scene, [&](std::size_t v) {
            s.uploaded.vertices[v].position = scene.positions[v];
            s.uploaded.vertices[v].normal = scene.normals[v];
        });
        s.capsules.write(*s.context, scene.capsules, s.vertices, sizeof(GBufferVertex) / sizeof(float), true);
        s.sceneCapsules = scene.capsules;
        return;
    }
    GBufferGeometry geometry = buildGBufferGeometry(scene);
    // A scene that fits the buffers (a character moved, a light did, a dig changed a model's
    // mesh by a little): only the span of vertices and indices that differs goes over the bus.
    if (patch && s.hasScene && !geometry.vertices.empty() && !geometry.indices.empty() &&
        geometry.vertices.size() * sizeof(GBufferVertex) <= s.vertices.getSize() &&
        geometry.indices.size() * sizeof(std::uint32_t) <= s.indices.getSize()) {
        s.hasScene = false;
        // The characters' vertices are meshed on the device from their poses (the same bits):
        // held as the new ones, they are left out of the span that goes up.
        const bool meshCapsules =
            canMeshCapsulesOnDevice(scene, s.uploaded.vertices.size(), geometry.vertices.size());
        if (meshCapsules)
            forEachCapsuleVertex(scene, [&](std::size_t v) {
                s.uploaded.vertices[v].position = geometry.vertices[v].position;
                s.uploaded.vertices[v].normal = geometry.vertices[v].normal;
            });
        gpu::uploadChangedSpan<GBufferVertex>(s.vertices, s.uploaded.vertices, geometry.vertices);
        gpu::uploadChangedSpan<std::uint32_t>(s.indices, s.uploaded.indices, geometry.indices);
        if (meshCapsules)
            s.capsules.write(*s.context, scene.capsules, s.vertices, sizeof(GBufferVertex) / sizeof(float), true);
        s.indexCount = static_cast<std::uint32_t>(geometry.indices.size());
        s.vertexCount = geometry.vertices.size();
        s.uploaded = std::move(geometry);
        s.remember(scene);
        s.hasScene = true;
        return;
    }
    s.hasScene = false;
    // Buffers cannot be empty: an empty scene keeps one unused vertex and triangle. With room to
    // be patched when the scene grows a little; without patching, the exact size (the ablation
    // allocates and uploads as before).
    const auto room = [patch](std::size_t n) { return patch ? gpu::getPatchCapacity(n) : n; };
    const std::size_t vertexCount = room(std::max<std::size_t>(geometry.vertices.size(), 1));
    const std::size_t indexCount = room(std::max<std::size_t>(geometry.indices.size(), 3));
    gpu::BufferDesc vertexDesc{vertexCount * sizeof(GBufferVertex), "gbuffer vertices", true};
    gpu::BufferDesc indexDesc{indexCount * sizeof(std::uint32_t), "gbuffer indices", true};
    s.vertices = s.context->createBuffer(vertexDesc);
    s.indices = s.context->createBuffer(indexDesc);
    if (!geometry.vertices.empty())
        s.vertices.uploadSpan<GBufferVertex>(geometry.vertices);
    if (!geometry.indices.empty())
        s.indices.uploadSpan<std::uint32_t>(geometry.indices);
    s.indexCount = static_cast<std::uint32_t>(geometry.indices.size());
    s.vertexCount = geometry.vertices.size();
    s.uploaded = std::move(geometry);
    s.remember(scene);
    s.hasScene = true;
}

bool GBufferPass::hasScene() const
{
    return mState->hasScene;
}

std::size_t GBufferPass::getVertexCount() const
{
    return mState->vertexCount;
}

gpu::RunResult GBufferPass::draw(const scene::Camera& camera, int width, int height,
                                 glm::vec2 jitterPixels)
{
    State& s = *mState;
    if (!s.hasScene)
        throw Error("GBufferPass::draw: no scene was set");
    if (width < 1 || height < 1)
        throw Error("GBufferPass::draw: invalid size " + std::to_string(width) + "x" +
                    std::to_string(height));
    if (!s.target.isValid() || s.target.getWidth() != static_cast<std::uint32_t>(width) ||
        s.target.getHeight() != static_cast<std::uint32_t>(height)) {
        if (s.last == &s.target)
            s.last = nullptr;
        s.target = gpu::RenderTarget(); // free the old attachments first
        s.target = s.context->createRenderTarget(makeTargetDesc(width, height));
    }
    return draw(s.target, camera, jitterPixels);
}

gpu::RunResult GBufferPass::draw(const gpu::RenderTarget& target, const scene::Camera& camera,
                                 glm::vec2 jitterPixels)
{
    State& s = *mState;
    if (!s.hasScene)
        throw Error("GBufferPass::draw: no scene was set");
    const gpu::RenderTargetDesc expected =
        makeTargetDesc(int(std::max(target.getWidth(), 1u)), int(std::max(target.getHeight(), 1u)));
    const gpu::RenderTargetDesc& given = target.getDesc();
    bool matches = target.isValid() && given.colors.size() == expected.colors.size() && given.depth;
    for (std::size_t i = 0; matches && i < given.colors.size(); ++i)
        matches = given.colors[i].format == expected.colors[i].format;
    if (!matches)
        throw Error("GBufferPass::draw: the render target was not made from makeTargetDesc()");
    const int width = int(target.getWidth());
    const int height = int(target.getHeight());

    const FrameMatrices m = computeFrameMatrices(camera, width, height, jitterPixels);
    glm::mat4 rotation = m.view;
    rotation[3] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
    GBufferFrameConstants constants;
    constants.relativeViewProjection = m.projection * rotation;
    constants.cameraPosition = glm::vec4(m.cameraPosition, 1.0f);
    constants.viewForward = glm::vec4(m.viewForward, 0.0f);

    gpu::IndexedDraw drawCall;
    drawCall.vertexBuffers = {&s.vertices};
    drawCall.indexBuffer = &s.indices;
    drawCall.indexCount = s.indexCount;
    gpu::RunResult result = s.context->run([&](gpu::CommandList& cmd) {
        cmd.drawIndexed(s.pipeline, target, drawCall, gpu::PushConstants(constants), kDrawLabel);
    });

    s.last = &target;
    s.drawn = true;
    s.camera = camera;
    s.jitter = jitterPixels;
    s.matrices = m;
    s.lastGpuMs = result.sumGpuMs(kDrawLabel);
    return result;
}

scene::GBuffer GBufferPass::readBack() const
{
    const State& s = *mState;
    if (!s.drawn || s.last == nullptr)
        throw Error("GBufferPass::readBack: nothing was drawn yet");
    const gpu::RenderTarget& target = *s.last;
    const int w = static_cast<int>(target.getWidth());
    const int h = static_cast<int>(target.getHeight());
    const std::size_t n = std::size_t(w) * std::size_t(h);

    scene::GBuffer g;
    g.width = w;
    g.height = h;
    g.camera = s.camera;
    g.jitter = s.jitter;
    g.view = s.matrices.view;
    g.projection = s.matrices.projection;
    g.depth = Image<float>(w, h);
    g.position = Image<glm::vec3>(w, h);
    g.normal = Image<glm::vec3>(w, h);
    g.albedo = Image<glm::vec3>(w, h);
    g.emission = Image<glm::vec3>(w, h);

    std::vector<glm::vec4> texels = target.downloadColorVector<glm::vec4>(kPositionDepth);
    for (std::size_t i = 0; i < n; ++i) {
        g.position.pixels[i] = glm::vec3(texels[i]);
        g.depth.pixels[i] = texels[i].w;
    }
    const std::pair<std::size_t, Image<glm::vec3>*> vectors[] = {
        {kNormal, &g.normal}, {kAlbedo, &g.albedo}, {kEmission, &g.emission}};
    for (const auto& [attachment, image] : vectors) {
        target.downloadColor(attachment, texels.data(), texels.size() * sizeof(glm::vec4));
        for (std::size_t i = 0; i < n; ++i)
            image->pixels[i] = glm::vec3(texels[i]);
    }
    g.materialId.width = w;
    g.materialId.height = h;
    g.materialId.pixels = target.downloadColorVector<std::uint32_t>(kMaterial);
    return g;
}

scene::GBuffer GBufferPass::render(const scene::Camera& camera, int width, int height,
                                   glm::vec2 jitterPixels)
{
    draw(camera, width, height, jitterPixels);
    return readBack();
}

std::optional<double> GBufferPass::getLastGpuMs() const
{
    return mState->lastGpuMs;
}

const gpu::RenderTarget& GBufferPass::getTarget() const
{
    return mState->last != nullptr ? *mState->last : mState->target;
}

scene::GBuffer renderGBuffer(gpu::Context& context, const scene::RenderScene& scene,
                             const scene::Camera& camera, int width, int height,
                             glm::vec2 jitterPixels, const GBufferPassOptions& options)
{
    GBufferPass pass(context, options);
    pass.setScene(scene);
    return pass.render(camera, width, height, jitterPixels);
}

} // namespace rtlab::render
