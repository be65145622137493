#pragma once
// Reduced-resolution gathering for voxel_gi techniques: trace at one pixel per factor x factor
// block and upsample with depth- and normal-aware weights. The Tomorrow Children traced its pixel
// cones at a quarter of each dimension (1/16 of the pixels) and upsampled "in a geometrically
// aware way" (shared/seeds/000_3da000e866ebc485.txt, "Trace at a lower resolution"); the weights
// here are joint bilateral upsampling (Kopf et al., "Joint Bilateral Upsampling", SIGGRAPH 2007):
// bilinear weights of the four nearest low-resolution samples times a depth term and a normal
// term, so that light does not bleed across depth discontinuities or creases.

#include "core/image.h"
#include "scene/gbuffer.h"

#include <glm/vec3.hpp>

#include <vector>

namespace rtlab::voxelgi {

//! The low-resolution view of a G-buffer: one representative pixel per block (the block's centre
//! pixel when it has a surface, else its first surface pixel in row order, else none).
struct ReducedGBuffer {
    int factor = 1;
    scene::GBuffer gbuffer;          //!< ceil(w / factor) x ceil(h / factor)
    std::vector<int> representative; //!< per low-res pixel: full-res pixel index, -1 = none
};

//! `factor` in [1, 16]; factor 1 copies the G-buffer.
ReducedGBuffer reduceGBuffer(const scene::GBuffer& full, int factor);

//! Per-cone images (16) restricted to the representative pixels, or empty when `full` is null.
std::vector<Image<float>> reduceConeImages(const std::vector<Image<float>>* full,
                                           const ReducedGBuffer& reduced);

//! Upsamples `low` (irradiance at the representative pixels) to the full G-buffer. A pixel whose
//! four neighbours all fail the depth and normal tests takes the most similar of its 3 x 3
//! low-resolution neighbours; pixels without a surface get 0.
Image<glm::vec3> upsampleIrradiance(const Image<glm::vec3>& low, const ReducedGBuffer& reduced,
                                    const scene::GBuffer& full);

} // namespace rtlab::voxelgi
