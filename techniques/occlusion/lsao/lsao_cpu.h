#pragma once
// The plain C++ version of both passes (TBB-parallel): the same layout, jitter, hull and gather
// as shaders/lsao_sweep.comp and shaders/lsao_gather.comp.

#include "lsao_core.h"

#include "core/image.h"
#include "families/occlusion/occlusion.h"

#include <cstdint>
#include <vector>

namespace rtlab::occlusion::lsao {

//! Pass 1 of batch `batch`: for every line of its directions, walks the step strata in order
//! and stores, per stratum, the stratum index of the dominant occluder of its sample (or
//! kNoOccluder), at Direction::base + line * stepCount + stratum.
std::vector<std::uint32_t> runSweepCpu(const Layout& layout, std::size_t batch,
                                       const Image<float>& depth, const Image<glm::vec3>& normal);

//! Per-pixel sums of the half-slice contributions (ordered by direction).
struct Accumulators {
    std::vector<float> obscurance;
    std::vector<float> visibility;
    std::vector<glm::vec3> moment;
};

//! Pass 2 of batch `batch`: adds the contributions of its directions to `sums`.
void runGatherCpu(const Layout& layout, std::size_t batch,
                  const plugin::ScreenProjection& projection, const Params& params,
                  const Image<float>& depth, const Image<glm::vec3>& normal,
                  const std::vector<std::uint32_t>& sweep, Accumulators& sums);

//! Both passes over all batches, then the outputs.
void computeOnCpu(const Layout& layout, const plugin::ScreenProjection& projection,
                  const Params& params, const Image<float>& depth, const Image<glm::vec3>& normal,
                  plugin::OcclusionOutput& out);

//! Whether a G-buffer pixel holds a surface: finite positive depth and a non-zero normal.
inline bool hasSurface(float depth, const glm::vec3& normal)
{
    return depth > 0.0f && depth < std::numeric_limits<float>::infinity() &&
           glm::dot(normal, normal) > 1e-12f;
}

} // namespace rtlab::occlusion::lsao
