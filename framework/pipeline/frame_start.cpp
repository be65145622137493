#include "pipeline/frame_start.h"

#include "core/hash.h"
#include "gpu/context.h"
#include "pipeline/gpu_resources.h"
#include "render/frame_matrices.h"
#include "render/gbuffer_pass.h"
#include "render/view_inputs_pass.h"

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

namespace rtlab::pipeline {

namespace {

std::string makeDrawKey(const std::string& geometryHash, const scene::Camera& c, int width,
                        int height)
{
    Hasher h;
    h.addBytes(geometryHash.data(), geometryHash.size())
        .addValue(c.position)
        .addValue(c.target)
        .addValue(c.up)
        .addValue(c.verticalFovDegrees)
        .addValue(c.nearPlane)
        .addValue(c.farPlane)
        .addValue(width)
        .addValue(height);
    return h.hexDigest();
}

} // namespace

FrameStart::FrameStart(const scene::Scene& scene, gpu::Context& gpu, FrameStartOptions options)
    : mScene(scene), mFeatures(scene.computeFeatures()), mGpu(gpu), mOptions(options)
{
}

FrameStart::~FrameStart() = default;

Resource<gpu::Image> FrameStart::viewDepthGpu() const
{
    return makeGpuImageResource(mGpu, "view_depth_gpu", gpu::Format::R32Float, mOptions.width,
                                mOptions.height);
}

Resource<gpu::Image> FrameStart::viewNormalGpu() const
{
    return makeGpuImageResource(mGpu, "view_normal_gpu", gpu::Format::RGBA32Float, mOptions.width,
                                mOptions.height);
}

Resource<gpu::Image> FrameStart::positionDepthGpu() const
{
    return makeGpuImageResource(mGpu, "gbuffer_position_depth_gpu", gpu::Format::RGBA32Float,
                                mOptions.width, mOptions.height);
}

Resource<gpu::Image> FrameStart::worldNormalGpu() const
{
    return makeGpuImageResource(mGpu, "gbuffer_normal_gpu", gpu::Format::RGBA32Float,
                                mOptions.width, mOptions.height);
}

Resource<gpu::RenderTarget> FrameStart::gbufferTarget() const
{
    gpu::Context* ctx = &mGpu;
    const int w = mOptions.width, h = mOptions.height;
    return {"gbuffer_target",
            ResourceType::gpuImage("render target: 4 x rgba32f + r32ui + d32", w, h),
            [ctx, w, h] {
                return std::make_shared<gpu::RenderTarget>(
                    ctx->createRenderTarget(render::GBufferPass::makeTargetDesc(w, h)));
            }};
}

bool FrameStart::findSdfChangeSince(int since, glm::dvec3& lo, glm::dvec3& hi) const
{
    lo = glm::dvec3(1e300);
    hi = glm::dvec3(-1e300);
    if (mSdfChanges.empty() || since < mSdfChanges.front().frame)
        return false; // before the first meshing
    for (const SdfChange& c : mSdfChanges) {
        if (c.frame <= since)
            continue;
        if (!c.bounded)
            return false;
        lo = glm::min(lo, c.lo);
        hi = glm::max(hi, c.hi);
    }
    return true;
}

void FrameStart::addPasses(FrameGraph& graph)
{
    const auto sceneRes =
        graph.addExternal<scene::Scene>(kScene, ResourceType::value("scene"), &mScene);
    const auto sdfMeshes = this->sdfMeshes();
    const auto capsules = this->capsules();
    const auto geometryRes = geometry();
    const auto geometryKeyRes = geometryKey();
    const Resource<GpuScene> gpuScene{"gpu_scene", ResourceType::value("uploaded scene")};
    const auto gbufferRes = gbuffer();
    const auto gbufferCpuRes = gbufferCpu();
    const auto viewRes = viewInputs();

    graph.addPass({.name = "sdf_remesh",
                   .reads = {sceneRes},
                   .writes = {sdfMeshes},
                   .needs = {scene::SceneFeature::SdfModels},
                   .persistent = {sdfMeshes.name},
                   .reuse =
                       [this](const PassContext& ctx) {
                           if (mMeshedFrame >= 0 &&
                               mScene.getEditStateKey(ctx.frame()) == mMeshedEditKey)
                               return "no edit starts after frame " + std::to_string(mMeshedFrame) +
                                      ": its SDF meshes are reused";
                           return std::string();
                       }},
                  [this, sdfMeshes](PassContext& ctx) {
                      // A dig re-meshes only what it touched (scene/sdf_mesher.h); without
                      // culling every model is meshed in full, as before the meshers kept
                      // their grids (the ablation).
                      if (mMeshers.empty())
                          for (const scene::SdfModel& model : mScene.sdfModels)
                              mMeshers.emplace_back(model, scene::SdfMeshOptions{.resolution = model.resolution});
                      auto& meshes = ctx.write(sdfMeshes);
                      meshes.resize(mMeshers.size());
                      mStats = FrameStartStats{.remeshFrame = ctx.frame()};
                      SdfChange logged{.frame = ctx.frame(), .bounded = true};
                      for (std::size_t k = 0; k < mMeshers.size(); ++k) {
                          const scene::SdfMeshChange change =
                              mMeshers[k].update(ctx.frame(), !ctx.mayReuse());
                          if (change.changed || meshes[k].mesh.positions.empty())
                              meshes[k] = mMeshers[k].getMesh();
                          logged.bounded = logged.bounded && !change.full;
                          logged.lo = glm::min(logged.lo, change.changedMin);
                          logged.hi = glm::max(logged.hi, change.changedMax);
                          mStats.remesh += (mStats.remesh.empty() ? "" : "; ") +
                                           mScene.sdfModels[k].name + ": " + change.what;
                          mStats.cellsMeshed += std::int64_t(change.cellsMeshed);
                          mStats.cells += std::int64_t(change.cellCount);
                      }
                      if (!logged.bounded || logged.lo.x <= logged.hi.x)
                          mSdfChanges.push_back(logged);
                      mMeshedEditKey = mScene.getEditStateKey(ctx.frame());
                      mMeshedFrame = ctx.frame();
                      ++mSdfMeshVersion;
                      return PassOutcome{};
                  });
    graph.addPass({.name = "character_pose",
                   .reads = {sceneRes},
                   .writes = {capsules},
                   .needs = {scene::SceneFeature::Characters}},
                  [this, capsules](PassContext& ctx) {
                      ctx.write(capsules) = mScene.poseCharacters(ctx.frame());
                      return PassOutcome{};
                  });
    graph.addPass({.name = "assemble_geometry",
                   .reads = {sceneRes},
                   .optionalReads = {sdfMeshes, capsules},
                   .writes = {geometryRes, geometryKeyRes},
                   .persistent = {geometryRes.name}},
                  [this, sdfMeshes, capsules, geometryRes, geometryKeyRes](PassContext& ctx) {
                      static const std::vector<scene::SdfMesh> kNoMeshes;
                      static const std::vector<scene::PosedCapsule> kNoCapsules;
                      const auto* meshes = ctx.tryRead(sdfMeshes);
                      const auto* posed = ctx.tryRead(capsules);
                      // The static part (meshes and SDF meshes) and its content hash are kept
                      // until sdf_remesh gives new meshes; a frame where only the characters
                      // moved copies it and appends their capsules (culling off: assembled and
                      // hashed anew, the ablation). The key hashes the static part's hash with
                      // the capsules, from which their triangles follow: it changes exactly when
                      // the geometry does.
                      if (!ctx.mayReuse() || mStaticVersion != mSdfMeshVersion || mStaticKey.empty()) {
                          mStaticGeometry = mScene.assembleStaticGeometry(meshes ? *meshes : kNoMeshes);
                          mStaticKey = mStaticGeometry.computeContentHash();
                          mStaticVersion = mSdfMeshVersion;
                      }
                      // The last frame's geometry (kept across frames) when its static part is
                      // this one: its characters cut off, back to the static part, without
                      // copying the static part again.
                      scene::RenderScene& g = ctx.write(geometryRes);
                      const scene::RenderScene& st = mStaticGeometry;
                      if (ctx.mayReuse() && g.staticKey == mStaticKey && g.positions.size() >= st.positions.size() &&
                          g.indices.size() >= st.indices.size() && g.materials.size() == st.materials.size()) {
                          g.positions.resize(st.positions.size());
                          g.normals.resize(st.normals.size());
                          g.indices.resize(st.indices.size());
                          g.triangleMaterial.resize(st.triangleMaterial.size());
                          g.capsules.clear();
                          g.boundsMin = st.boundsMin;
                          g.boundsMax = st.boundsMax;
                      } else {
                          g = st;
                          g.staticKey = mStaticKey;
                      }
                      const auto& characters = posed ? *posed : kNoCapsules;
                      mScene.appendCharacters(g, characters);
                      if (g.indices.empty())
                          throw Error("scene '" + mScene.name + "' has no triangles at frame " +
                                      std::to_string(ctx.frame()) +
                                      "; a scene needs at least one mesh, SDF model or character");
                      Hasher key;
                      key.add("assembled geometry v1").add(mStaticKey).addValue(characters.size());
                      for (const scene::PosedCapsule& c : characters)
                          key.addValue(c.capsule.a).addValue(c.capsule.b).addValue(c.capsule.radius).addValue(
                              c.material);
                      ctx.write(geometryKeyRes) = key.hexDigest();
                      return PassOutcome{};
                  });
    graph.addPass({.name = "scene_upload",
                   .reads = {geometryRes, geometryKeyRes},
                   .writes = {gpuScene},
                   .persistent = {gpuScene.name},
                   .reuse =
                       [this, geometryKeyRes](const PassContext& ctx) {
                           if (!mGBufferPass || !mGBufferPass->hasScene())
                               return std::string();
                           const std::string& hash = ctx.read(geometryKeyRes);
                           // The upload pass's own record of what it uploaded.
                           return hash == mUploadedHash ? "geometry unchanged since frame " +
                                                              std::to_string(mUploadedFrame)
                                                        : std::string();
                       }},
                  [this, geometryRes, geometryKeyRes, gpuScene](PassContext& ctx) {
                      if (!mGBufferPass)
                          mGBufferPass = std::make_unique<render::GBufferPass>(mGpu);
                      const scene::RenderScene& g = ctx.read(geometryRes);
                      // Without culling nothing is patched: everything is uploaded again.
                      mGBufferPass->setScene(g, ctx.mayReuse());
                      mUploadedHash = ctx.read(geometryKeyRes);
                      mUploadedFrame = ctx.frame();
                      ctx.write(gpuScene) = GpuScene{mUploadedHash, ctx.frame()};
                      return PassOutcome{};
                  });
    const auto targetRes = gbufferTarget();
    graph.addPass({.name = "gbuffer",
                   .reads = {gpuScene},
                   .writes = {gbufferRes, targetRes},
                   .timing = PassTiming::Repeated,
                   .persistent = {gbufferRes.name, targetRes.name},
                   .reuse =
                       [this, gpuScene](const PassContext& ctx) {
                           const std::string key =
                               makeDrawKey(ctx.read(gpuScene).hash, mScene.getCameraAt(ctx.frame()),
                                           mOptions.width, mOptions.height);
                           return mDrawnFrame >= 0 && key == mDrawnKey
                                      ? "camera, geometry and size unchanged since frame " +
                                            std::to_string(mDrawnFrame) + ": its G-buffer is reused"
                                      : std::string();
                       }},
                  [this, gpuScene, gbufferRes, targetRes](PassContext& ctx) {
                      const scene::Camera camera = mScene.getCameraAt(ctx.frame());
                      const gpu::RenderTarget& target = ctx.write(targetRes);
                      mGBufferPass->draw(target, camera);
                      GpuGBuffer& out = ctx.write(gbufferRes);
                      out.target = &target;
                      out.width = mOptions.width;
                      out.height = mOptions.height;
                      out.camera = camera;
                      // The matrices the rasteriser used (render/frame_matrices.h), as the
                      // read-back has them.
                      const render::FrameMatrices m = render::computeFrameMatrices(
                          camera, mOptions.width, mOptions.height, glm::vec2(0.0f));
                      out.view = m.view;
                      out.projection = m.projection;
                      mDrawnKey = makeDrawKey(ctx.read(gpuScene).hash, camera, mOptions.width,
                                              mOptions.height);
                      mDrawnFrame = ctx.frame();
                      return PassOutcome{};
                  });
    graph.addPass({.name = "gbuffer_readback",
                   .reads = {gbufferRes},
                   .writes = {gbufferCpuRes},
                   .persistent = {gbufferCpuRes.name},
                   .reuse =
                       [this](const PassContext&) {
                           return mReadFrame >= 0 && mReadKey == mDrawnKey
                                      ? "the G-buffer is unchanged since frame " +
                                            std::to_string(mReadFrame) + ": its CPU copy is reused"
                                      : std::string();
                       },
                   .forReaders = true},
                  [this, gbufferCpuRes](PassContext& ctx) {
                      ctx.write(gbufferCpuRes) = mGBufferPass->readBack();
                      mReadKey = mDrawnKey;
                      mReadFrame = ctx.frame();
                      return PassOutcome{};
                  });
    graph.addPass({.name = "view_inputs",
                   .reads = {gbufferCpuRes},
                   .writes = {viewRes},
                   .forReaders = true},
                  [gbufferCpuRes, viewRes](PassContext& ctx) {
                      const scene::GBuffer& g = ctx.read(gbufferCpuRes);
                      ViewInputs& v = ctx.write(viewRes);
                      const glm::mat3 toView(g.view);
                      v.normal = Image<glm::vec3>(g.width, g.height, glm::vec3(0.0f));
                      v.surface = Image<std::uint8_t>(g.width, g.height, 0);
                      for (std::size_t i = 0; i < v.normal.pixels.size(); ++i)
                          if (g.materialId.pixels[i] != scene::kNoMaterial) {
                              v.normal.pixels[i] = glm::normalize(toView * g.normal.pixels[i]);
                              v.surface.pixels[i] = 1;
                          }
                      return PassOutcome{};
                  });
    const auto viewGpuRes = viewInputsGpu();
    const auto depthGpu = viewDepthGpu();
    const auto normalGpu = viewNormalGpu();
    const auto positionGpu = positionDepthGpu();
    const auto worldGpu = worldNormalGpu();
    graph.addPass({.name = "view_inputs_gpu",
                   .reads = {gbufferRes},
                   .writes = {viewGpuRes, depthGpu, normalGpu, positionGpu, worldGpu}},
                  [this, gbufferRes, viewGpuRes, depthGpu, normalGpu, positionGpu,
                   worldGpu](PassContext& ctx) {
                      const GpuGBuffer& g = ctx.read(gbufferRes);
                      if (!mViewInputsPass)
                          mViewInputsPass = std::make_unique<render::ViewInputsPass>(mGpu);
                      mViewInputsPass->run(*g.target, g.view, ctx.write(positionGpu),
                                           ctx.write(worldGpu), ctx.write(depthGpu),
                                           ctx.write(normalGpu));
                      ctx.write(viewGpuRes) = GpuViewInputs{g.view, g.projection};
                      return PassOutcome{};
                  });
}

} // namespace rtlab::pipeline
