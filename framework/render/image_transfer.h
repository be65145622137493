#pragma once
// Moving images between the passes of a frame and the CPU:
//  * gpu::copyAttachmentToImage (gpu/graphics.h) records a GPU-side copy of a render-target
//  attachment into a
//    gpu::Image. Attachments are colour attachments only (no storage or sampled usage), so a
//    compute shader cannot bind them; the copy lets compute passes read what a draw rendered
//    (the G-buffer, shadow-map faces) without a round trip through the CPU.
//  * createImageFrom / downloadRgb / downloadScalar convert between rtlab::Image and GPU images
//    (for inputs such as ambient occlusion, and for metrics and files).

#include "core/image.h"
#include "gpu/commands.h"
#include "gpu/context.h"
#include "gpu/graphics.h"
#include "gpu/resources.h"

#include <glm/vec3.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace rtlab::render {

using gpu::copyAttachmentToImage; // gpu/graphics.h

//! A 2D R32Float image (storage and sampled) holding `image`.
gpu::Image createImageFrom(gpu::Context& context, const Image<float>& image,
                           const std::string& name);
//! A 2D RGBA32Float image (storage and sampled) holding `image` with alpha 1.
gpu::Image createImageFrom(gpu::Context& context, const Image<glm::vec3>& image,
                           const std::string& name);

//! Uploads `image` into `target`, an R32Float (Image<float>) or RGBA32Float (Image<glm::vec3>,
//! alpha 1) image of its size. Throws rtlab::Error for another size or format.
void uploadInto(gpu::Image& target, const Image<float>& image);
void uploadInto(gpu::Image& target, const Image<glm::vec3>& image);
//! The 16 cone visibilities of scene::getConeDirections() packed as the lighting pass reads them
//! (render/lighting_pass.h): cone k in channel k % 4 of targets[k / 4], four RGBA32Float images
//! of the cones' size. Throws rtlab::Error unless there are 16 images of one size.
void uploadConeVisibility(const std::array<gpu::Image*, 4>& targets,
                          const std::vector<Image<float>>& cones);

//! The first three channels of a 2D RGBA32Float, RGBA16Float or RGBA8Unorm (as value / 255)
//! image. Throws rtlab::Error for other formats or 3D images.
Image<glm::vec3> downloadRgb(const gpu::Image& image);
//! Channel `channel` (0..3) of a 2D image of any format (R32Uint values converted to float).
//! Throws rtlab::Error for a 3D image or a channel the format lacks.
Image<float> downloadScalar(const gpu::Image& image, int channel = 0);

} // namespace rtlab::render
