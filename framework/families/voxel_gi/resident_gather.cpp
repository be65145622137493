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
         .reads = {resources.voxelLight, gbufferGpu, positionGpu, normalGpu},
         .optionalReads = optional,
         .writes = {onGpu}},
        [s, gbufferGpu, positionGpu, normalGpu, cones, posed, onGpu, w, h](pipeline::PassContext& ctx) {
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
    // No cone sky on this path yet: the lit frame takes the lobes, and the row says why.
    const auto coneSkyGpu = pipeline::Compose::coneSkyGpuSlot(w, h);
    graph.addPass({.name = "voxel_cone_sky", .reads = {onGpu}, .writes = {coneSkyGpu}},
                  [s, coneSkyGpu](pipeline::PassContext& ctx) {
                      ctx.write(coneSkyGpu) = nullptr;
                      (*s.row)->set("voxel_cone_sky.none",
                                    "the resident Vulkan gather traces no cone sky yet (device: cpu does)");
                      return pipeline::PassOutcome{};
                  });
}

} // namespace rtlab::voxelgi
