#include "families/voxel_gi/resident_gather.h"

#include "core/error.h"
#include "gpu/format.h"
#include "gpu/resources.h"
#include "pipeline/compose.h"

namespace rtlab::voxelgi {

void addResidentGather(pipeline::FrameGraph& graph, pipeline::FrameStart& start,
                       const ResidentGatherResources& resources, const ResidentGatherSettings& settings)
{
    const int w = settings.width, h = settings.height;
    const ResidentGatherSettings s = settings;
    const auto gbufferGpu = start.gbuffer();
    const auto positionGpu = start.positionDepthGpu();
    const auto normalGpu = start.worldNormalGpu();
    const pipeline::Resource<const gpu::Image*> onGpu{
        "technique_indirect_gpu", pipeline::ResourceType::gpuImage("rgba32f irradiance", w, h)};
    std::vector<pipeline::ResourceRef> optional;
    if (resources.coneVisibility)
        optional.push_back(*resources.coneVisibility);
    if (resources.capsules)
        optional.push_back(*resources.capsules);
    const auto cones = resources.coneVisibility;
    const auto posed = resources.capsules;
    graph.addPass(
        {.name = "voxel_gather",
         .reads = {resources.voxelLight, gbufferGpu, positionGpu, normalGpu, resources.geometry},
         .optionalReads = optional,
         .writes = {onGpu}},
        [s, gbufferGpu, positionGpu, normalGpu, cones, posed, onGpu, w, h,
         geometry = resources.geometry](pipeline::PassContext& ctx) {
            const pipeline::GpuGBuffer& g = ctx.read(gbufferGpu);
            plugin::VoxelGiGpuGBuffer images;
            images.positionDepth = &ctx.read(positionGpu);
            images.normal = &ctx.read(normalGpu);
            images.width = g.width;
            images.height = g.height;
            images.cameraPosition = glm::dvec3(g.camera.position);
            plugin::VoxelGiInput input;
            input.gpuGBuffer = &images;
            input.cameraPosition = images.cameraPosition;
            input.frameIndex = ctx.frame();
            input.gpu = s.gpu;
            input.capsules = posed ? ctx.tryRead(*posed) : nullptr;
            if (const auto* v = cones ? ctx.tryRead(*cones) : nullptr)
                input.gpuConeVisibility = *v;
            input.readBack = false;
            input.scene = &ctx.read(geometry);
            input.coneSky = s.coneSky;
            Image<glm::vec3> unused;
            s.technique->gather(input, unused);
            const gpu::Image* image = s.technique->getGpuIrradiance();
            if (image == nullptr)
                throw Error("technique '" + s.techniqueName +
                            "' says its gather runs on the GPU but left no irradiance there");
            const gpu::ImageDesc& d = image->getDesc();
            if (int(d.width) != w || int(d.height) != h || d.format != gpu::Format::RGBA32Float)
                throw Error("technique '" + s.techniqueName + "' left a " + std::to_string(d.width) + "x" +
                            std::to_string(d.height) + " " + std::string(gpu::getFormatName(d.format)) +
                            " irradiance image on the GPU where the lighting pass binds an RGBA32Float image "
                            "of the G-buffer's size (" +
                            std::to_string(w) + "x" + std::to_string(h) + ")");
            ctx.write(onGpu) = image;
            (*s.row)->set("gather.cone_visibility", input.gpuConeVisibility[0] != nullptr);
            (*s.row)->set("voxel_gather.resident", *s.resident);
            return pipeline::PassOutcome{};
        });
    graph.addPass({.name = "voxel_gather_readback",
                   .reads = {onGpu},
                   .writes = {resources.indirect},
                   .forReaders = true},
                  [s, indirect = resources.indirect, w, h](pipeline::PassContext& ctx) {
                      Image<glm::vec3>& out = ctx.write(indirect);
                      s.technique->readBackIrradiance(out);
                      if (out.width != w || out.height != h)
                          throw Error("technique '" + s.techniqueName + "' read back " +
                                      std::to_string(out.width) + "x" + std::to_string(out.height) +
                                      " irradiance for a " + std::to_string(w) + "x" + std::to_string(h) +
                                      " G-buffer");
                      return pipeline::PassOutcome{};
                  });
    const auto slotGpu = pipeline::Compose::indirectIrradianceGpuSlot(w, h);
    graph.addPass({.name = "indirect_gpu_slot", .reads = {onGpu}, .writes = {slotGpu}},
                  [onGpu, slotGpu](pipeline::PassContext& ctx) {
                      ctx.write(slotGpu) = ctx.read(onGpu);
                      return pipeline::PassOutcome{};
                  });
    // The cones' sky where the technique left it (checked as the irradiance is), else a null
    // slot: the lit frame then takes the lobes, and the row says why.
    const auto coneSkyGpu = pipeline::Compose::coneSkyGpuSlot(w, h);
    graph.addPass({.name = "voxel_cone_sky", .reads = {onGpu}, .writes = {coneSkyGpu}},
                  [s, coneSkyGpu, w, h](pipeline::PassContext& ctx) {
                      const gpu::Image* image = s.technique->getGpuConeSky();
                      if (image == nullptr) {
                          ctx.write(coneSkyGpu) = nullptr;
                          (*s.row)->set("voxel_cone_sky.none",
                                        "technique '" + s.techniqueName +
                                            "' traced no cone sky in its resident Vulkan gather");
                          return pipeline::PassOutcome{};
                      }
                      const gpu::ImageDesc& d = image->getDesc();
                      if (int(d.width) != w || int(d.height) != h || d.format != gpu::Format::RGBA32Float)
                          throw Error("technique '" + s.techniqueName + "' left a " + std::to_string(d.width) +
                                      "x" + std::to_string(d.height) + " " +
                                      std::string(gpu::getFormatName(d.format)) +
                                      " cone sky image on the GPU where the lighting pass binds an "
                                      "RGBA32Float image of the G-buffer's size (" +
                                      std::to_string(w) + "x" + std::to_string(h) + ")");
                      ctx.write(coneSkyGpu) = image;
                      return pipeline::PassOutcome{};
                  });
    graph.addPass({.name = "voxel_cone_sky_readback",
                   .reads = {coneSkyGpu},
                   .writes = {resources.coneSky},
                   .forReaders = true},
                  [s, coneSkyGpu, coneSky = resources.coneSky](pipeline::PassContext& ctx) {
                      Image<glm::vec3>& out = ctx.write(coneSky);
                      out = Image<glm::vec3>();
                      if (ctx.read(coneSkyGpu) != nullptr)
                          s.technique->readBackConeSky(out);
                      return pipeline::PassOutcome{};
                  });
}

} // namespace rtlab::voxelgi
