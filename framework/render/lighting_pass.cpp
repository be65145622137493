#include "render/lighting_pass.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "core/error.h"
#include "render/frame_matrices.h"
#include "render/gbuffer_pass.h"
#include "render/image_transfer.h"

namespace rtlab::render {

namespace {

constexpr std::uint32_t kGroupSize = 8; // lighting.comp and tonemap.comp: 8 x 8 invocations
constexpr int kLobes = scene::kConeDirectionCount;
// G-buffer attachments the lighting reads (render/gbuffer_pass.h): position + depth, normal,
// albedo, emission.
constexpr std::size_t kGBufferImages = 4;

// The GPU layout of one light (std430).
struct GpuLight {
    glm::vec4 position;  // xyz world units, w: first atlas slice of its map, -1 without
    glm::vec4 intensity; // rgb
};

// The GPU layout of the sky header (std430), followed by the irradiance table.
struct GpuSkyHeader {
    glm::vec4 parameters; // kind (0 none, 1 constant, 2 gradient, 3 srbf), sharpness, table size
    glm::vec4 constant;
    glm::vec4 zenith;
    glm::vec4 horizon;
    glm::vec4 ground;
    glm::vec4 axes[kLobes];
    glm::vec4 lobeRadiance[kLobes];
};
static_assert(sizeof(GpuSkyHeader) == 16 * (5 + 2 * kLobes), "must match lighting.comp");

std::uint32_t getSkyKindCode(scene::Sky::Kind kind)
{
    switch (kind) {
    case scene::Sky::Kind::None:
        return 0;
    case scene::Sky::Kind::Constant:
        return 1;
    case scene::Sky::Kind::Gradient:
        return 2;
    case scene::Sky::Kind::Srbf:
        return 3;
    }
    return 0;
}

gpu::ComputePipeline createComputePipeline(gpu::Context& context,
                                           const gpu::ShaderCompiler& compiler, const char* file,
                                           const char* name, std::vector<gpu::BindingSlot> bindings,
                                           std::uint32_t pushConstantSize)
{
    gpu::ComputePipelineDesc desc;
    desc.name = name;
    desc.spirv = compiler.compileFile(getRenderShaderDir() / file).spirv;
    desc.bindings = std::move(bindings);
    desc.pushConstantSize = pushConstantSize;
    return context.createPipeline(desc);
}

gpu::Image createImage2D(gpu::Context& context, gpu::Format format, std::uint32_t width,
                         std::uint32_t height, const char* name)
{
    gpu::ImageDesc desc;
    desc.format = format;
    desc.width = width;
    desc.height = height;
    desc.usage = gpu::ImageUsage::Storage;
    desc.name = name;
    return context.createImage(desc);
}

void requireImage(const gpu::Image& image, gpu::Format format, std::uint32_t width,
                  std::uint32_t height, const char* what)
{
    const gpu::ImageDesc& d = image.getDesc();
    if (!image.isValid() || d.dimension != gpu::ImageDimension::Image2D || d.format != format ||
        d.width != width || d.height != height)
        throw Error(std::string("LightingPass: ") + what + " must be a 2D " +
                    std::string(gpu::getFormatName(format)) + " image of " + std::to_string(width) +
                    "x" + std::to_string(height) + ", got '" + d.name + "' " +
                    std::to_string(d.width) + "x" + std::to_string(d.height) + " " +
                    std::string(gpu::getFormatName(d.format)));
}

} // namespace

const char* getTonemapperName(Tonemapper tonemapper)
{
    switch (tonemapper) {
    case Tonemapper::Aces:
        return "aces";
    case Tonemapper::Reinhard:
        return "reinhard";
    }
    return "aces";
}

Tonemapper parseTonemapper(std::string_view name)
{
    if (name == "aces")
        return Tonemapper::Aces;
    if (name == "reinhard")
        return Tonemapper::Reinhard;
    throw Error("unknown tonemapper '" + std::string(name) + "' (valid: aces, reinhard)");
}

float encodeSrgb(float linear)
{
    // IEC 61966-2-1.
    return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

glm::vec3 computeTonemappedColor(glm::vec3 hdr, const TonemapSettings& settings)
{
    const float scale = std::exp2(settings.exposureEv);
    glm::vec3 out;
    for (int c = 0; c < 3; ++c) {
        float x = hdr[c] * scale;
        x = x > 0.0f ? x : 0.0f; // also maps NaN to 0
        float y;
        if (settings.tonemapper == Tonemapper::Aces) // [Narkowicz 2015]
            y = (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f);
        else // [Reinhard et al. 2002], per channel
            y = x / (1.0f + x);
        out[c] = encodeSrgb(std::clamp(y, 0.0f, 1.0f));
    }
    return out;
}

struct LightingPass::State {
    gpu::Context* context = nullptr;
    LightingPassOptions options;
    gpu::ComputePipeline lighting;
    gpu::ComputePipeline tonemap;

    std::uint32_t width = 0;
    std::uint32_t height = 0;
    gpu::Image gbuffer[kGBufferImages];
    gpu::Image hdr;
    gpu::Image direct;
    gpu::Image ldr;
    bool drawn = false;

    // Stand-ins bound where an input is absent (the pipeline binds every slot).
    gpu::Image noShadows;
    gpu::Image noOcclusion;
    gpu::Image noCones;
    gpu::Image noIndirect;

    gpu::Buffer lights;
    std::size_t lightCapacity = 0;
    gpu::Buffer sky;
    bool hasSky = false;
    scene::Sky lastSky;
    SkyLobes lobes;

    SkyVisibility lastVisibility = SkyVisibility::None;
    bool lastIndirect = false;
    bool lastConeSky = false;
    std::optional<double> lastGpuMs;

    void resize(std::uint32_t w, std::uint32_t h)
    {
        if (w == width && h == height && hdr.isValid())
            return;
        const char* names[kGBufferImages] = {"lighting position+depth", "lighting normal",
                                             "lighting albedo", "lighting emission"};
        for (std::size_t i = 0; i < kGBufferImages; ++i) {
            gbuffer[i] = gpu::Image();
            gbuffer[i] = createImage2D(*context, gpu::Format::RGBA32Float, w, h, names[i]);
        }
        hdr = createImage2D(*context, gpu::Format::RGBA32Float, w, h, "lighting hdr");
        direct = createImage2D(*context, gpu::Format::RGBA32Float, w, h, "lighting direct");
        ldr = createImage2D(*context, gpu::Format::RGBA8Unorm, w, h, "lighting ldr");
        width = w;
        height = h;
    }

    void updateSky(const scene::Sky& sceneSky)
    {
        if (hasSky && isSameSky(sceneSky, lastSky))
            return;
        lobes = projectSkyOntoLobes(sceneSky);
        const int tableSize = options.skyTableSize;
        const std::vector<float> table = computeLobeIrradianceTable(lobes.sharpness, tableSize);
        GpuSkyHeader header{};
        header.parameters = glm::vec4(float(getSkyKindCode(sceneSky.kind)), lobes.sharpness,
                                      float(tableSize), 0.0f);
        header.constant = glm::vec4(sceneSky.constant, 0.0f);
        header.zenith = glm::vec4(sceneSky.zenith, 0.0f);
        header.horizon = glm::vec4(sceneSky.horizon, 0.0f);
        header.ground = glm::vec4(sceneSky.ground, 0.0f);
        for (int k = 0; k < kLobes; ++k) {
            header.axes[k] = glm::vec4(glm::vec3(scene::getConeDirections()[k]), 0.0f);
            header.lobeRadiance[k] = glm::vec4(lobes.radiance[k], 0.0f);
        }
        std::vector<std::byte> bytes(sizeof(GpuSkyHeader) + table.size() * sizeof(float));
        std::memcpy(bytes.data(), &header, sizeof(header));
        std::memcpy(bytes.data() + sizeof(header), table.data(), table.size() * sizeof(float));
        sky = context->createBuffer({bytes.size(), "lighting sky"});
        sky.upload(bytes.data(), bytes.size());
        lastSky = sceneSky;
        hasSky = true;
    }
};

LightingPass::LightingPass(gpu::Context& context, LightingPassOptions options)
    : mState(std::make_unique<State>())
{
    if (!(options.minLightDistance > 0.0f))
        throw Error("LightingPass: minLightDistance must be > 0");
    if (!(options.pcfSpacingTexels >= 0.0f && options.normalOffsetTexels >= 0.0f &&
          options.slopeOffsetTexels >= 0.0f))
        throw Error("LightingPass: PCF spacing and shadow offsets must be >= 0");
    if (options.skyTableSize < 2 || options.skyTableSize > 65536)
        throw Error("LightingPass: skyTableSize " + std::to_string(options.skyTableSize) +
                    " is outside 2..65536");
    if (!std::isfinite(options.tonemap.exposureEv))
        throw Error("LightingPass: exposure must be finite");
    State& s = *mState;
    s.context = &context;
    s.options = options;

    gpu::ShaderCompilerOptions compilerOptions = options.compiler;
    compilerOptions.includeDirs.push_back(getRenderShaderDir());
    const gpu::ShaderCompiler compiler(compilerOptions);
    using gpu::BindingType;
    std::vector<gpu::BindingSlot> slots;
    for (std::uint32_t b = 0; b <= 15; ++b) {
        const bool buffer = b == 5 || b == 6;
        slots.push_back({b, buffer ? BindingType::StorageBuffer : BindingType::StorageImage});
    }
    s.lighting = createComputePipeline(context, compiler, "lighting.comp", "lighting", slots,
                                       sizeof(LightingConstants));
    s.tonemap = createComputePipeline(
        context, compiler, "tonemap.comp", "tonemap",
        {{0, BindingType::StorageImage}, {1, BindingType::StorageImage}}, sizeof(TonemapConstants));

    gpu::ImageDesc atlas;
    atlas.dimension = gpu::ImageDimension::Image3D;
    atlas.format = gpu::Format::R32Float;
    atlas.usage = gpu::ImageUsage::Storage;
    atlas.name = "lighting no shadows";
    s.noShadows = context.createImage(atlas);
    s.noOcclusion = createImage2D(context, gpu::Format::R32Float, 1, 1, "lighting no occlusion");
    s.noIndirect = createImage2D(context, gpu::Format::RGBA32Float, 1, 1, "lighting no indirect");
    s.noCones = createImage2D(context, gpu::Format::RGBA32Float, 1, 1, "lighting no cones");
    // Stand-ins are never read, but give them defined contents.
    const float zero[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    s.noShadows.upload(zero, sizeof(float));
    s.noOcclusion.upload(zero, sizeof(float));
    s.noIndirect.upload(zero, sizeof(zero));
    const float ones[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    s.noCones.upload(ones, sizeof(ones));
}

LightingPass::~LightingPass() = default;
LightingPass::LightingPass(LightingPass&&) noexcept = default;
LightingPass& LightingPass::operator=(LightingPass&&) noexcept = default;

gpu::RunResult LightingPass::draw(const scene::RenderScene& scene, const LightingInputs& inputs)
{
    State& s = *mState;
    if (inputs.gbuffer == nullptr || !inputs.gbuffer->isValid())
        throw Error("LightingPass::draw: no G-buffer (draw the GBufferPass first)");
    const gpu::RenderTarget& target = *inputs.gbuffer;
    if (target.getDesc().colors.size() < kGBufferImages)
        throw Error("LightingPass::draw: the render target is not a G-buffer");
    const std::uint32_t w = target.getWidth();
    const std::uint32_t h = target.getHeight();
    const bool hasCones = inputs.coneVisibility[0] != nullptr;
    for (const gpu::Image* image : inputs.coneVisibility) {
        if ((image != nullptr) != hasCones)
            throw Error("LightingPass::draw: give all four cone visibility images or none");
        if (image != nullptr)
            requireImage(*image, gpu::Format::RGBA32Float, w, h, "cone visibility");
    }
    if (inputs.ambientOcclusion != nullptr && hasCones)
        throw Error("LightingPass::draw: give ambient occlusion or cone visibilities, not both");
    if (inputs.ambientOcclusion != nullptr)
        requireImage(*inputs.ambientOcclusion, gpu::Format::R32Float, w, h, "ambient occlusion");
    if (inputs.indirectIrradiance != nullptr)
        requireImage(*inputs.indirectIrradiance, gpu::Format::RGBA32Float, w, h,
                     "indirect irradiance");
    if (inputs.coneSkyIrradiance != nullptr)
        requireImage(*inputs.coneSkyIrradiance, gpu::Format::RGBA32Float, w, h,
                     "cone sky irradiance");

    if (inputs.outHdr != nullptr)
        requireImage(*inputs.outHdr, gpu::Format::RGBA32Float, w, h, "HDR output");
    if (inputs.outDirect != nullptr)
        requireImage(*inputs.outDirect, gpu::Format::RGBA32Float, w, h, "direct output");
    if ((inputs.outHdr == nullptr) != (inputs.outDirect == nullptr))
        throw Error("LightingPass::draw: give both outputs (HDR and direct) or neither");
    const bool ownOutputs = inputs.outHdr == nullptr;

    s.resize(w, h);
    s.updateSky(scene.sky);

    // Lights, with the atlas slices of those the shadow pass has rendered.
    const std::size_t lightCount = scene.pointLights.size();
    std::vector<GpuLight> lights(std::max<std::size_t>(lightCount, 1), GpuLight{});
    for (std::size_t i = 0; i < lightCount; ++i) {
        const scene::PointLight& l = scene.pointLights[i];
        float slice = -1.0f;
        if (inputs.shadows != nullptr && i < inputs.shadows->getLightCount() &&
            inputs.shadows->getLightState(i).rendered)
            slice = float(i * kCubeFaceCount);
        lights[i].position = glm::vec4(l.position, slice);
        lights[i].intensity = glm::vec4(l.intensity, 0.0f);
    }
    if (lights.size() > s.lightCapacity) {
        s.lights = s.context->createBuffer({lights.size() * sizeof(GpuLight), "lighting lights"});
        s.lightCapacity = lights.size();
    }
    s.lights.uploadSpan<GpuLight>(lights);

    // Rays of background pixels: the inverse of the G-buffer's camera-relative view-projection.
    const FrameMatrices m =
        computeFrameMatrices(inputs.camera, int(w), int(h), inputs.jitterPixels);
    glm::mat4 rotation = m.view;
    rotation[3] = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);

    const SkyVisibility visibility = inputs.ambientOcclusion != nullptr
                                         ? SkyVisibility::AmbientOcclusion
                                     : hasCones ? SkyVisibility::Cones
                                                                        : SkyVisibility::None;
    LightingConstants constants;
    constants.inverseRelativeViewProjection = glm::inverse(m.projection * rotation);
    constants.cameraPosition = glm::vec4(m.cameraPosition, s.options.minLightDistance);
    constants.sizeLightsVisibility =
        glm::uvec4(w, h, std::uint32_t(lightCount), std::uint32_t(visibility));
    constants.flags =
        glm::uvec4(inputs.indirectIrradiance != nullptr ? 1u : 0u,
                   inputs.shadows != nullptr ? inputs.shadows->getFaceSize() : 1,
                   inputs.coneSkyIrradiance != nullptr ? 1u : 0u, 0u);
    constants.shadowParameters = glm::vec4(s.options.pcfSpacingTexels, s.options.normalOffsetTexels,
                                           s.options.slopeOffsetTexels, 0.0f);

    TonemapConstants tonemap;
    tonemap.exposureScale = std::exp2(s.options.tonemap.exposureEv);
    tonemap.tonemapper = std::uint32_t(s.options.tonemap.tonemapper);
    tonemap.width = w;
    tonemap.height = h;

    const gpu::Image& atlas = inputs.shadows != nullptr ? inputs.shadows->getAtlas() : s.noShadows;
    const gpu::Image& ao =
        inputs.ambientOcclusion != nullptr ? *inputs.ambientOcclusion : s.noOcclusion;
    const auto cone = [&](std::size_t g) -> const gpu::Image& {
        return hasCones ? *inputs.coneVisibility[g] : s.noCones;
    };
    const gpu::Image& indirect =
        inputs.indirectIrradiance != nullptr ? *inputs.indirectIrradiance : s.noIndirect;
    const gpu::Image& coneSky =
        inputs.coneSkyIrradiance != nullptr ? *inputs.coneSkyIrradiance : s.noIndirect;
    const gpu::GroupCount groups{gpu::computeGroupCount(w, kGroupSize),
                                 gpu::computeGroupCount(h, kGroupSize), 1};

    gpu::RunResult result = s.context->run([&](gpu::CommandList& cmd) {
        for (std::size_t i = 0; i < kGBufferImages; ++i)
            copyAttachmentToImage(cmd, target, i, s.gbuffer[i], 0, kCopyLabel);
        cmd.dispatch(
            s.lighting,
            {gpu::Binding::storageImage(0, s.gbuffer[0]),
             gpu::Binding::storageImage(1, s.gbuffer[1]),
             gpu::Binding::storageImage(2, s.gbuffer[2]),
             gpu::Binding::storageImage(3, s.gbuffer[3]), gpu::Binding::storageImage(4, atlas),
             gpu::Binding::storageBuffer(5, s.lights), gpu::Binding::storageBuffer(6, s.sky),
             gpu::Binding::storageImage(7, ao), gpu::Binding::storageImage(8, cone(0)),
             gpu::Binding::storageImage(9, indirect),
             gpu::Binding::storageImage(10, ownOutputs ? s.hdr : *inputs.outHdr),
             gpu::Binding::storageImage(11, ownOutputs ? s.direct : *inputs.outDirect),
             gpu::Binding::storageImage(12, cone(1)), gpu::Binding::storageImage(13, cone(2)),
             gpu::Binding::storageImage(14, cone(3)), gpu::Binding::storageImage(15, coneSky)},
            gpu::PushConstants(constants), groups, kLightingLabel);
        if (ownOutputs)
            cmd.dispatch(
                s.tonemap,
                {gpu::Binding::storageImage(0, s.hdr), gpu::Binding::storageImage(1, s.ldr)},
                gpu::PushConstants(tonemap), groups, kTonemapLabel);
    });
    s.drawn = s.drawn || ownOutputs;
    s.lastVisibility = visibility;
    s.lastIndirect = inputs.indirectIrradiance != nullptr;
    s.lastConeSky = inputs.coneSkyIrradiance != nullptr;
    const auto copyMs = result.sumGpuMs(kCopyLabel);
    const auto lightingMs = result.sumGpuMs(kLightingLabel);
    const auto tonemapMs = ownOutputs ? result.sumGpuMs(kTonemapLabel) : std::optional<double>(0.0);
    s.lastGpuMs = copyMs && lightingMs && tonemapMs
                      ? std::optional<double>(*copyMs + *lightingMs + *tonemapMs)
                      : std::nullopt;
    return result;
}

gpu::RunResult LightingPass::tonemap(const TonemapSettings& settings)
{
    State& s = *mState;
    if (!s.drawn)
        throw Error("LightingPass::tonemap: nothing was drawn yet");
    return tonemap(s.hdr, settings);
}

gpu::RunResult LightingPass::tonemap(const gpu::Image& hdr, const TonemapSettings& settings)
{
    State& s = *mState;
    const gpu::ImageDesc& d = hdr.getDesc();
    if (!hdr.isValid() || d.dimension != gpu::ImageDimension::Image2D ||
        d.format != gpu::Format::RGBA32Float)
        throw Error("LightingPass::tonemap: '" + d.name + "' is not a 2D RGBA32Float image");
    if (!std::isfinite(settings.exposureEv))
        throw Error("LightingPass::tonemap: exposure must be finite");
    if (&hdr != &s.hdr && (!s.ldr.isValid() || s.ldr.getDesc().width != d.width ||
                           s.ldr.getDesc().height != d.height)) {
        s.ldr = gpu::Image();
        s.ldr =
            createImage2D(*s.context, gpu::Format::RGBA8Unorm, d.width, d.height, "lighting ldr");
    }
    return tonemap(hdr, settings, s.ldr);
}

gpu::RunResult LightingPass::tonemap(const gpu::Image& hdr, const TonemapSettings& settings,
                                     const gpu::Image& ldr)
{
    State& s = *mState;
    const gpu::ImageDesc& d = hdr.getDesc();
    if (!hdr.isValid() || d.dimension != gpu::ImageDimension::Image2D ||
        d.format != gpu::Format::RGBA32Float)
        throw Error("LightingPass::tonemap: '" + d.name + "' is not a 2D RGBA32Float image");
    requireImage(ldr, gpu::Format::RGBA8Unorm, d.width, d.height, "tonemapped output");
    if (!std::isfinite(settings.exposureEv))
        throw Error("LightingPass::tonemap: exposure must be finite");
    TonemapConstants constants;
    constants.exposureScale = std::exp2(settings.exposureEv);
    constants.tonemapper = std::uint32_t(settings.tonemapper);
    constants.width = d.width;
    constants.height = d.height;
    const gpu::GroupCount groups{gpu::computeGroupCount(d.width, kGroupSize),
                                 gpu::computeGroupCount(d.height, kGroupSize), 1};
    gpu::RunResult result = s.context->run([&](gpu::CommandList& cmd) {
        cmd.dispatch(s.tonemap,
                     {gpu::Binding::storageImage(0, hdr), gpu::Binding::storageImage(1, ldr)},
                     gpu::PushConstants(constants), groups, kTonemapLabel);
    });
    s.lastGpuMs = result.sumGpuMs(kTonemapLabel);
    return result;
}

const gpu::Image& LightingPass::getHdr() const
{
    return mState->hdr;
}

const gpu::Image& LightingPass::getDirect() const
{
    return mState->direct;
}

const gpu::Image& LightingPass::getLdr() const
{
    return mState->ldr;
}

Image<glm::vec3> LightingPass::readBackHdr() const
{
    if (!mState->drawn)
        throw Error("LightingPass::readBackHdr: nothing was drawn yet");
    return downloadRgb(mState->hdr);
}

Image<glm::vec3> LightingPass::readBackDirect() const
{
    if (!mState->drawn)
        throw Error("LightingPass::readBackDirect: nothing was drawn yet");
    return downloadRgb(mState->direct);
}

Image<glm::vec3> LightingPass::readBackLdr() const
{
    if (!mState->ldr.isValid())
        throw Error("LightingPass::readBackLdr: nothing was tonemapped yet");
    return downloadRgb(mState->ldr);
}

const SkyLobes& LightingPass::getSkyLobes() const
{
    return mState->lobes;
}

SkyVisibility LightingPass::getLastVisibility() const
{
    return mState->lastVisibility;
}

bool LightingPass::hadIndirect() const
{
    return mState->lastIndirect;
}

bool LightingPass::hadConeSky() const
{
    return mState->lastConeSky;
}

std::optional<double> LightingPass::getLastGpuMs() const
{
    return mState->lastGpuMs;
}

} // namespace rtlab::render
