// SSIM after Wang, Bovik, Sheikh, Simoncelli, "Image Quality Assessment: From Error Visibility to
// Structural Similarity", IEEE Trans. Image Processing 13(4), 2004.
#include "metrics/image_metrics.h"

#include "metrics/image_metrics_detail.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rtlab::metrics {

namespace {

// Double-precision planes: the variance E[x^2] - E[x]^2 cancels badly in float.
struct DoublePlane {
    int width = 0;
    int height = 0;
    std::vector<double> values;
};

// Gaussian-weighted local mean with the window clipped to the image and renormalised over the
// part inside it. The 2D window is the product of two 1D windows and the clipped region is a
// rectangle, so the renormalised 2D filter is the product of two renormalised 1D filters.
DoublePlane computeLocalMean(const DoublePlane& in, const std::vector<double>& g)
{
    const int w = in.width, h = in.height, r = int(g.size() - 1) / 2;
    DoublePlane tmp{w, h, std::vector<double>(in.values.size())};
    DoublePlane out{w, h, std::vector<double>(in.values.size())};
    detail::forEachRowBlock(h, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0, norm = 0;
                for (int i = std::max(-r, -x); i <= std::min(r, w - 1 - x); ++i) {
                    sum += g[std::size_t(i + r)] * in.values[std::size_t(y) * w + x + i];
                    norm += g[std::size_t(i + r)];
                }
                tmp.values[std::size_t(y) * w + x] = sum / norm;
            }
    });
    detail::forEachRowBlock(h, [&](int y0, int y1) {
        for (int y = y0; y < y1; ++y)
            for (int x = 0; x < w; ++x) {
                double sum = 0, norm = 0;
                for (int j = std::max(-r, -y); j <= std::min(r, h - 1 - y); ++j) {
                    sum += g[std::size_t(j + r)] * tmp.values[std::size_t(y + j) * w + x];
                    norm += g[std::size_t(j + r)];
                }
                out.values[std::size_t(y) * w + x] = sum / norm;
            }
    });
    return out;
}

// SSIM map of one channel, added into `accum` with weight `scale`.
void accumulateSsimMap(const DoublePlane& x, const DoublePlane& y, const SsimOptions& o,
                       double scale, std::vector<double>& accum)
{
    // [Wang et al. 2004, Sec. III-C] circular-symmetric Gaussian weighting, sigma 1.5, 11 x 11.
    std::vector<double> g(std::size_t(2 * o.radius + 1));
    for (int i = -o.radius; i <= o.radius; ++i)
        g[std::size_t(i + o.radius)] = std::exp(-double(i * i) / (2.0 * o.sigma * o.sigma));

    const std::size_t n = x.values.size();
    DoublePlane xx{x.width, x.height, std::vector<double>(n)};
    DoublePlane yy = xx, xy = xx;
    for (std::size_t i = 0; i < n; ++i) {
        xx.values[i] = x.values[i] * x.values[i];
        yy.values[i] = y.values[i] * y.values[i];
        xy.values[i] = x.values[i] * y.values[i];
    }
    const DoublePlane muX = computeLocalMean(x, g), muY = computeLocalMean(y, g);
    const DoublePlane mXX = computeLocalMean(xx, g), mYY = computeLocalMean(yy, g);
    const DoublePlane mXY = computeLocalMean(xy, g);

    // [Wang et al. 2004, Sec. III-B]: C1 = (K1 L)^2, C2 = (K2 L)^2.
    const double c1 = (o.k1 * o.dynamicRange) * (o.k1 * o.dynamicRange);
    const double c2 = (o.k2 * o.dynamicRange) * (o.k2 * o.dynamicRange);
    for (std::size_t i = 0; i < n; ++i) {
        const double mx = muX.values[i], my = muY.values[i];
        // [Wang et al. 2004, Eqs. (14)-(16)] weighted local statistics.
        const double vx = std::max(0.0, mXX.values[i] - mx * mx);
        const double vy = std::max(0.0, mYY.values[i] - my * my);
        const double cov = mXY.values[i] - mx * my;
        // [Wang et al. 2004, Eq. (13)].
        const double ssim =
            ((2 * mx * my + c1) * (2 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2));
        accum[i] += scale * ssim;
    }
}

void requireValidOptions(const SsimOptions& o)
{
    if (!(o.dynamicRange > 0) || !std::isfinite(o.dynamicRange) || !(o.k1 > 0) || !(o.k2 > 0) ||
        !(o.sigma > 0) || o.radius < 0)
        throw std::invalid_argument("computeSsim: invalid options (need dynamicRange, k1, k2, "
                                    "sigma > 0 and radius >= 0); dynamicRange = " +
                                    std::to_string(o.dynamicRange));
}

SsimResult finishSsim(int width, int height, const std::vector<double>& accum, MaskView mask)
{
    SsimResult result;
    result.map = Image<float>(width, height);
    for (std::size_t i = 0; i < accum.size(); ++i)
        result.map.pixels[i] = float(accum[i]);
    // The mean is taken over the double-precision map.
    const auto mean =
        detail::computeWeightedMean(width, height, mask, [&](std::size_t i) { return accum[i]; });
    result.mean = mean.mean;
    result.pixels = mean.pixels;
    return result;
}

} // namespace

SsimResult computeSsim(const Image<float>& test, const Image<float>& reference,
                       const SsimOptions& options, MaskView mask)
{
    detail::requireSameSize(test.width, test.height, reference.width, reference.height,
                            "computeSsim");
    detail::requireValidMask(mask, test.width, test.height, "computeSsim");
    detail::requireFiniteReference(reference, "computeSsim");
    requireValidOptions(options);
    const std::size_t n = test.pixels.size();
    DoublePlane x{test.width, test.height, std::vector<double>(n)};
    DoublePlane y = x;
    for (std::size_t i = 0; i < n; ++i) {
        x.values[i] = test.pixels[i];
        y.values[i] = reference.pixels[i];
    }
    std::vector<double> accum(n, 0.0);
    accumulateSsimMap(x, y, options, 1.0, accum);
    return finishSsim(test.width, test.height, accum, mask);
}

SsimResult computeSsim(const Image<glm::vec3>& test, const Image<glm::vec3>& reference,
                       const SsimOptions& options, MaskView mask)
{
    detail::requireSameSize(test.width, test.height, reference.width, reference.height,
                            "computeSsim");
    detail::requireValidMask(mask, test.width, test.height, "computeSsim");
    detail::requireFiniteReference(reference, "computeSsim");
    requireValidOptions(options);
    const std::size_t n = test.pixels.size();
    std::vector<double> accum(n, 0.0);
    DoublePlane x{test.width, test.height, std::vector<double>(n)};
    DoublePlane y = x;
    if (options.channels == SsimChannels::Luminance) {
        // Rec. 709 / sRGB luminance weights.
        const auto luminance = [](const glm::vec3& c) {
            return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        };
        for (std::size_t i = 0; i < n; ++i) {
            x.values[i] = luminance(test.pixels[i]);
            y.values[i] = luminance(reference.pixels[i]);
        }
        accumulateSsimMap(x, y, options, 1.0, accum);
    } else {
        for (int c = 0; c < 3; ++c) {
            for (std::size_t i = 0; i < n; ++i) {
                x.values[i] = test.pixels[i][c];
                y.values[i] = reference.pixels[i][c];
            }
            accumulateSsimMap(x, y, options, 1.0 / 3.0, accum);
        }
    }
    return finishSsim(test.width, test.height, accum, mask);
}

} // namespace rtlab::metrics
