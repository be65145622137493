#include "metrics/image_metrics.h"

#include "metrics/image_metrics_detail.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rtlab::metrics {

namespace detail {

void requireSameSize(int testWidth, int testHeight, int refWidth, int refHeight, const char* what)
{
    if (testWidth != refWidth || testHeight != refHeight)
        throw std::invalid_argument(std::string(what) + ": test image is " +
                                    std::to_string(testWidth) + "x" + std::to_string(testHeight) +
                                    " but the reference is " + std::to_string(refWidth) + "x" +
                                    std::to_string(refHeight));
}

void requireValidMask(MaskView mask, int width, int height, const char* what)
{
    if (mask.isAll())
        return;
    if (mask.width() != width || mask.height() != height)
        throw std::invalid_argument(std::string(what) + ": mask is " +
                                    std::to_string(mask.width()) + "x" +
                                    std::to_string(mask.height()) + " but the images are " +
                                    std::to_string(width) + "x" + std::to_string(height));
    const std::size_t n = std::size_t(width) * height;
    for (std::size_t i = 0; i < n; ++i) {
        const double w = mask.weight(i);
        if (!std::isfinite(w) || w < 0)
            throw std::invalid_argument(std::string(what) + ": mask weight " + std::to_string(w) +
                                        " at pixel " + std::to_string(i % width) + "," +
                                        std::to_string(i / width) +
                                        " (weights must be finite and >= 0)");
    }
}

template <class T>
static void requireFiniteReferenceImpl(const Image<T>& reference, const char* what)
{
    std::size_t bad = 0;
    for (const T& p : reference.pixels)
        bad += isFinite(p) ? 0 : 1;
    if (bad > 0)
        throw std::invalid_argument(std::string(what) + ": the reference image has " +
                                    std::to_string(bad) +
                                    " pixels with NaN or infinite values; a reference must be "
                                    "finite");
}

void requireFiniteReference(const Image<float>& reference, const char* what)
{
    requireFiniteReferenceImpl(reference, what);
}

void requireFiniteReference(const Image<glm::vec3>& reference, const char* what)
{
    requireFiniteReferenceImpl(reference, what);
}

void forEachRowBlock(int height, const std::function<void(int y0, int y1)>& body)
{
    if (height <= 0)
        return;
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 8),
                      [&](const tbb::blocked_range<int>& r) { body(r.begin(), r.end()); });
}

WeightedMean computeWeightedMean(int width, int height, MaskView mask,
                                 const std::function<double(std::size_t)>& value)
{
    std::vector<double> rowSum(std::size_t(std::max(height, 0)), 0.0);
    std::vector<double> rowWeight(rowSum.size(), 0.0);
    std::vector<std::size_t> rowCount(rowSum.size(), 0);
    forEachRowBlock(height, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            double sum = 0, weight = 0;
            std::size_t count = 0;
            for (int x = 0; x < width; ++x) {
                const std::size_t i = std::size_t(y) * width + x;
                const double w = mask.weight(i);
                if (w <= 0)
                    continue;
                sum += w * value(i);
                weight += w;
                ++count;
            }
            rowSum[y] = sum;
            rowWeight[y] = weight;
            rowCount[y] = count;
        }
    });
    WeightedMean result;
    double sum = 0, weight = 0;
    for (std::size_t y = 0; y < rowSum.size(); ++y) {
        sum += rowSum[y];
        weight += rowWeight[y];
        result.pixels += rowCount[y];
    }
    result.mean = weight > 0 ? sum / weight : std::numeric_limits<double>::quiet_NaN();
    return result;
}

Plane filterRows(const Plane& in, const std::vector<float>& k)
{
    const int w = in.width, h = in.height, r = int(k.size() - 1) / 2;
    Plane out(w, h);
    forEachRowBlock(h, [&](int y0, int y1) {
        // Each row is padded with copies of its end pixels, then the taps are accumulated as
        // whole-row multiply-adds (contiguous, so the compiler vectorises them).
        std::vector<float> padded(std::size_t(w + 2 * r));
        for (int y = y0; y < y1; ++y) {
            const float* src = &in.values[std::size_t(y) * w];
            for (int x = -r; x < w + r; ++x)
                padded[std::size_t(x + r)] = src[std::clamp(x, 0, w - 1)];
            float* dst = &out.values[std::size_t(y) * w];
            for (int i = 0; i <= 2 * r; ++i) {
                const float ki = k[std::size_t(i)];
                const float* p = &padded[std::size_t(i)];
                for (int x = 0; x < w; ++x)
                    dst[x] += ki * p[x];
            }
        }
    });
    return out;
}

Plane filterColumns(const Plane& in, const std::vector<float>& k)
{
    const int w = in.width, h = in.height, r = int(k.size() - 1) / 2;
    Plane out(w, h);
    forEachRowBlock(h, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y) {
            float* dst = &out.values[std::size_t(y) * w];
            for (int j = -r; j <= r; ++j) {
                const float kj = k[std::size_t(j + r)];
                const float* src = &in.values[std::size_t(std::clamp(y + j, 0, h - 1)) * w];
                for (int x = 0; x < w; ++x)
                    dst[x] += kj * src[x];
            }
        }
    });
    return out;
}

Plane filterSeparable(const Plane& in, const std::vector<float>& kx, const std::vector<float>& ky)
{
    return filterColumns(filterRows(in, kx), ky);
}

} // namespace detail

// ------------------------------------------------------------------------------------------------
// MaskView

int MaskView::width() const
{
    return mBinary ? mBinary->width : mWeights ? mWeights->width : 0;
}

int MaskView::height() const
{
    return mBinary ? mBinary->height : mWeights ? mWeights->height : 0;
}

double MaskView::weight(std::size_t index) const
{
    if (mBinary)
        return mBinary->pixels[index] != 0 ? 1.0 : 0.0;
    if (mWeights)
        return double(mWeights->pixels[index]);
    return 1.0;
}

std::size_t countMaskPixels(MaskView mask, int width, int height)
{
    detail::requireValidMask(mask, width, height, "countMaskPixels");
    const std::size_t n = std::size_t(std::max(width, 0)) * std::max(height, 0);
    if (mask.isAll())
        return n;
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i)
        count += mask.weight(i) > 0 ? 1 : 0;
    return count;
}

// ------------------------------------------------------------------------------------------------
// Pixel-wise metrics

namespace {

// Channel access shared by scalar and RGB images: per-pixel errors average the channels.
inline int countChannels(float)
{
    return 1;
}
inline int countChannels(const glm::vec3&)
{
    return 3;
}
inline double getChannel(float v, int)
{
    return v;
}
inline double getChannel(const glm::vec3& v, int c)
{
    return v[c];
}

template <class T, class PerChannel>
detail::WeightedMean averageOverPixels(const Image<T>& test, const Image<T>& reference,
                                       MaskView mask, const char* what, PerChannel perChannel)
{
    detail::requireSameSize(test.width, test.height, reference.width, reference.height, what);
    detail::requireValidMask(mask, test.width, test.height, what);
    detail::requireFiniteReference(reference, what);
    return detail::computeWeightedMean(test.width, test.height, mask, [&](std::size_t i) {
        const T& t = test.pixels[i];
        const T& r = reference.pixels[i];
        const int channels = countChannels(t);
        double sum = 0;
        for (int c = 0; c < channels; ++c)
            sum += perChannel(getChannel(t, c), getChannel(r, c));
        return sum / channels;
    });
}

template <class T>
double computeMseImpl(const Image<T>& test, const Image<T>& reference, MaskView mask,
                      const char* what)
{
    return averageOverPixels(test, reference, mask, what,
                             [](double t, double r) { return (t - r) * (t - r); })
        .mean;
}

template <class T>
double computeRelMseImpl(const Image<T>& test, const Image<T>& reference, MaskView mask,
                         double epsilon)
{
    if (!(epsilon > 0))
        throw std::invalid_argument("computeRelativeMse: epsilon must be > 0, got " +
                                    std::to_string(epsilon));
    return averageOverPixels(
               test, reference, mask, "computeRelativeMse",
               [epsilon](double t, double r) { return (t - r) * (t - r) / (r * r + epsilon); })
        .mean;
}

double convertMseToPsnr(double mse, double peak)
{
    if (!(peak > 0) || !std::isfinite(peak))
        throw std::invalid_argument("computePsnr: peak must be finite and > 0, got " +
                                    std::to_string(peak));
    if (std::isnan(mse))
        return mse;
    if (mse == 0)
        return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(peak * peak / mse);
}

template <class T>
double computeMeanSignedErrorImpl(const Image<T>& test, const Image<T>& reference, MaskView mask)
{
    return averageOverPixels(test, reference, mask, "computeMeanSignedError",
                             [](double t, double r) { return t - r; })
        .mean;
}

} // namespace

double computeMse(const Image<float>& test, const Image<float>& reference, MaskView mask)
{
    return computeMseImpl(test, reference, mask, "computeMse");
}

double computeMse(const Image<glm::vec3>& test, const Image<glm::vec3>& reference, MaskView mask)
{
    return computeMseImpl(test, reference, mask, "computeMse");
}

double computeRmse(const Image<float>& test, const Image<float>& reference, MaskView mask)
{
    return std::sqrt(computeMseImpl(test, reference, mask, "computeRmse"));
}

double computeRmse(const Image<glm::vec3>& test, const Image<glm::vec3>& reference, MaskView mask)
{
    return std::sqrt(computeMseImpl(test, reference, mask, "computeRmse"));
}

double computeRelativeMse(const Image<float>& test, const Image<float>& reference, MaskView mask,
                          double epsilon)
{
    return computeRelMseImpl(test, reference, mask, epsilon);
}

double computeRelativeMse(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                          MaskView mask, double epsilon)
{
    return computeRelMseImpl(test, reference, mask, epsilon);
}

double computePsnr(const Image<float>& test, const Image<float>& reference, double peak,
                   MaskView mask)
{
    return convertMseToPsnr(computeMseImpl(test, reference, mask, "computePsnr"), peak);
}

double computePsnr(const Image<glm::vec3>& test, const Image<glm::vec3>& reference, double peak,
                   MaskView mask)
{
    return convertMseToPsnr(computeMseImpl(test, reference, mask, "computePsnr"), peak);
}

double computeMeanSignedError(const Image<float>& test, const Image<float>& reference,
                              MaskView mask)
{
    return computeMeanSignedErrorImpl(test, reference, mask);
}

double computeMeanSignedError(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                              MaskView mask)
{
    return computeMeanSignedErrorImpl(test, reference, mask);
}

// ------------------------------------------------------------------------------------------------
// Everything at once

namespace {

// The worst value a valid image could hold at a pixel whose reference value is r: whichever of
// 0 and peak is farther from r.
inline float pickWorstValue(float r, double peak)
{
    return double(r) >= 0.5 * peak ? 0.0f : float(peak);
}

inline glm::vec3 convertToVec3(float v)
{
    return glm::vec3(v);
}
inline glm::vec3 convertToVec3(const glm::vec3& v)
{
    return v;
}

template <class T> Image<glm::vec3> convertToRgb(const Image<T>& image)
{
    Image<glm::vec3> rgb(image.width, image.height);
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        rgb.pixels[i] = convertToVec3(image.pixels[i]);
    return rgb;
}

template <class T> double findDefaultPeak(const Image<T>& reference, DynamicRange range)
{
    if (range == DynamicRange::Ldr)
        return 1.0;
    double peak = 0;
    for (const T& p : reference.pixels)
        for (int c = 0; c < countChannels(p); ++c)
            peak = std::max(peak, getChannel(p, c));
    return peak > 0 ? peak : 1.0;
}

template <class T>
ImageErrors computeImageErrorsImpl(const Image<T>& testIn, const Image<T>& reference,
                                   const ImageErrorOptions& options, MaskView mask)
{
    const char* what = "computeImageErrors";
    detail::requireSameSize(testIn.width, testIn.height, reference.width, reference.height, what);
    detail::requireValidMask(mask, testIn.width, testIn.height, what);
    detail::requireFiniteReference(reference, what);

    ImageErrors e;
    e.peak = options.peak ? *options.peak : findDefaultPeak(reference, options.range);
    if (!(e.peak > 0) || !std::isfinite(e.peak))
        throw std::invalid_argument("computeImageErrors: peak must be finite and > 0, got " +
                                    std::to_string(e.peak));

    // Non-finite test values: count the selected ones, replace all by the worst valid value.
    Image<T> test = testIn;
    std::vector<std::size_t> nonFinite;
    for (std::size_t i = 0; i < test.pixels.size(); ++i) {
        T& p = test.pixels[i];
        if (detail::isFinite(p))
            continue;
        nonFinite.push_back(i);
        if (mask.weight(i) > 0)
            ++e.nonFinitePixels;
        if constexpr (std::is_same_v<T, float>) {
            p = pickWorstValue(reference.pixels[i], e.peak);
        } else {
            for (int c = 0; c < 3; ++c)
                if (!std::isfinite(p[c]))
                    p[c] = pickWorstValue(reference.pixels[i][c], e.peak);
        }
    }

    const auto mse = averageOverPixels(test, reference, mask, what,
                                       [](double t, double r) { return (t - r) * (t - r); });
    e.pixels = mse.pixels;
    e.rmse = std::sqrt(mse.mean);
    e.psnr = convertMseToPsnr(mse.mean, e.peak);
    e.relMse = computeRelMseImpl(test, reference, mask, options.relMseEpsilon);
    e.meanSignedError = computeMeanSignedErrorImpl(test, reference, mask);

    const double nan = std::numeric_limits<double>::quiet_NaN();
    e.ssim = nan;
    if (options.withSsim) {
        SsimOptions ssim;
        ssim.dynamicRange = e.peak;
        ssim.channels = options.ssimChannels;
        e.ssim = computeSsim(test, reference, ssim, mask).mean;
    }

    e.flip = nan;
    if (options.withFlip) {
        FlipResult flip;
        if (options.range == DynamicRange::Ldr) {
            flip = computeFlip(convertToRgb(test), convertToRgb(reference), options.encoding,
                               options.flip, mask);
        } else {
            flip = computeHdrFlip(convertToRgb(test), convertToRgb(reference), options.flip, mask);
        }
        if (nonFinite.empty()) {
            e.flip = flip.mean;
        } else {
            for (std::size_t i : nonFinite)
                flip.map.pixels[i] = 1.0f;
            e.flip = detail::computeWeightedMean(
                         flip.map.width, flip.map.height, mask,
                         [&](std::size_t i) { return double(flip.map.pixels[i]); })
                         .mean;
        }
    }
    return e;
}

} // namespace

ImageErrors computeImageErrors(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                               const ImageErrorOptions& options, MaskView mask)
{
    return computeImageErrorsImpl(test, reference, options, mask);
}

ImageErrors computeImageErrors(const Image<float>& test, const Image<float>& reference,
                               const ImageErrorOptions& options, MaskView mask)
{
    return computeImageErrorsImpl(test, reference, options, mask);
}

} // namespace rtlab::metrics
