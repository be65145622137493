#pragma once
// Image error metrics of a technique's image against a reference image: RMSE, relative MSE,
// PSNR, SSIM, FLIP (LDR and HDR) and mean signed error, each optionally restricted to a mask,
// plus the standard masks (depth edges, thin objects, screen border).
//
// Conventions shared by every function here:
//  - `test` is the image being judged, `reference` the ground truth; both have the same size,
//    otherwise std::invalid_argument is thrown naming both sizes.
//  - RGB images hold either LDR values in [0, 1] (sRGB-encoded or linear: see ColorEncoding) or
//    HDR linear radiance (>= 0, unbounded). RMSE, relative MSE, PSNR, SSIM and the mean signed
//    error are computed on the stored values as they are; only FLIP interprets the encoding.
//  - Per-pixel errors of RGB images are the average over the three channels.
//  - A mask (MaskView) weights each pixel; a metric inside a mask is the weighted mean of its
//    per-pixel values. SSIM and FLIP maps are always computed on the whole image (their windows
//    see unmasked neighbours); the mask only selects which map values are averaged.
//  - An empty selection (no pixel with a positive weight, or an empty image) gives NaN for every
//    metric and `pixels == 0`; it never throws.
//  - Non-finite values (NaN, +-inf) in `test` are not screened by the individual metric
//    functions: they propagate into the result (NaN or inf), except that FLIP clamps its inputs
//    (so +-inf becomes 1 or 0 there; NaN still propagates). computeImageErrors instead counts them
//    and replaces them by the worst valid value (see ImageErrors::nonFinitePixels). Non-finite
//    values in `reference` are an error (std::invalid_argument) everywhere.

#include "core/image.h"

#include <glm/vec3.hpp>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace rtlab::metrics {

// ------------------------------------------------------------------------------------------------
// Masks

//! A non-owning view of per-pixel weights that restricts a metric to part of the image.
//! Default-constructed: no mask (every pixel has weight 1). From an Image<std::uint8_t>: weight 1
//! where the value is nonzero, 0 elsewhere. From an Image<float>: the value itself, which must be
//! finite and >= 0 (std::invalid_argument otherwise); fractional weights give a weighted mean.
//! The viewed image must outlive the view and have the size of the images being compared.
class MaskView {
public:
    MaskView() = default;
    MaskView(const Image<std::uint8_t>& mask) : mBinary(&mask) {} // NOLINT: implicit on purpose
    MaskView(const Image<float>& weights) : mWeights(&weights) {} // NOLINT: implicit on purpose

    //! True when no mask was given.
    bool isAll() const { return mBinary == nullptr && mWeights == nullptr; }
    //! Size of the viewed image in pixels (0 x 0 when isAll()).
    int width() const;
    int height() const;
    //! Weight of pixel `index` (row-major), >= 0; 1 when isAll().
    double weight(std::size_t index) const;

private:
    const Image<std::uint8_t>* mBinary = nullptr;
    const Image<float>* mWeights = nullptr;
};

//! Pixels within `k` pixels of a depth discontinuity. Two 4-neighbours p, q form a discontinuity
//! when |d_p - d_q| / min(d_p, d_q) > relativeJump. Depths are view distances (> 0, any unit);
//! values that are not finite or <= 0 mean "no surface" (background): a pixel next to the
//! background is a discontinuity, two background pixels are not. Both pixels of a discontinuous
//! pair are marked, then the marks are dilated by `k` in Chebyshev distance (a (2k+1)^2 square).
//! So a vertical step between columns s-1 and s marks exactly columns s-1-k .. s+k.
//! Returns 1 inside the mask, 0 outside. k >= 0 and relativeJump > 0 (std::invalid_argument).
Image<std::uint8_t> makeDepthEdgeMask(const Image<float>& depth, int k, double relativeJump = 0.1);

//! Pixels within `k` pixels of the image edge: those with min(x, y, W-1-x, H-1-y) < k, i.e. the
//! outer k rows and columns. Pixel count: W*H - max(0, W-2k) * max(0, H-2k). k >= 0.
Image<std::uint8_t> makeBorderMask(int width, int height, int k);

//! Thin structures of a coverage mask by morphological opening: a covered (nonzero) pixel is thin
//! when no fully covered (2r+1) x (2r+1) square contains it, i.e. it is removed by an opening with
//! that square. Everything narrower than 2r+1 pixels (wires, foliage, silhouette slivers) is
//! thin; pixels of wider regions are not. Squares are clipped at the image edge, so the edge itself
//! never makes a region thin. r >= 1 (std::invalid_argument).
Image<std::uint8_t> makeThinStructureMask(const Image<std::uint8_t>& coverage, int r);

//! The same opening applied per object: a pixel with id != background is thin when no
//! (2r+1) x (2r+1) square made only of its own id contains it. Unlike the coverage version, this
//! finds a thin object in front of another object (where the coverage is full).
Image<std::uint8_t> makeThinStructureMask(const Image<std::uint32_t>& objectIds, int r,
                                          std::uint32_t background = 0);

//! Pixels whose object id is in `ids` (e.g. the objects a scene tags as thin), dilated by
//! `dilation` pixels (Chebyshev distance) to include their silhouette edges. dilation >= 0.
Image<std::uint8_t> makeObjectMask(const Image<std::uint32_t>& objectIds,
                                   const std::vector<std::uint32_t>& ids, int dilation = 0);

//! Binary dilation (nonzero = set) by a (2k+1) x (2k+1) square: every pixel within Chebyshev
//! distance k of a set pixel is set. Use it to grow a given thin-object mask. k >= 0.
Image<std::uint8_t> dilateMask(const Image<std::uint8_t>& mask, int k);

//! Number of pixels of a width x height image with a positive weight.
std::size_t countMaskPixels(MaskView mask, int width, int height);

// ------------------------------------------------------------------------------------------------
// Pixel-wise metrics

//! The epsilon of the relative MSE, (x - r)^2 / (r^2 + eps): 1e-2, the value used in the
//! rendering literature (e.g. Rousselle et al. 2011 and the denoising papers that followed).
inline constexpr double kRelMseEpsilon = 1e-2;

//! Mean squared error (units of the pixel values, squared).
double computeMse(const Image<float>& test, const Image<float>& reference, MaskView mask = {});
double computeMse(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                  MaskView mask = {});
//! Root mean squared error, sqrt(MSE) (units of the pixel values).
double computeRmse(const Image<float>& test, const Image<float>& reference, MaskView mask = {});
double computeRmse(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                   MaskView mask = {});
//! Relative MSE: mean of (x - r)^2 / (r^2 + epsilon) (dimensionless).
double computeRelativeMse(const Image<float>& test, const Image<float>& reference,
                          MaskView mask = {}, double epsilon = kRelMseEpsilon);
double computeRelativeMse(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                          MaskView mask = {}, double epsilon = kRelMseEpsilon);
//! Peak signal-to-noise ratio 10 log10(peak^2 / MSE) in dB. `peak` is 1 for LDR images; for HDR
//! images pass the value to treat as full scale (e.g. the reference's maximum). Identical images
//! give +infinity (no cap).
double computePsnr(const Image<float>& test, const Image<float>& reference, double peak = 1.0,
                   MaskView mask = {});
double computePsnr(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                   double peak = 1.0, MaskView mask = {});
//! Mean of (x - r): positive when the test image is brighter than the reference (pixel units).
double computeMeanSignedError(const Image<float>& test, const Image<float>& reference,
                              MaskView mask = {});
double computeMeanSignedError(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                              MaskView mask = {});

// ------------------------------------------------------------------------------------------------
// SSIM [Wang, Bovik, Sheikh, Simoncelli 2004, "Image Quality Assessment: From Error Visibility to
// Structural Similarity"]

//! Which signal SSIM compares for RGB images.
enum class SsimChannels {
    Luminance,  //!< Y = 0.2126 R + 0.7152 G + 0.0722 B of the stored values (luma if encoded)
    PerChannel, //!< SSIM map of R, G and B separately, then averaged
};

struct SsimOptions {
    double dynamicRange = 1.0; //!< L, the range of the pixel values (1 for LDR), > 0
    double k1 = 0.01;          //!< C1 = (k1 L)^2
    double k2 = 0.03;          //!< C2 = (k2 L)^2
    double sigma = 1.5;        //!< Gaussian window standard deviation, pixels
    int radius = 5;            //!< window half size: 11 x 11 for 5, pixels
    SsimChannels channels = SsimChannels::Luminance; //!< RGB inputs only
};

struct SsimResult {
    double mean = 0;        //!< mean SSIM over the selected pixels, [-1, 1]; 1 for identical images
    Image<float> map;       //!< per-pixel SSIM, [-1, 1], the size of the inputs
    std::size_t pixels = 0; //!< pixels with a positive mask weight
};

//! SSIM with the Gaussian window of Wang et al. (sigma 1.5, 11 x 11, K1 0.01, K2 0.03). The map
//! has the image's size: near the edge the window is clipped to the image and renormalised (Wang
//! et al. keep only the interior). Statistics are computed in double precision.
SsimResult computeSsim(const Image<float>& test, const Image<float>& reference,
                       const SsimOptions& options = {}, MaskView mask = {});
SsimResult computeSsim(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                       const SsimOptions& options = {}, MaskView mask = {});

// ------------------------------------------------------------------------------------------------
// FLIP [Andersson, Nilsson, Akenine-Moeller, Oskarsson, Astroem, Fairchild 2020, "FLIP: A
// Difference Evaluator for Alternating Images", HPG 2020] and HDR-FLIP [Andersson, Nilsson,
// Shirley, Akenine-Moeller 2021, "Visualizing Errors in Rendered High Dynamic Range Images",
// Eurographics 2021 short papers].

//! How LDR values are encoded.
enum class ColorEncoding {
    Srgb,   //!< sRGB transfer function (what an 8-bit PNG holds), [0, 1]
    Linear, //!< linear RGB with sRGB/Rec.709 primaries, [0, 1]
};

//! HDR-FLIP's tone mappers, applied after the exposure 2^c; results are clamped to [0, 1].
enum class ToneMapper {
    Aces,     //!< per channel: Narkowicz's ACES fit with its 0.6 pre-scale (the default)
    Hable,    //!< per channel: Hable's filmic curve, white point 11.2, exposure bias 2
    Reinhard, //!< x / (1 + Y(x)), Y the luminance of the exposed colour
};

//! Pixels per degree of visual angle of an observer at `distanceMeters` from a monitor
//! `widthMeters` wide with `widthPixels` pixels across: distance * (pixels / width) * pi / 180.
double computePixelsPerDegree(double distanceMeters, double widthMeters, double widthPixels);

//! FLIP's default viewing conditions: 0.7 m from a 0.7 m wide 3840-pixel monitor, ~67.02 ppd.
inline constexpr double kDefaultPixelsPerDegree =
    0.7 * (3840.0 / 0.7) * 3.14159265358979323846 / 180.0;

struct FlipOptions {
    //! Observer's pixels per degree of visual angle, > 0 (see computePixelsPerDegree).
    double pixelsPerDegree = kDefaultPixelsPerDegree;
    //! HDR-FLIP only: the tone mapper assumed for display.
    ToneMapper toneMapper = ToneMapper::Aces;
    //! HDR-FLIP only: first exposure in stops (log2 of the factor applied before tone mapping).
    //! Unset: from the reference's luminance Y = 0.2126 R + 0.7152 G + 0.0722 B, as in HDR-FLIP:
    //! start = log2(T^-1(0.85) / max Y), T the tone mapper.
    std::optional<double> startExposure;
    //! HDR-FLIP only: last exposure in stops. Unset: stop = log2(T^-1(0.85) / median Y). When
    //! more than half of the reference is black the median of the pixels with Y > 0 is used
    //! (the plain median would give an infinite stop exposure). An all-black reference gives
    //! start = stop = 0.
    std::optional<double> stopExposure;
    //! HDR-FLIP only: exposures from start to stop, evenly spaced, >= 1. Unset: max(2,
    //! ceil(stop - start)), or 1 when start == stop.
    std::optional<int> exposureCount;
};

struct FlipResult {
    double mean = 0;        //!< mean FLIP over the selected pixels, [0, 1]; 0 for identical
    Image<float> map;       //!< per-pixel FLIP error, [0, 1], the size of the inputs
    std::size_t pixels = 0; //!< pixels with a positive mask weight
    // HDR-FLIP only (0 for LDR-FLIP):
    double startExposure = 0; //!< stops, the exposure range actually used
    double stopExposure = 0;  //!< stops
    int exposureCount = 0;    //!< LDR-FLIP evaluations whose per-pixel maximum is the map
};

//! LDR-FLIP. Values outside [0, 1] are clamped (LDR-FLIP is defined on [0, 1]). Scalar images are
//! treated as grey (R = G = B).
FlipResult computeFlip(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                       ColorEncoding encoding, const FlipOptions& options = {}, MaskView mask = {});
FlipResult computeFlip(const Image<float>& test, const Image<float>& reference,
                       ColorEncoding encoding, const FlipOptions& options = {}, MaskView mask = {});

//! HDR-FLIP of linear radiance images: for each exposure c in the range, both images are scaled
//! by 2^c, tone mapped and clamped to [0, 1], LDR-FLIP is evaluated, and the map is the per-pixel
//! maximum over the exposures. Negative values are clamped to 0 first.
FlipResult computeHdrFlip(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                          const FlipOptions& options = {}, MaskView mask = {});

//! The tone mapper T of HDR-FLIP applied to one linear colour (already exposed), clamped to [0,1].
glm::vec3 applyToneMapper(ToneMapper toneMapper, const glm::vec3& exposed);

// ------------------------------------------------------------------------------------------------
// Everything at once

enum class DynamicRange {
    Ldr, //!< values in [0, 1], encoded per ImageErrorOptions::encoding; LDR-FLIP
    Hdr, //!< linear radiance >= 0; HDR-FLIP
};

struct ImageErrorOptions {
    DynamicRange range = DynamicRange::Ldr;       //!< LDR (LDR-FLIP) or HDR (HDR-FLIP) inputs
    ColorEncoding encoding = ColorEncoding::Srgb; //!< LDR only; read by FLIP alone
    //! Full-scale value: PSNR's peak, SSIM's L and the bound used for non-finite pixels. Unset: 1
    //! for LDR, the reference's largest channel value for HDR (1 if that is <= 0).
    std::optional<double> peak;
    double relMseEpsilon = kRelMseEpsilon;               //!< > 0
    SsimChannels ssimChannels = SsimChannels::Luminance; //!< RGB inputs only
    FlipOptions flip;     //!< observer and, for HDR, tone mapper and exposures
    bool withSsim = true; //!< false: ssim is NaN (saves time)
    bool withFlip = true; //!< false: flip is NaN (HDR-FLIP runs several LDR-FLIPs)
};

struct ImageErrors {
    double rmse = 0;            //!< pixel units, >= 0
    double relMse = 0;          //!< dimensionless, >= 0
    double psnr = 0;            //!< dB; +infinity when the images are identical
    double ssim = 0;            //!< [-1, 1], 1 = identical
    double flip = 0;            //!< [0, 1], 0 = identical (LDR- or HDR-FLIP per `range`)
    double meanSignedError = 0; //!< pixel units; > 0 when the test image is too bright
    double peak = 0;            //!< the peak that was used (pixel units)
    std::size_t pixels = 0;     //!< pixels with a positive mask weight (all when no mask)
    //! Selected pixels of `test` with a NaN or infinite channel. Policy (applied to every pixel of
    //! the image, selected or not): each such channel is replaced by whichever of 0 and `peak` is
    //! farther from the reference value (the worst value a valid image could hold) before any
    //! metric is computed, and the FLIP map is set to 1, its maximum, at such pixels. They are
    //! counted and scored as large errors, never dropped.
    std::size_t nonFinitePixels = 0;
};

//! All metrics of `test` against `reference` inside `mask`.
ImageErrors computeImageErrors(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                               const ImageErrorOptions& options = {}, MaskView mask = {});
//! Scalar images (FLIP sees them as grey).
ImageErrors computeImageErrors(const Image<float>& test, const Image<float>& reference,
                               const ImageErrorOptions& options = {}, MaskView mask = {});

} // namespace rtlab::metrics
