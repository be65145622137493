#include "metrics/temporal_metrics.h"

#include "core/error.h"
#include "plugin/screen_space.h"

#include <glm/mat3x3.hpp>
#include <glm/matrix.hpp>
#include <glm/vec4.hpp>

#include <cmath>
#include <limits>
#include <string>

namespace rtlab::metrics {

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

//! Sums that pool over pixels and frame pairs.
struct ChangeSums {
    double technique2 = 0.0;
    double reference2 = 0.0;
    double flicker2 = 0.0;
    double technique = 0.0;
    double noise2 = 0.0;
    bool hasNoise = true;
    std::int64_t candidates = 0;
    std::int64_t used = 0;
    std::int64_t offScreen = 0;
    std::int64_t disoccluded = 0;

    void add(const ChangeSums& o)
    {
        technique2 += o.technique2;
        reference2 += o.reference2;
        flicker2 += o.flicker2;
        technique += o.technique;
        noise2 += o.noise2;
        hasNoise = hasNoise && o.hasNoise;
        candidates += o.candidates;
        used += o.used;
        offScreen += o.offScreen;
        disoccluded += o.disoccluded;
    }

    TemporalChange finish() const
    {
        TemporalChange c;
        const double n = double(used);
        c.techniqueChangeRms = used ? std::sqrt(technique2 / n) : kNaN;
        c.referenceChangeRms = used ? std::sqrt(reference2 / n) : kNaN;
        c.flickerRms = used ? std::sqrt(flicker2 / n) : kNaN;
        c.techniqueChangeMean = used ? technique / n : kNaN;
        c.referenceNoiseFloorRms = used && hasNoise ? std::sqrt(noise2 / n) : kNaN;
        c.candidatePixels = candidates;
        c.usedPixels = used;
        c.offScreenPixels = offScreen;
        c.disoccludedPixels = disoccluded;
        c.usedShare = candidates ? double(used) / double(candidates) : 0.0;
        return c;
    }
};

template <class T>
void checkImage(const Image<T>* image, int w, int h, const char* frame, const char* name,
                bool required)
{
    if (!image) {
        if (required)
            throw Error(std::string("temporal metrics: the ") + frame + " frame has no " + name +
                        " image");
        return;
    }
    if (image->width != w || image->height != h ||
        image->pixels.size() != std::size_t(w) * std::size_t(h))
        throw Error(std::string("temporal metrics: the ") + frame + " frame's " + name +
                    " image is " + std::to_string(image->width) + "x" +
                    std::to_string(image->height) + " but its depth is " + std::to_string(w) + "x" +
                    std::to_string(h));
}

void checkFrame(const TemporalFrame& f, const char* which)
{
    if (!f.linearDepth)
        throw Error(std::string("temporal metrics: the ") + which + " frame has no depth image");
    const int w = f.linearDepth->width;
    const int h = f.linearDepth->height;
    if (w <= 0 || h <= 0 || f.linearDepth->pixels.size() != std::size_t(w) * std::size_t(h))
        throw Error(std::string("temporal metrics: the ") + which + " frame's depth is empty");
    checkImage(f.technique, w, h, which, "technique", true);
    checkImage(f.reference, w, h, which, "reference", true);
    checkImage(f.worldPosition, w, h, which, "world position", false);
    checkImage(f.referenceStdErr, w, h, which, "reference standard error", false);
    checkImage(f.mask, w, h, which, "mask", false);
}

//! ScreenProjection::toView and toPixel in double precision.
glm::dvec3 toView(const plugin::ScreenProjection& p, double x, double y, double depth)
{
    const double ndcX = 2.0 * x / p.size.x - 1.0;
    const double ndcY = 2.0 * y / p.size.y - 1.0;
    return {depth * (ndcX + p.offset.x) / p.scale.x, depth * (ndcY + p.offset.y) / p.scale.y,
            -depth};
}

glm::dvec2 toPixel(const plugin::ScreenProjection& p, const glm::dvec3& v)
{
    const double depth = -v.z;
    const double ndcX = v.x * p.scale.x / depth - p.offset.x;
    const double ndcY = v.y * p.scale.y / depth - p.offset.y;
    return {(ndcX + 1.0) * 0.5 * p.size.x, (ndcY + 1.0) * 0.5 * p.size.y};
}

bool hasSurface(float depth)
{
    return std::isfinite(depth) && depth > 0.0f;
}

ChangeSums accumulate(const TemporalFrame& previous, const TemporalFrame& current,
                      const TemporalOptions& options, TemporalChangeImages* images)
{
    checkFrame(previous, "previous");
    checkFrame(current, "current");
    if (!(options.depthTolerance > 0.0))
        throw Error("temporal metrics: depthTolerance must be > 0, got " +
                    std::to_string(options.depthTolerance));
    const int w = current.linearDepth->width;
    const int h = current.linearDepth->height;
    const int pw = previous.linearDepth->width;
    const int ph = previous.linearDepth->height;
    const auto projection = plugin::ScreenProjection::fromMatrix(current.projection, w, h);
    const auto previousProjection =
        plugin::ScreenProjection::fromMatrix(previous.projection, pw, ph);
    const glm::dmat4 currentToWorld = glm::inverse(glm::dmat4(current.view));
    const glm::dmat4 worldToPrevious(previous.view);
    const bool noise = current.referenceStdErr && previous.referenceStdErr;
    if (images) {
        images->techniqueChange = Image<float>(w, h, float(kNaN));
        images->flicker = Image<float>(w, h, float(kNaN));
    }

    ChangeSums sums;
    sums.hasNoise = noise;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const float depth = current.linearDepth->pixels[i];
            if (!hasSurface(depth) || (current.mask && !current.mask->pixels[i]))
                continue;
            ++sums.candidates;
            glm::dvec3 world;
            if (current.worldPosition) {
                world = glm::dvec3(current.worldPosition->pixels[i]);
            } else {
                const glm::dvec3 v = toView(projection, x + 0.5, y + 0.5, depth);
                world = glm::dvec3(currentToWorld * glm::dvec4(v, 1.0));
            }
            const glm::dvec3 v = glm::dvec3(worldToPrevious * glm::dvec4(world, 1.0));
            const double expectedDepth = -v.z;
            if (!(expectedDepth > 0.0)) {
                ++sums.offScreen;
                continue;
            }
            const glm::dvec2 pixel = toPixel(previousProjection, v);
            const double px = std::floor(pixel.x);
            const double py = std::floor(pixel.y);
            if (!(px >= 0.0 && py >= 0.0 && px < pw && py < ph)) {
                ++sums.offScreen;
                continue;
            }
            const std::size_t j = std::size_t(py) * std::size_t(pw) + std::size_t(px);
            const float previousDepth = previous.linearDepth->pixels[j];
            if (!hasSurface(previousDepth) || std::abs(double(previousDepth) - expectedDepth) >
                                                  options.depthTolerance * expectedDepth) {
                ++sums.disoccluded;
                continue;
            }
            const double technique =
                double(current.technique->pixels[i]) - double(previous.technique->pixels[j]);
            const double reference =
                double(current.reference->pixels[i]) - double(previous.reference->pixels[j]);
            const double flicker = technique - reference;
            ++sums.used;
            sums.technique2 += technique * technique;
            sums.reference2 += reference * reference;
            sums.flicker2 += flicker * flicker;
            sums.technique += technique;
            if (noise) {
                const double a = current.referenceStdErr->pixels[i];
                const double b = previous.referenceStdErr->pixels[j];
                sums.noise2 += a * a + b * b;
            }
            if (images) {
                images->techniqueChange.pixels[i] = float(technique);
                images->flicker.pixels[i] = float(flicker);
            }
        }
    }
    return sums;
}

} // namespace

TemporalChange computeTemporalChange(const TemporalFrame& previous, const TemporalFrame& current,
                                     const TemporalOptions& options, TemporalChangeImages* images)
{
    return accumulate(previous, current, options, images).finish();
}

TemporalSummary computeTemporalSummary(const std::vector<TemporalFrame>& frames,
                                       const TemporalOptions& options)
{
    TemporalSummary summary;
    ChangeSums pooled;
    for (std::size_t k = 1; k < frames.size(); ++k) {
        const ChangeSums sums = accumulate(frames[k - 1], frames[k], options, nullptr);
        summary.pairs.push_back(sums.finish());
        pooled.add(sums);
    }
    if (frames.size() < 2)
        pooled.hasNoise = false;
    summary.pooled = pooled.finish();
    return summary;
}

} // namespace rtlab::metrics
