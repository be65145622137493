#pragma once
// The lit frame of a run with `frame: {lighting: true}`: the compose passes (pipeline/compose.h)
// after the families' passes, then its ground truth and metrics:
//   reference_full    Embree `full` radiance (emission + direct + 2 bounces) from the same G-buffer
//   reference_direct  Embree `direct` radiance
//   metric.frame      final HDR frame against `full` (frame.*: RMSE, relMSE, HDR-FLIP, mean signed
//                     error over all pixels) and the direct term against `direct` (direct.*, over
//                     surface pixels); a missing indirect term shows as a negative signed error
//   frame_images      frame<k>/lit.png (tonemapped), lit.exr (HDR), truth.png, truth.exr, and
//                     lit_error.exr (HDR frame minus truth)

#include "experiment/experiment.h"
#include "experiment/results.h"

#include <memory>
#include <string>
#include <vector>

namespace rtlab::pipeline {
class FrameGraph;
class FrameStart;
class Compose;
} // namespace rtlab::pipeline

namespace rtlab::experiment {

class DriverContext;

class LitFrame {
public:
    //! Adds the compose passes and the measurement passes to `graph` (after the families'
    //! passes) and the requested outputs to `outputs`.
    LitFrame(const RunConfig& run, DriverContext& context, pipeline::FrameStart& start,
             pipeline::FrameGraph& graph, std::vector<std::string>& outputs);
    ~LitFrame();

    //! Columns every row carries (tonemapper, exposure, shadow-map size, what fills the slots).
    void describe(ResultRow& row) const;
    void beginFrame(ResultRow& row) { mRow = &row; }
    //! Columns of what the compose passes did this frame.
    void endFrame(ResultRow& row);

private:
    const RunConfig& mRun;
    DriverContext& mContext;
    std::unique_ptr<pipeline::Compose> mCompose;
    ResultRow* mRow = nullptr;
};

} // namespace rtlab::experiment
