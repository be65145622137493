#include "pipeline/compose.h"

#include "core/error.h"
#include "gpu/context.h"
#include "pipeline/gpu_resources.h"
#include "render/image_transfer.h"
#include "render/lighting_pass.h"
#include "render/shadow_pass.h"
#include "scene/sky.h"

#include <algorithm>
#include <cstring>

namespace rtlab::pipeline {

Compose::Compose(FrameStart& start, ComposeOptions options)
    : mStart(start), mOptions(std::move(options)), mWidth(start.getOptions().width),
      mHeight(start.getOptions().height)
{
    render::parseTonemapper(mOptions.tonemapper); // throws for an unknown name
    if (mOptions.shadowMapSize < 1)
        throw Error("compose: shadow map size must be at least 1, found " +
                    std::to_string(mOptions.shadowMapSize));
}

Compose::~Compose() = default;

void Compose::addPasses(FrameGraph& graph)
{
    const auto geometry = mStart.geometry();
    const auto gbuffer = mStart.gbuffer();
    const auto ao = ambientOcclusionSlot(mWidth, mHeight);
    const auto cones = coneVisibilitySlot(mWidth, mHeight);
    const auto indirect = indirectIrradianceSlot(mWidth, mHeight);
    const auto lit = litFrame();
    const Resource<const render::ShadowPass*> shadowMaps{
        "shadow_maps",
        ResourceType::gpuImage("r32f cube atlas", mOptions.shadowMapSize, mOptions.shadowMapSize)};
    // The frame's images are the graph's: created on first use, pooled between frames.
    gpu::Context& gpuContext = mStart.getGpu();
    const auto hdr =
        makeGpuImageResource(gpuContext, "lit_hdr", gpu::Format::RGBA32Float, mWidth, mHeight);
    const auto direct =
        makeGpuImageResource(gpuContext, "lit_direct", gpu::Format::RGBA32Float, mWidth, mHeight);
    const auto ldr =
        makeGpuImageResource(gpuContext, "lit_ldr", gpu::Format::RGBA8Unorm, mWidth, mHeight);

    // Slots that no family of the run fills.
    if (!graph.declares(kAmbientOcclusion))
        graph.addExternal(ao, false, "no occlusion technique in the run");
    if (!graph.declares(kConeVisibility))
        graph.addExternal(cones, false, "no occlusion technique in the run");
    if (!graph.declares(kIndirectIrradiance))
        graph.addExternal(indirect, false, "no voxel_gi technique in the run");
    const bool indirectFilled =
        graph.passes().end() !=
        std::find_if(graph.passes().begin(), graph.passes().end(), [](const PassDesc& p) {
            return std::any_of(p.writes.begin(), p.writes.end(),
                               [](const ResourceRef& w) { return w.name == kIndirectIrradiance; });
        });
    mStats.indirect =
        indirectFilled ? "indirect_irradiance" : "none (no voxel_gi technique in the run)";

    graph.addPass(
        {.name = "shadow_maps",
         .reads = {geometry},
         .writes = {shadowMaps},
         .needs = {scene::SceneFeature::PointLights},
         .persistent = {shadowMaps.name},
         .reuse =
             [this, geometry](const PassContext& ctx) {
                 const scene::RenderScene& g = ctx.read(geometry);
                 if (mShadowFrame < 0 || g.computeContentHash() != mShadowGeometryHash ||
                     g.pointLights.size() != mShadowLightPositions.size())
                     return std::string();
                 for (std::size_t i = 0; i < g.pointLights.size(); ++i)
                     if (g.pointLights[i].position != mShadowLightPositions[i])
                         return std::string();
                 mStats.lightsRendered = 0;
                 return "no light and no shadow caster moved since frame " +
                        std::to_string(mShadowFrame);
             }},
        [this, geometry, shadowMaps](PassContext& ctx) {
            const scene::RenderScene& g = ctx.read(geometry);
            if (!mShadows)
                mShadows = std::make_unique<render::ShadowPass>(
                    mStart.getGpu(), render::ShadowPassOptions{.faceSize = mOptions.shadowMapSize});
            const std::string hash = g.computeContentHash();
            std::vector<std::size_t> lights;
            const bool castersMoved =
                hash != mShadowGeometryHash || g.pointLights.size() != mShadowLightPositions.size();
            for (std::size_t i = 0; i < g.pointLights.size(); ++i)
                if (castersMoved || !ctx.mayReuse() ||
                    g.pointLights[i].position != mShadowLightPositions[i])
                    lights.push_back(i);
            mShadows->render(g, lights);
            mStats.lightsRendered = int(lights.size());
            mShadowGeometryHash = hash;
            mShadowLightPositions.clear();
            for (const auto& l : g.pointLights)
                mShadowLightPositions.push_back(l.position);
            mShadowFrame = ctx.frame();
            ctx.write(shadowMaps) = mShadows.get();
            return PassOutcome{};
        });

    graph.addPass(
        {.name = "lighting",
         .reads = {gbuffer, geometry},
         .optionalReads = {shadowMaps, ao, cones, indirect},
         .writes = {hdr, direct},
         .timing = PassTiming::Repeated},
        [this, gbuffer, geometry, shadowMaps, ao, cones, indirect, hdr, direct](PassContext& ctx) {
            gpu::Context& gpu = mStart.getGpu();
            if (!mLighting) {
                render::LightingPassOptions options;
                options.tonemap = {float(mOptions.exposureEv),
                                   render::parseTonemapper(mOptions.tonemapper)};
                mLighting = std::make_unique<render::LightingPass>(gpu, options);
            }
            const scene::RenderScene& g = ctx.read(geometry);
            const GpuGBuffer& gb = ctx.read(gbuffer);
            mStats.lights = int(g.pointLights.size());
            render::LightingInputs inputs;
            inputs.gbuffer = gb.target;
            inputs.camera = gb.camera;
            const auto* shadows = ctx.tryRead(shadowMaps);
            inputs.shadows = shadows ? *shadows : nullptr;
            // CPU outputs of the families go up here; once their techniques keep them
            // on the GPU these uploads disappear.
            gpu::Image aoImage, indirectImage;
            gpu::Buffer coneBuffer;
            const auto* coneImages = ctx.tryRead(cones);
            const auto* aoCpu = ctx.tryRead(ao);
            mStats.visibility = "none";
            if (coneImages && coneImages->size() == std::size_t(scene::kConeDirectionCount)) {
                const std::size_t pixels = std::size_t(mWidth) * std::size_t(mHeight);
                std::vector<float> packed(pixels * std::size_t(scene::kConeDirectionCount));
                for (std::size_t k = 0; k < coneImages->size(); ++k)
                    for (std::size_t i = 0; i < pixels; ++i)
                        packed[i * coneImages->size() + k] = (*coneImages)[k].pixels[i];
                coneBuffer = gpu.createBuffer({packed.size() * sizeof(float), "cone visibility"});
                coneBuffer.uploadSpan<float>(packed);
                inputs.coneVisibility = &coneBuffer;
                mStats.visibility = "cones";
            } else if (aoCpu) {
                aoImage = render::createImageFrom(gpu, *aoCpu, "ambient occlusion");
                inputs.ambientOcclusion = &aoImage;
                mStats.visibility = "ambient_occlusion";
            }
            if (const auto* e = ctx.tryRead(indirect)) {
                indirectImage = render::createImageFrom(gpu, *e, "indirect irradiance");
                inputs.indirectIrradiance = &indirectImage;
            }
            inputs.outHdr = &ctx.write(hdr);
            inputs.outDirect = &ctx.write(direct);
            mLighting->draw(g, inputs);
            return PassOutcome{};
        });
    graph.addPass({.name = "tonemap", .reads = {hdr}, .writes = {ldr}},
                  [this, hdr, ldr](PassContext& ctx) {
                      mLighting->tonemap(ctx.read(hdr),
                                         {float(mOptions.exposureEv),
                                          render::parseTonemapper(mOptions.tonemapper)},
                                         ctx.write(ldr));
                      return PassOutcome{};
                  });
    graph.addPass({.name = "frame_readback", .reads = {hdr, direct, ldr}, .writes = {lit}},
                  [hdr, direct, ldr, lit](PassContext& ctx) {
                      LitFrame& out = ctx.write(lit);
                      out.hdr = render::downloadRgb(ctx.read(hdr));
                      out.direct = render::downloadRgb(ctx.read(direct));
                      out.ldr = render::downloadRgb(ctx.read(ldr));
                      return PassOutcome{};
                  });
}

} // namespace rtlab::pipeline
