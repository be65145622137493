#pragma once
// Typed handles of GPU images the frame graph creates itself (pipeline/frame_graph.h): the graph
// allocates the image on the device when its producer first writes it, releases it into its pool
// after the last reader, and hands it to the next writer of the same type and size.

#include "gpu/context.h"
#include "gpu/format.h"
#include "pipeline/frame_graph.h"

#include <memory>
#include <string>

namespace rtlab::pipeline {

//! A 2D storage (and sampled) image of `format`, width x height, allocated on `context` by the
//! graph.
inline Resource<gpu::Image> makeGpuImageResource(gpu::Context& context, const std::string& name,
                                                 gpu::Format format, int width, int height)
{
    gpu::ImageDesc desc;
    desc.format = format;
    desc.width = std::uint32_t(width);
    desc.height = std::uint32_t(height);
    desc.usage = gpu::ImageUsage::StorageAndSampled;
    desc.name = name;
    gpu::Context* ctx = &context;
    return {name, ResourceType::gpuImage(std::string(gpu::getFormatName(format)), width, height),
            [ctx, desc] { return std::make_shared<gpu::Image>(ctx->createImage(desc)); }};
}

} // namespace rtlab::pipeline
