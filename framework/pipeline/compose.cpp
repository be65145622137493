#include "pipeline/compose.h"

#include "core/error.h"
#include "gpu/context.h"
#include "pipeline/gpu_resources.h"
#include "render/image_transfer.h"
#include "render/lighting_pass.h"
#include "render/shadow_pass.h"
#include "scene/sky.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <limits>
#include <utility>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace rtlab::pipeline {

namespace {

constexpr std::array<const char*, render::kCubeFaceCount> kFaceNames = {"+x", "-x", "+y",
                                                                        "-y", "+z", "-z"};
using Box = std::pair<glm::vec3, glm::vec3>;

// The box a capsule's triangles lie in (scene.cpp appendCapsule: points on the capsule's
// surface), grown by a little for the rounding of centre + radius * unit normal.
Box getCapsuleBox(const scene::Capsule& c)
{
    const float r = c.radius * (1.0f + 1e-5f) + 1e-6f;
    return {glm::min(c.a, c.b) - r, glm::max(c.a, c.b) + r};
}

bool isSameCapsule(const scene::Capsule& x, const scene::Capsule& y)
{
    return std::memcmp(&x, &y, sizeof(scene::Capsule)) == 0;
}

// Where the triangles may differ between the shadow maps' last rendering and this frame, from
// what the scene says moved rather than from the triangles (nothing per triangle on the host):
//  * each character capsule whose pose changed: its old and its new box;
//  * the SDF triangles the digs re-meshed since `lastFrame` (FrameStart::findSdfChangeSince:
//    the box of the triangles a re-mesh removed or added).
// `bounded` is false when the geometry changed and neither explains it (a capsule more or
// fewer, a full re-mesh, or nothing moved at all): then every face is redrawn.
struct MovedBounds {
    std::vector<Box> boxes;
    bool bounded = true;
};

MovedBounds findMovedBounds(const FrameStart& start, const std::vector<scene::Capsule>& before,
                            const std::vector<scene::Capsule>& now, int lastFrame)
{
    MovedBounds moved;
    if (before.size() != now.size()) {
        moved.bounded = false;
        return moved;
    }
    for (std::size_t i = 0; i < now.size(); ++i)
        if (!isSameCapsule(before[i], now[i])) {
            moved.boxes.push_back(getCapsuleBox(before[i]));
            moved.boxes.push_back(getCapsuleBox(now[i]));
        }
    if (!start.getScene().sdfModels.empty()) {
        glm::dvec3 lo, hi;
        if (!start.findSdfChangeSince(lastFrame, lo, hi)) {
            moved.bounded = false;
            return moved;
        }
        // Outward to float: the triangles' corners are floats inside the box.
        if (lo.x <= hi.x)
            moved.boxes.push_back({glm::vec3(lo) - glm::abs(glm::vec3(lo)) * 1e-6f - 1e-6f,
                                   glm::vec3(hi) + glm::abs(glm::vec3(hi)) * 1e-6f + 1e-6f});
    }
    moved.bounded = !moved.boxes.empty();
    return moved;
}

std::string describeFaces(std::uint8_t mask)
{
    std::string s;
    for (int f = 0; f < render::kCubeFaceCount; ++f)
        if (mask & (1u << f))
            s += (s.empty() ? "" : ",") + std::string(kFaceNames[std::size_t(f)]);
    return s;
}

} // namespace

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

void Compose::addSlotUploads(FrameGraph& graph)
{
    gpu::Context& gpuContext = mStart.getGpu();
    const auto ao = ambientOcclusionSlot(mWidth, mHeight);
    const auto cones = coneVisibilitySlot(mWidth, mHeight);
    const auto indirect = indirectIrradianceSlot(mWidth, mHeight);
    const auto aoGpu = ambientOcclusionGpuSlot(mWidth, mHeight);
    const auto conesGpu = coneVisibilityGpuSlot(mWidth, mHeight);
    const auto indirectGpu = indirectIrradianceGpuSlot(mWidth, mHeight);

    // Occlusion: AO or cone visibilities from the CPU slots, unless the family wrote the GPU ones.
    const bool occlusionOnGpu =
        graph.declares(kAmbientOcclusionGpu) || graph.declares(kConeVisibilityGpu);
    const bool hasAo = graph.declares(kAmbientOcclusion);
    const bool hasCones = graph.declares(kConeVisibility);
    if (!occlusionOnGpu && (hasAo || hasCones)) {
        // Kept across frames (persistent): the slots point into them.
        const auto aoImage = makeGpuImageResource(gpuContext, "occlusion.ambient_upload",
                                                  gpu::Format::R32Float, mWidth, mHeight);
        std::array<Resource<gpu::Image>, 4> coneImages;
        std::vector<ResourceRef> writes = {aoGpu, conesGpu, aoImage};
        std::vector<std::string> kept = {aoImage.name};
        for (std::size_t g = 0; g < 4; ++g) {
            coneImages[g] = makeGpuImageResource(
                gpuContext, "occlusion.cone_visibility_upload" + std::to_string(g),
                gpu::Format::RGBA32Float, mWidth, mHeight);
            writes.push_back(coneImages[g]);
            kept.push_back(coneImages[g].name);
        }
        std::vector<ResourceRef> reads;
        if (hasAo)
            reads.push_back(ao);
        if (hasCones)
            reads.push_back(cones);
        graph.addPass({.name = "occlusion_upload",
                       .reads = reads,
                       .writes = writes,
                       .persistent = kept},
                      [ao, cones, hasAo, hasCones, aoGpu, conesGpu, aoImage,
                       coneImages](PassContext& ctx) {
                          std::array<const gpu::Image*, 4> coneSlot{};
                          const gpu::Image* aoSlot = nullptr;
                          if (hasCones && ctx.read(cones).size() ==
                                              std::size_t(scene::kConeDirectionCount)) {
                              std::array<gpu::Image*, 4> targets{};
                              for (std::size_t g = 0; g < 4; ++g)
                                  targets[g] = &ctx.write(coneImages[g]);
                              render::uploadConeVisibility(targets, ctx.read(cones));
                              std::copy(targets.begin(), targets.end(), coneSlot.begin());
                          } else if (hasAo) {
                              gpu::Image& image = ctx.write(aoImage);
                              render::uploadInto(image, ctx.read(ao));
                              aoSlot = &image;
                          }
                          ctx.write(aoGpu) = aoSlot;
                          ctx.write(conesGpu) = coneSlot;
                          return PassOutcome{};
                      });
    } else if (!occlusionOnGpu) {
        graph.addExternal(aoGpu, false, "no occlusion technique in the run");
        graph.addExternal(conesGpu, false, "no occlusion technique in the run");
    } else {
        if (!graph.declares(kAmbientOcclusionGpu))
            graph.addExternal(aoGpu, false, "the occlusion technique gives cone visibilities");
        if (!graph.declares(kConeVisibilityGpu))
            graph.addExternal(conesGpu, false, "the occlusion technique gives no cones");
    }

    // The voxel GI family's images: indirect irradiance, and the sky through its cones (an empty
    // CPU image when the technique gave none this frame: the GPU slot is then null).
    const auto addUpload = [&](const Resource<Image<glm::vec3>>& cpu,
                               const Resource<const gpu::Image*>& gpuSlot, const char* pass,
                               const char* imageName) {
        if (graph.declares(gpuSlot.name))
            return;
        if (!graph.declares(cpu.name)) {
            graph.addExternal(gpuSlot, false, "no voxel_gi technique in the run");
            return;
        }
        const auto image = makeGpuImageResource(gpuContext, imageName,
                                                gpu::Format::RGBA32Float, mWidth, mHeight);
        graph.addPass({.name = pass,
                       .reads = {cpu},
                       .writes = {gpuSlot, image},
                       .persistent = {image.name}},
                      [cpu, gpuSlot, image](PassContext& ctx) {
                          const Image<glm::vec3>& data = ctx.read(cpu);
                          const gpu::Image* slot = nullptr;
                          if (data.width > 0) {
                              gpu::Image& target = ctx.write(image);
                              render::uploadInto(target, data);
                              slot = &target;
                          }
                          ctx.write(gpuSlot) = slot;
                          return PassOutcome{};
                      });
    };
    addUpload(indirect, indirectGpu, "indirect_upload", "indirect_irradiance_upload");
    addUpload(coneSkySlot(mWidth, mHeight), coneSkyGpuSlot(mWidth, mHeight), "cone_sky_upload",
              "cone_sky_upload_image");
    // CPU slots nobody fills (CPU readers read them optionally).
    if (!graph.declares(kAmbientOcclusion))
        graph.addExternal(ao, false, "no occlusion technique in the run");
    if (!graph.declares(kConeVisibility))
        graph.addExternal(cones, false, "no occlusion technique in the run");
    if (!graph.declares(kIndirectIrradiance))
        graph.addExternal(indirect, false, "no voxel_gi technique in the run");
    if (!graph.declares(kConeSky))
        graph.addExternal(coneSkySlot(mWidth, mHeight), false, "no voxel_gi technique in the run");
}

void Compose::addPasses(FrameGraph& graph)
{
    const auto geometry = mStart.geometry();
    const auto geometryKey = mStart.geometryKey();
    const auto gbuffer = mStart.gbuffer();
    const auto lit = litFrame();
    const Resource<const render::ShadowPass*> shadowMaps{
        "shadow_maps",
        ResourceType::gpuImage("r32f cube atlas", mOptions.shadowMapSize, mOptions.shadowMapSize)};
    // The frame's images are the graph's: created on first use, pooled between frames.
    gpu::Context& gpuContext = mStart.getGpu();
    // The shadow atlas too, kept across frames (faces nothing changed keep their maps): six
    // faces per point light of the scene (their number is the scene's in every frame).
    const std::size_t lightCount = std::max<std::size_t>(mStart.getScene().pointLights.size(), 1);
    const int faceSize = mOptions.shadowMapSize;
    gpu::Context* atlasContext = &gpuContext;
    const Resource<gpu::Image> atlas{
        "shadow_atlas",
        ResourceType::gpuImage("r32f cube faces, 6 x " + std::to_string(lightCount) + " slices",
                               faceSize, faceSize),
        [atlasContext, faceSize, lightCount] {
            return std::make_shared<gpu::Image>(atlasContext->createImage(
                render::ShadowPass::makeAtlasDesc(faceSize, lightCount)));
        }};
    const auto hdr =
        makeGpuImageResource(gpuContext, "lit_hdr", gpu::Format::RGBA32Float, mWidth, mHeight);
    const auto direct =
        makeGpuImageResource(gpuContext, "lit_direct", gpu::Format::RGBA32Float, mWidth, mHeight);
    const auto ldr =
        makeGpuImageResource(gpuContext, "lit_ldr", gpu::Format::RGBA8Unorm, mWidth, mHeight);

    const bool indirectFilled =
        graph.passes().end() !=
        std::find_if(graph.passes().begin(), graph.passes().end(), [](const PassDesc& p) {
            return std::any_of(p.writes.begin(), p.writes.end(), [](const ResourceRef& w) {
                return w.name == kIndirectIrradiance || w.name == kIndirectIrradianceGpu;
            });
        });
    mStats.indirect =
        indirectFilled ? "indirect_irradiance" : "none (no voxel_gi technique in the run)";
    addSlotUploads(graph);
    const auto aoGpu = ambientOcclusionGpuSlot(mWidth, mHeight);
    const auto conesGpu = coneVisibilityGpuSlot(mWidth, mHeight);
    const auto indirectGpu = indirectIrradianceGpuSlot(mWidth, mHeight);
    const auto coneSkyGpu = coneSkyGpuSlot(mWidth, mHeight);

    const auto capsulesRes = mStart.capsules();
    graph.addPass(
        {.name = "shadow_maps",
         .reads = {geometry, geometryKey},
         .optionalReads = {capsulesRes},
         .writes = {shadowMaps, atlas},
         .needs = {scene::SceneFeature::PointLights},
         .persistent = {shadowMaps.name, atlas.name},
         .reuse =
             [this, geometry, geometryKey](const PassContext& ctx) {
                 const scene::RenderScene& g = ctx.read(geometry);
                 if (mShadowFrame < 0 || ctx.read(geometryKey) != mShadowGeometryHash ||
                     g.pointLights.size() != mShadowLightPositions.size())
                     return std::string();
                 for (std::size_t i = 0; i < g.pointLights.size(); ++i)
                     if (g.pointLights[i].position != mShadowLightPositions[i])
                         return std::string();
                 const std::string why = "no light and no shadow caster moved since frame " +
                                         std::to_string(mShadowFrame);
                 mStats.lightsRendered = 0;
                 mStats.shadowFacesRendered = 0;
                 mStats.shadowSkips = "every light: " + why;
                 return why;
             }},
        [this, geometry, geometryKey, capsulesRes, shadowMaps, atlas](PassContext& ctx) {
            const scene::RenderScene& g = ctx.read(geometry);
            if (!mShadows) {
                mShadows = std::make_unique<render::ShadowPass>(
                    mStart.getGpu(), render::ShadowPassOptions{.faceSize = mOptions.shadowMapSize});
                mShadows->useAtlas(ctx.write(atlas));
            }
            const std::size_t lightCount = g.pointLights.size();
            // The assembled geometry's bounds (kept as its vertices: RenderScene::updateBounds,
            // extended over the characters), what the shadow planes follow.
            const glm::vec3 boundsMin = g.positions.empty() ? glm::vec3(0.0f) : g.boundsMin;
            const glm::vec3 boundsMax = g.positions.empty() ? glm::vec3(0.0f) : g.boundsMax;
            std::vector<scene::Capsule> capsules;
            if (const auto* posed = ctx.tryRead(capsulesRes))
                for (const auto& c : *posed)
                    capsules.push_back(c.capsule);
            // Every face of every light is drawn when the kept maps may not be what a full
            // rendering gives: the near and far planes follow the bounds.
            if (!ctx.mayReuse())
                mShadows->forgetGeometry(); // without culling nothing is patched
            bool drawAll = !ctx.mayReuse() || mShadowFrame < 0 ||
                           lightCount != mShadowLightPositions.size() ||
                           boundsMin != mShadowBoundsMin || boundsMax != mShadowBoundsMax;
            MovedBounds changed;
            if (!drawAll && ctx.read(geometryKey) != mShadowGeometryHash) {
                changed = findMovedBounds(mStart, mShadowCapsules, capsules, mShadowFrame);
                drawAll = !changed.bounded;
            }
            std::vector<std::uint8_t> masks(lightCount, 0);
            std::vector<std::string> skips;
            for (std::size_t i = 0; i < lightCount; ++i) {
                const glm::vec3 p = g.pointLights[i].position;
                if (drawAll || p != mShadowLightPositions[i]) {
                    masks[i] = render::kAllCubeFaces;
                    continue;
                }
                for (const auto& [lo, hi] : changed.boxes) {
                    masks[i] |= render::computeCubeFacesTouching(p, lo, hi);
                    if (masks[i] == render::kAllCubeFaces)
                        break;
                }
                // The six pyramids cover space, so a light keeps every face only when nothing
                // moved (the geometry's hash is that of the last rendering).
                if (masks[i] == 0)
                    skips.push_back("light " + std::to_string(i) +
                                    ": no caster moved, the light did not move");
                else if (masks[i] != render::kAllCubeFaces)
                    skips.push_back("light " + std::to_string(i) + " faces " +
                                    describeFaces(std::uint8_t(render::kAllCubeFaces & ~masks[i])) +
                                    ": no caster moved in their view");
            }
            std::string joined;
            for (const std::string& skip : skips)
                joined += (joined.empty() ? "" : "; ") + skip;
            mStats.shadowSkips = joined;
            mStats.lightsRendered = 0;
            mStats.shadowFacesRendered = 0;
            const bool nothingToDraw =
                std::all_of(masks.begin(), masks.end(), [](std::uint8_t m) { return m == 0; });
            const int lastFrame = mShadowFrame;
            if (!nothingToDraw)
                mShadows->renderFaces(g, masks);
            // Remembered once the maps hold it (a failed rendering keeps the last state).
            mShadowGeometryHash = ctx.read(geometryKey);
            mShadowLightPositions.clear();
            for (const auto& l : g.pointLights)
                mShadowLightPositions.push_back(l.position);
            mShadowCapsules = std::move(capsules);
            mShadowBoundsMin = boundsMin;
            mShadowBoundsMax = boundsMax;
            mShadowFrame = ctx.frame();
            ctx.write(shadowMaps) = mShadows.get();
            if (nothingToDraw)
                return PassOutcome::skipped("no shadow caster and no light moved since frame " +
                                            std::to_string(lastFrame));
            for (std::size_t i = 0; i < lightCount; ++i) {
                const int faces = std::popcount(mShadows->getLightState(i).lastFaceMask);
                mStats.lightsRendered += faces > 0 ? 1 : 0;
                mStats.shadowFacesRendered += faces;
            }
            return PassOutcome{};
        });

    graph.addPass(
        {.name = "lighting",
         .reads = {gbuffer, geometry},
         .optionalReads = mOptions.coneSky
                              ? std::vector<ResourceRef>{shadowMaps, aoGpu, conesGpu, indirectGpu,
                                                         coneSkyGpu}
                              : std::vector<ResourceRef>{shadowMaps, aoGpu, conesGpu, indirectGpu},
         .writes = {hdr, direct},
         .timing = PassTiming::Repeated},
        [this, gbuffer, geometry, shadowMaps, aoGpu, conesGpu, indirectGpu, coneSkyGpu, hdr,
         direct](PassContext& ctx) {
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
            // The families' results, on the GPU already (slots filled on the CPU were uploaded
            // by their own pass, see addSlotUploads).
            mStats.visibility = "none";
            const auto* coneImages = ctx.tryRead(conesGpu);
            const auto* aoImage = ctx.tryRead(aoGpu);
            if (coneImages && (*coneImages)[0] != nullptr) {
                inputs.coneVisibility = *coneImages;
                mStats.visibility = "cones";
            } else if (aoImage && *aoImage != nullptr) {
                inputs.ambientOcclusion = *aoImage;
                mStats.visibility = "ambient_occlusion";
            }
            if (const auto* e = ctx.tryRead(indirectGpu))
                inputs.indirectIrradiance = *e;
            mStats.sky = "lobes";
            if (const auto* c = mOptions.coneSky ? ctx.tryRead(coneSkyGpu) : nullptr;
                c && *c != nullptr) {
                inputs.coneSkyIrradiance = *c;
                mStats.sky = "cones";
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
    graph.addPass({.name = "frame_readback",
                   .reads = {hdr, direct, ldr},
                   .writes = {lit},
                   .forReaders = true},
                  [hdr, direct, ldr, lit](PassContext& ctx) {
                      LitFrame& out = ctx.write(lit);
                      out.hdr = render::downloadRgb(ctx.read(hdr));
                      out.direct = render::downloadRgb(ctx.read(direct));
                      out.directSky = render::downloadScalar(ctx.read(direct), 3);
                      out.ldr = render::downloadRgb(ctx.read(ldr));
                      return PassOutcome{};
                  });
}

} // namespace rtlab::pipeline
