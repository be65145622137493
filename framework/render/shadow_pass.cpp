#include "render/shadow_pass.h"

#include "render/capsule_mesh_gpu.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vector_relational.hpp>

#include "core/error.h"
#include "render/gbuffer_geometry.h"
#include "render/gbuffer_pass.h"
#include "render/image_transfer.h"

namespace rtlab::render {

namespace {

// Face axis F, and the directions R and U whose components give s and t (Vulkan cube-map
// table): direction(face, s, t) = F + s R + t U.
struct FaceBasis {
    glm::vec3 forward;
    glm::vec3 right;
    glm::vec3 up;
};

constexpr std::array<FaceBasis, kCubeFaceCount> kFaces = {{
    {{1, 0, 0}, {0, 0, -1}, {0, -1, 0}},  // +x: s = -z/|x|, t = -y/|x|
    {{-1, 0, 0}, {0, 0, 1}, {0, -1, 0}},  // -x: s = +z/|x|, t = -y/|x|
    {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}},    // +y: s = +x/|y|, t = +z/|y|
    {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},  // -y: s = +x/|y|, t = -z/|y|
    {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},   // +z: s = +x/|z|, t = -y/|z|
    {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}}, // -z: s = -x/|z|, t = -y/|z|
}};

gpu::GraphicsPipeline createPipeline(gpu::Context& context, const ShadowPassOptions& options)
{
    gpu::ShaderCompilerOptions compilerOptions = options.compiler;
    compilerOptions.includeDirs.push_back(getRenderShaderDir());
    const gpu::ShaderCompiler compiler(compilerOptions);
    gpu::GraphicsPipelineDesc desc;
    desc.name = "shadow";
    desc.vertexSpirv = compiler.compileFile(getRenderShaderDir() / "shadow.vert").spirv;
    desc.fragmentSpirv = compiler.compileFile(getRenderShaderDir() / "shadow.frag").spirv;
    desc.vertexBindings = {{0, sizeof(glm::vec3)}};
    desc.vertexAttributes = {{0, 0, gpu::VertexFormat::Float3, 0}};
    desc.colorFormats = {gpu::Format::R32Float};
    desc.depthTest = true;
    desc.cullMode = gpu::CullMode::None;
    desc.pushConstantSize = sizeof(ShadowFaceConstants);
    return context.createGraphicsPipeline(desc);
}

gpu::RenderTargetDesc makeFaceTargetDesc(int size)
{
    gpu::RenderTargetDesc desc;
    desc.width = static_cast<std::uint32_t>(size);
    desc.height = static_cast<std::uint32_t>(size);
    desc.name = "shadow face";
    gpu::ColorAttachmentDesc color;
    color.format = gpu::Format::R32Float;
    color.name = "shadow face distance";
    const float inf = std::numeric_limits<float>::infinity();
    color.clearFloat = {inf, inf, inf, inf}; // no occluder
    desc.colors.push_back(color);
    desc.depth = true;
    desc.depthClear = 1.0f;
    return desc;
}

} // namespace

int computeCubeFace(glm::vec3 d)
{
    const glm::vec3 a = glm::abs(d);
    if (a.x >= a.y && a.x >= a.z)
        return d.x >= 0.0f ? 0 : 1;
    if (a.y >= a.z)
        return d.y >= 0.0f ? 2 : 3;
    return d.z >= 0.0f ? 4 : 5;
}

glm::vec2 computeCubeFaceCoords(glm::vec3 d, int face)
{
    const FaceBasis& f = kFaces[static_cast<std::size_t>(face)];
    const float major = glm::dot(d, f.forward);
    return glm::vec2(glm::dot(d, f.right), glm::dot(d, f.up)) / major;
}

glm::vec3 computeCubeFaceDirection(int face, glm::vec2 st)
{
    const FaceBasis& f = kFaces[static_cast<std::size_t>(face)];
    return f.forward + st.x * f.right + st.y * f.up;
}

glm::mat4 computeCubeFaceProjection(int face, float nearPlane, float farPlane)
{
    const FaceBasis& f = kFaces[static_cast<std::size_t>(face)];
    // Rows: clip.x = d.R, clip.y = d.U (framebuffer row t grows with it, row 0 at t = -1),
    // clip.w = d.F, clip.z = a d.F + b so that depth = z / w runs from 0 (near) to 1 (far).
    const float a = farPlane / (farPlane - nearPlane);
    const float b = -farPlane * nearPlane / (farPlane - nearPlane);
    glm::mat4 m(0.0f);
    for (int c = 0; c < 3; ++c) {
        m[c][0] = f.right[c];
        m[c][1] = f.up[c];
        m[c][2] = a * f.forward[c];
        m[c][3] = f.forward[c];
    }
    m[3][2] = b;
    return m;
}

std::uint8_t computeCubeFacesTouching(glm::vec3 light, glm::vec3 boxMin, glm::vec3 boxMax)
{
    if (boxMin.x > boxMax.x || boxMin.y > boxMax.y || boxMin.z > boxMax.z)
        return 0;
    if (glm::all(glm::lessThanEqual(boxMin, light)) && glm::all(glm::lessThanEqual(light, boxMax)))
        return kAllCubeFaces;
    std::array<glm::vec3, 8> corners;
    for (int corner = 0; corner < 8; ++corner)
        corners[static_cast<std::size_t>(corner)] =
            glm::vec3((corner & 1) ? boxMax.x : boxMin.x, (corner & 2) ? boxMax.y : boxMin.y,
                      (corner & 4) ? boxMax.z : boxMin.z) -
            light;
    std::uint8_t mask = 0;
    for (int face = 0; face < kCubeFaceCount; ++face) {
        const FaceBasis& f = kFaces[static_cast<std::size_t>(face)];
        // The pyramid is F.d >= |R.d| and F.d >= |U.d|: four planes through the light (F.d >= 0,
        // implied by them, is a fifth that rejects boxes behind the face). The box misses it
        // when all its corners lie outside one of them. The slack (relative to the corner's
        // distance) keeps a box that grazes a plane in despite float rounding; the GPU's texel
        // centres lie half a texel inside the face, so the slack loses nothing.
        const std::array<glm::vec3, 5> normals = {f.forward - f.right, f.forward + f.right,
                                                  f.forward - f.up, f.forward + f.up, f.forward};
        bool outside = false;
        for (const glm::vec3& n : normals) {
            bool allOut = true;
            for (const glm::vec3& d : corners) {
                const float slack = 1e-5f * (std::abs(d.x) + std::abs(d.y) + std::abs(d.z));
                if (glm::dot(n, d) >= -slack) {
                    allOut = false;
                    break;
                }
            }
            if (allOut) {
                outside = true;
                break;
            }
        }
        if (!outside)
            mask = static_cast<std::uint8_t>(mask | (1u << face));
    }
    return mask;
}

struct ShadowPass::State {
    gpu::Context* context = nullptr;
    ShadowPassOptions options;
    gpu::GraphicsPipeline pipeline;
    gpu::RenderTarget faceTarget;
    gpu::Image atlas;
    gpu::Buffer vertices;
    gpu::Buffer indices;
    std::uint32_t indexCount = 0;
    bool uploaded = false;
    std::vector<glm::vec3> uploadedPositions; // what the buffers hold, to skip equal uploads
    CapsuleMeshGpu capsules;                  // meshes the characters where they moved
    std::vector<std::uint32_t> uploadedIndices;
    // The static part of what the buffers hold (onlyCharactersMoved) and its bounds (of the
    // vertices before the characters').
    std::string staticKey;
    std::vector<scene::CapsuleMesh> uploadedCapsules;
    glm::vec3 staticMin{std::numeric_limits<float>::max()}, staticMax{std::numeric_limits<float>::lowest()};
    glm::vec3 boundsMin{0.0f};
    glm::vec3 boundsMax{0.0f};
    std::vector<ShadowLightState> lights;
    std::optional<double> lastGpuMs;

    const gpu::Image* external = nullptr; //!< the caller's atlas (useAtlas), else `atlas`

    const gpu::Image& getAtlasImage() const { return external != nullptr ? *external : atlas; }

    void createAtlas(std::size_t lightCount)
    {
        const gpu::ImageDesc desc = makeAtlasDesc(options.faceSize, lightCount);
        const std::uint32_t limit = context->getDeviceInfo().maxImageDimension3D;
        if (desc.depth > limit)
            throw Error("ShadowPass: " + std::to_string(lightCount) +
                        " lights need a 3D image of depth " + std::to_string(desc.depth) +
                        ", the device allows " + std::to_string(limit));
        if (external != nullptr) {
            if (external->getDesc().depth < desc.depth)
                throw Error("ShadowPass: the atlas given to useAtlas() holds " +
                            std::to_string(external->getDesc().depth / kCubeFaceCount) +
                            " lights, the scene has " + std::to_string(lightCount));
            return;
        }
        atlas = gpu::Image(); // free the old one first
        atlas = context->createImage(desc);
    }

    void uploadGeometry(const scene::RenderScene& scene)
    {
        // Only the characters moved: their vertices are meshed on the device from their poses;
        // nothing else is compared or uploaded, and the bounds are the static part's and theirs.
        if (uploaded && onlyCharactersMoved(scene, staticKey, uploadedPositions.size(), uploadedIndices.size(),
                                            uploadedCapsules)) {
            if (scene.capsules == uploadedCapsules)
                return; // not even they moved
            boundsMin = staticMin;
            boundsMax = staticMax;
            forEachCapsuleVertex(scene, [&](std::size_t v) {
                uploadedPositions[v] = scene.positions[v];
                boundsMin = glm::min(boundsMin, scene.positions[v]);
                boundsMax = glm::max(boundsMax, scene.positions[v]);
            });
            capsules.write(*context, scene.capsules, vertices, 3, false);
            uploadedCapsules = scene.capsules;
            return;
        }
        if (uploaded && scene.positions == uploadedPositions && scene.indices == uploadedIndices)
            return;
        validateRenderScene(scene);
        // Vertices and indices that fit the buffers (a character moved, a dig changed a mesh by
        // a little): only the span that differs goes over the bus; the planes follow the new
        // bounds.
        const bool fits = uploaded && !scene.positions.empty() && !scene.indices.empty() &&
                          scene.positions.size() * sizeof(glm::vec3) <= vertices.getSize() &&
                          scene.indices.size() * sizeof(std::uint32_t) <= indices.getSize();
        uploaded = false;
        if (fits) {
            // The characters' vertices are meshed on the device from their poses (the same
            // bits): held as the new ones, they are left out of the span that goes up.
            const bool meshCapsules =
                canMeshCapsulesOnDevice(scene, uploadedPositions.size(), scene.positions.size());
            if (meshCapsules)
                forEachCapsuleVertex(scene, [&](std::size_t v) { uploadedPositions[v] = scene.positions[v]; });
            gpu::uploadChangedSpan<glm::vec3>(vertices, uploadedPositions, scene.positions);
            gpu::uploadChangedSpan<std::uint32_t>(indices, uploadedIndices, scene.indices);
            if (meshCapsules)
                capsules.write(*context, scene.capsules, vertices, 3, false);
        } else {
            // Buffers cannot be empty: an empty scene keeps one unused vertex and triangle.
            // With room to be patched when the scene grows a little (gpu::getPatchCapacity).
            const std::size_t vertexSlots =
                gpu::getPatchCapacity(std::max<std::size_t>(scene.positions.size(), 1));
            const std::size_t indexSlots =
                gpu::getPatchCapacity(std::max<std::size_t>(scene.indices.size(), 3));
            vertices = context->createBuffer(
                {vertexSlots * sizeof(glm::vec3), "shadow vertices", /*vertexIndexUsage=*/true});
            indices = context->createBuffer(
                {indexSlots * sizeof(std::uint32_t), "shadow indices", /*vertexIndexUsage=*/true});
            if (!scene.positions.empty())
                vertices.uploadSpan<glm::vec3>(scene.positions);
            if (!scene.indices.empty())
                indices.uploadSpan<std::uint32_t>(scene.indices);
        }
        indexCount = static_cast<std::uint32_t>(scene.indices.size());
        uploadedPositions = scene.positions;
        uploadedIndices = scene.indices;
        staticMin = boundsMin = glm::vec3(std::numeric_limits<float>::max());
        staticMax = boundsMax = glm::vec3(std::numeric_limits<float>::lowest());
        const std::size_t firstCharacter =
            scene.capsules.empty() ? scene.positions.size() : std::size_t(scene.capsules.front().firstVertex);
        for (std::size_t i = 0; i < scene.positions.size(); ++i) {
            const glm::vec3& p = scene.positions[i];
            if (i == firstCharacter) {
                staticMin = boundsMin;
                staticMax = boundsMax;
            }
            boundsMin = glm::min(boundsMin, p);
            boundsMax = glm::max(boundsMax, p);
        }
        if (scene.positions.empty())
            boundsMin = boundsMax = glm::vec3(0.0f);
        staticKey = scene.staticKey;
        uploadedCapsules = scene.capsules;
        uploaded = true;
    }
};

void ShadowPass::forgetGeometry()
{
    mState->uploaded = false;
    mState->uploadedPositions.clear();
    mState->uploadedIndices.clear();
    mState->staticKey.clear();
}

ShadowPass::ShadowPass(gpu::Context& context, ShadowPassOptions options)
    : mState(std::make_unique<State>())
{
    if (options.faceSize < 1 || options.faceSize > 4096)
        throw Error("ShadowPass: faceSize " + std::to_string(options.faceSize) +
                    " is outside 1..4096");
    if (!(options.nearPlaneScale > 0.0f && options.nearPlaneScale <= 0.1f))
        throw Error("ShadowPass: nearPlaneScale " + std::to_string(options.nearPlaneScale) +
                    " is outside (0, 0.1]");
    State& s = *mState;
    s.context = &context;
    s.options = options;
    s.pipeline = createPipeline(context, options);
    s.faceTarget = context.createRenderTarget(makeFaceTargetDesc(options.faceSize));
    s.createAtlas(0);
}

gpu::ImageDesc ShadowPass::makeAtlasDesc(int faceSize, std::size_t lightCount)
{
    gpu::ImageDesc desc;
    desc.dimension = gpu::ImageDimension::Image3D;
    desc.format = gpu::Format::R32Float;
    desc.width = desc.height = static_cast<std::uint32_t>(std::max(faceSize, 1));
    desc.depth =
        static_cast<std::uint32_t>(std::max<std::size_t>(lightCount, 1) * kCubeFaceCount);
    desc.usage = gpu::ImageUsage::Storage;
    desc.name = "shadow atlas";
    return desc;
}

void ShadowPass::useAtlas(const gpu::Image& atlas)
{
    State& s = *mState;
    const gpu::ImageDesc& d = atlas.getDesc();
    if (!atlas.isValid() || d.dimension != gpu::ImageDimension::Image3D ||
        d.format != gpu::Format::R32Float || int(d.width) != s.options.faceSize ||
        int(d.height) != s.options.faceSize || d.depth % kCubeFaceCount != 0)
        throw Error("ShadowPass::useAtlas: the atlas must be a 3D R32Float image of " +
                    std::to_string(s.options.faceSize) + " x " +
                    std::to_string(s.options.faceSize) + " x 6 n texels (makeAtlasDesc)");
    s.external = &atlas;
    s.atlas = gpu::Image();
    s.lights.clear(); // every map is drawn again into the new atlas
}

ShadowPass::~ShadowPass() = default;
ShadowPass::ShadowPass(ShadowPass&&) noexcept = default;
ShadowPass& ShadowPass::operator=(ShadowPass&&) noexcept = default;

gpu::RunResult ShadowPass::render(const scene::RenderScene& scene)
{
    const std::vector<std::uint8_t> all(scene.pointLights.size(), kAllCubeFaces);
    return renderFaces(scene, all);
}

gpu::RunResult ShadowPass::render(const scene::RenderScene& scene,
                                  std::span<const std::size_t> lightIndices)
{
    const std::size_t lightCount = scene.pointLights.size();
    std::vector<std::uint8_t> masks(lightCount, 0);
    for (const std::size_t i : lightIndices) {
        if (i >= lightCount)
            throw Error("ShadowPass::render: light " + std::to_string(i) + " of " +
                        std::to_string(lightCount));
        masks[i] = kAllCubeFaces;
    }
    return renderFaces(scene, masks);
}

gpu::RunResult ShadowPass::renderFaces(const scene::RenderScene& scene,
                                       std::span<const std::uint8_t> faceMasks)
{
    State& s = *mState;
    const std::size_t lightCount = scene.pointLights.size();
    if (faceMasks.size() != lightCount)
        throw Error("ShadowPass::renderFaces: " + std::to_string(faceMasks.size()) +
                    " face masks for " + std::to_string(lightCount) + " lights");
    for (std::size_t i = 0; i < lightCount; ++i)
        if ((faceMasks[i] & ~kAllCubeFaces) != 0)
            throw Error("ShadowPass::renderFaces: face mask " + std::to_string(faceMasks[i]) +
                        " of light " + std::to_string(i) + " has bits above face 5");
    s.uploadGeometry(scene);

    std::vector<std::uint8_t> masks(faceMasks.begin(), faceMasks.end());
    if (lightCount != s.lights.size()) {
        s.createAtlas(lightCount);
        s.lights.assign(lightCount, ShadowLightState{});
        masks.assign(lightCount, kAllCubeFaces);
    }

    const float diagonal = glm::length(s.boundsMax - s.boundsMin);
    const float scale = diagonal > 0.0f ? diagonal : 1.0f;
    const float nearPlane = s.options.nearPlaneScale * scale;

    struct FaceDraw {
        std::uint32_t slice = 0;
        ShadowFaceConstants constants;
    };
    std::vector<FaceDraw> draws;
    for (std::size_t light = 0; light < lightCount; ++light) {
        ShadowLightState& state = s.lights[light];
        state.lastFaceMask = 0;
        std::uint8_t mask = masks[light];
        if (mask == 0)
            continue;
        const glm::vec3 p = scene.pointLights[light].position;
        float farthest = 0.0f;
        for (int corner = 0; corner < 8; ++corner) {
            const glm::vec3 c((corner & 1) ? s.boundsMax.x : s.boundsMin.x,
                              (corner & 2) ? s.boundsMax.y : s.boundsMin.y,
                              (corner & 4) ? s.boundsMax.z : s.boundsMin.z);
            farthest = std::max(farthest, glm::length(c - p));
        }
        const float farPlane = std::max(farthest * 1.01f + nearPlane, 4.0f * nearPlane);
        // The faces kept from the last rendering were drawn with its projection: mixing two
        // projections in one cube would give a map no full rendering gives.
        if (!state.rendered || state.position != p || state.nearPlane != nearPlane ||
            state.farPlane != farPlane)
            mask = kAllCubeFaces;
        for (int face = 0; face < kCubeFaceCount; ++face) {
            if ((mask & (1u << face)) == 0)
                continue;
            FaceDraw d;
            d.slice = static_cast<std::uint32_t>(light * kCubeFaceCount + std::size_t(face));
            d.constants.relativeFaceProjection =
                computeCubeFaceProjection(face, nearPlane, farPlane);
            d.constants.lightPosition = glm::vec4(p, 1.0f);
            draws.push_back(d);
            ++state.faceRenderCounts[static_cast<std::size_t>(face)];
        }
        state.rendered = true;
        state.position = p;
        state.nearPlane = nearPlane;
        state.farPlane = farPlane;
        state.lastFaceMask = mask;
        ++state.renderCount;
    }

    gpu::IndexedDraw drawCall;
    drawCall.vertexBuffers = {&s.vertices};
    drawCall.indexBuffer = &s.indices;
    drawCall.indexCount = s.indexCount;
    gpu::RunResult result = s.context->run([&](gpu::CommandList& cmd) {
        for (const FaceDraw& d : draws) {
            cmd.drawIndexed(s.pipeline, s.faceTarget, drawCall, gpu::PushConstants(d.constants),
                            kDrawLabel);
            copyAttachmentToImage(cmd, s.faceTarget, 0, s.getAtlasImage(), d.slice, kCopyLabel);
        }
    });
    const std::optional<double> drawMs = result.sumGpuMs(kDrawLabel);
    const std::optional<double> copyMs = result.sumGpuMs(kCopyLabel);
    s.lastGpuMs = drawMs && copyMs ? std::optional<double>(*drawMs + *copyMs) : std::nullopt;
    return result;
}

int ShadowPass::getFaceSize() const
{
    return mState->options.faceSize;
}

std::size_t ShadowPass::getLightCount() const
{
    return mState->lights.size();
}

const ShadowLightState& ShadowPass::getLightState(std::size_t light) const
{
    if (light >= mState->lights.size())
        throw Error("ShadowPass::getLightState: light " + std::to_string(light) + " of " +
                    std::to_string(mState->lights.size()));
    return mState->lights[light];
}

const gpu::Image& ShadowPass::getAtlas() const
{
    return mState->getAtlasImage();
}

Image<float> ShadowPass::readBackFace(std::size_t light, int face) const
{
    const State& s = *mState;
    if (light >= s.lights.size() || face < 0 || face >= kCubeFaceCount)
        throw Error("ShadowPass::readBackFace: no face " + std::to_string(face) + " of light " +
                    std::to_string(light));
    const std::vector<float> all = s.getAtlasImage().downloadVector<float>();
    const int n = s.options.faceSize;
    Image<float> result(n, n);
    const std::size_t offset =
        (light * kCubeFaceCount + std::size_t(face)) * std::size_t(n) * std::size_t(n);
    std::copy(all.begin() + static_cast<std::ptrdiff_t>(offset),
              all.begin() + static_cast<std::ptrdiff_t>(offset + result.pixels.size()),
              result.pixels.begin());
    return result;
}

std::optional<double> ShadowPass::getLastGpuMs() const
{
    return mState->lastGpuMs;
}

} // namespace rtlab::render
