#include "families/voxel_gi/cone_sky_split.h"

#include "metrics/image_metrics.h"

#include <cmath>

namespace rtlab::voxelgi {

void addConeSkySplit(pipeline::FrameGraph& graph, const ConeSkySplitResources& resources,
                     const ConeSkySplitSettings& settings)
{
    const int w = settings.width, h = settings.height;
    const auto geometry = resources.geometry;
    const auto gbuffer = resources.gbuffer;
    const auto view = resources.view;
    const auto voxelLight = resources.voxelLight;
    const auto coneSky = resources.coneSky;
    experiment::ResultRow* const* const row = settings.row;
    plugin::VoxelGiTechnique* const technique = settings.technique;
    const pipeline::Resource<reference::ReferenceResult> skyTruth{
        "ground_truth_cone_sky", pipeline::ResourceType::cpuImage("reference direct, no point lights", w, h)};
    graph.addPass({.name = "reference_cone_sky",
                   .reads = {geometry, gbuffer},
                   .writes = {skyTruth},
                   .measurement = true},
                  [settings, row, geometry, gbuffer, skyTruth](pipeline::PassContext& ctx) {
                      scene::RenderScene g = ctx.read(geometry);
                      g.pointLights.clear();
                      reference::ReferenceSettings direct = settings.reference;
                      direct.quantity = reference::Quantity::Direct;
                      reference::ReferenceResult& t = ctx.write(skyTruth);
                      t = reference::computeReference(g, ctx.read(gbuffer), direct);
                      (*row)->set("reference_cone_sky.seconds", t.stats.seconds)
                          .set("reference_cone_sky.from_cache", t.stats.fromCache);
                      return pipeline::PassOutcome{};
                  });
    const pipeline::Resource<Image<glm::vec3>> skyRays{
        "voxel_sky_rays", pipeline::ResourceType::cpuImage("vec3", w, h)};
    graph.addPass({.name = "voxel_sky_rays",
                   .reads = {voxelLight, gbuffer, geometry},
                   .writes = {skyRays},
                   .measurement = true},
                  [settings, technique, gbuffer, geometry, skyRays](pipeline::PassContext& ctx) {
                      plugin::VoxelGiInput input;
                      input.gbuffer = &ctx.read(gbuffer);
                      input.frameIndex = ctx.frame();
                      input.coneSky = true;
                      Image<glm::vec3>& out = ctx.write(skyRays);
                      if (!technique->traceVoxelSkyRays(input, settings.raysPerPixel, ctx.read(geometry).sky, out)) {
                          out = Image<glm::vec3>();
                          return pipeline::PassOutcome::skipped(
                              "technique '" + settings.techniqueName + "' traces no voxel sky rays");
                      }
                      return pipeline::PassOutcome{};
                  });
    graph.addPass({.name = "metric.sky_split",
                   .reads = {coneSky, skyRays, skyTruth, view},
                   .writes = {"metric.sky_split"},
                   .measurement = true},
                  [row, coneSky, skyRays, skyTruth, view](pipeline::PassContext& ctx) {
                      const Image<glm::vec3>& cones = ctx.read(coneSky);
                      const Image<glm::vec3>& rays = ctx.read(skyRays);
                      const Image<glm::vec3>& truth = ctx.read(skyTruth).irradiance;
                      const auto& surface = ctx.read(view).surface;
                      metrics::ImageErrorOptions o;
                      o.range = metrics::DynamicRange::Hdr;
                      o.withSsim = false;
                      o.withFlip = false;
                      const auto sized = [&](const Image<glm::vec3>& i) {
                          return i.width == truth.width && i.height == truth.height;
                      };
                      const double nan = std::nan("");
                      const auto put = [&](const std::string& name, const Image<glm::vec3>& a,
                                           const Image<glm::vec3>& b) {
                          const bool have = sized(a) && sized(b);
                          const auto e = have ? metrics::computeImageErrors(a, b, o, surface)
                                              : metrics::ImageErrors{};
                          (*row)->set(name + "rmse", have ? e.rmse : nan)
                              .set(name + "mean_signed_error", have ? e.meanSignedError : nan);
                      };
                      put("sky.", cones, truth);
                      put("split.sky_cone_", cones, rays);
                      put("split.sky_voxel_", rays, truth);
                      return pipeline::PassOutcome{};
                  });
}

} // namespace rtlab::voxelgi
