#pragma once
// Temporal stability of a screen-space estimate along a camera path: how much a technique's
// output changes from frame to frame at the same surface point, compared with how much the
// ground truth changes there.
//
// Reprojection. For each pixel p of frame t with a surface (finite linear depth > 0), its world
// point X is the G-buffer position when given, else it is reconstructed from the linear depth at
// the pixel's sample (pixel centre + the jitter the projection encodes; ScreenProjection::toView)
// and the inverse view matrix. X goes into frame t-1's view; the pixel of frame t-1 whose
// footprint contains its projection is fetched (nearest: no filtering, so a technique's noise in
// frame t-1 is not averaged away, which would understate its flicker). p is rejected, and counted,
// when X is behind frame t-1's camera or projects outside its image (off-screen), or when frame
// t-1 has no surface there or its linear depth differs from X's depth in frame t-1 by more than
// depthTolerance relative to the latter (disocclusion). Values are compared only at used pixels.
//
// With T' and R' the technique and reference of frame t-1 fetched at the reprojected pixel:
//   technique change  sqrt(mean_p (T_t(p) - T'(p))^2)
//   reference change  sqrt(mean_p (R_t(p) - R'(p))^2)
//   flicker           sqrt(mean_p ((T_t - T') - (R_t - R'))^2) = RMS change of the error T - R
// Flicker is the change of the technique that the true change does not explain: 0 for a
// technique whose error is constant on the surface, 2e for an error that alternates +e, -e.
// The reference's own Monte Carlo noise enters it too; given the reference's standard errors
// the expected contribution sqrt(mean_p (se_t^2 + se'^2)) is reported as the noise floor.

#include "core/image.h"

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include <cstdint>
#include <vector>

namespace rtlab::metrics {

//! One frame as the temporal metrics read it. Images share the depth image's size.
struct TemporalFrame {
    const Image<float>* technique = nullptr;   //!< T_t
    const Image<float>* reference = nullptr;   //!< R_t
    const Image<float>* linearDepth = nullptr; //!< view-space distance along -z; inf = no surface
    glm::mat4 projection{1.0f}; //!< view -> Vulkan clip space (scene/gbuffer.h), jitter included
    glm::mat4 view{1.0f};       //!< world -> view
    //! Optional: G-buffer world positions (else reconstructed from the depth).
    const Image<glm::vec3>* worldPosition = nullptr;
    //! Optional: per-pixel standard error of the reference (for the noise floor).
    const Image<float>* referenceStdErr = nullptr;
    //! Optional: pixels of frame t to consider (nonzero), e.g. surface pixels or an artifact mask.
    const Image<std::uint8_t>* mask = nullptr;
};

struct TemporalOptions {
    double depthTolerance = 0.05; //!< relative depth mismatch that marks a disocclusion, > 0
};

//! The change from frame t-1 to frame t.
struct TemporalChange {
    double techniqueChangeRms = 0.0; //!< NaN when no pixel is used
    double referenceChangeRms = 0.0;
    double flickerRms = 0.0;
    double techniqueChangeMean = 0.0;    //!< signed mean of T_t - T'
    double referenceNoiseFloorRms = 0.0; //!< NaN unless both frames carry referenceStdErr
    std::int64_t candidatePixels = 0;    //!< pixels of frame t with a surface (inside the mask)
    std::int64_t usedPixels = 0;
    std::int64_t offScreenPixels = 0;
    std::int64_t disoccludedPixels = 0;
    double usedShare = 0.0; //!< usedPixels / candidatePixels (0 when there is none)
};

//! Per-pixel images of one frame pair; NaN where a pixel is not used.
struct TemporalChangeImages {
    Image<float> techniqueChange; //!< T_t - T'
    Image<float> flicker;         //!< (T_t - T') - (R_t - R')
};

//! The change from `previous` (frame t-1) to `current` (frame t). Throws rtlab::Error for
//! missing or mismatched images or a bad tolerance. `images`, when given, receives the per-pixel
//! differences.
TemporalChange computeTemporalChange(const TemporalFrame& previous, const TemporalFrame& current,
                                     const TemporalOptions& options = {},
                                     TemporalChangeImages* images = nullptr);

//! A whole path: one TemporalChange per consecutive pair, and the pooled figures (RMS over every
//! used pixel of every pair; shares over every candidate).
struct TemporalSummary {
    std::vector<TemporalChange> pairs; //!< pairs[i]: frames i -> i + 1
    TemporalChange pooled;
};

//! Frames in path order; fewer than two frames give no pairs and a pooled result with NaN RMS.
TemporalSummary computeTemporalSummary(const std::vector<TemporalFrame>& frames,
                                       const TemporalOptions& options = {});

} // namespace rtlab::metrics
