#pragma once
// The Vulkan path of bentcone_ssdo: one dispatch, "bentcone_ssdo.main". The shader is compiled
// and the pipeline created on the first frame; images and the frame buffer are kept across frames
// and recreated when the image size or the sample count changes (or the Context does).

#include "bentcone_ssdo_cpu.h"

#include <memory>

namespace rtlab::gpu {
class Context;
}

namespace rtlab::bentcone_ssdo {

class GpuPath {
public:
    GpuPath();
    ~GpuPath();
    GpuPath(GpuPath&&) noexcept;
    GpuPath& operator=(GpuPath&&) noexcept;

    //! Runs the estimator on `context`: out.gpu.coneVisibility holds its 16 cone visibilities
    //! on the GPU, and with input.readBack every CPU field of `out` is filled like computeOnCpu.
    void compute(gpu::Context& context, const FrameSetup& frame,
                 const plugin::OcclusionInput& input, plugin::OcclusionOutput& out);
    //! The CPU fields of `out` from the last compute() (out.gpu kept). Throws rtlab::Error
    //! before the first.
    void readBack(plugin::OcclusionOutput& out) const;

private:
    struct State;
    std::unique_ptr<State> mState;
};

} // namespace rtlab::bentcone_ssdo
