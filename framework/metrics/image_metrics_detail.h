#pragma once
// Helpers shared by the image metric sources. Not part of the public interface.

#include "metrics/image_metrics.h"

#include <cmath>
#include <cstddef>
#include <functional>
#include <vector>

namespace rtlab::metrics::detail {

//! Throws std::invalid_argument "<what>: test image is WxH but the reference is WxH".
void requireSameSize(int testWidth, int testHeight, int refWidth, int refHeight, const char* what);
//! Throws std::invalid_argument when the mask's size differs or a weight is negative/non-finite.
void requireValidMask(MaskView mask, int width, int height, const char* what);
//! Throws std::invalid_argument when the reference holds a NaN or infinite value.
void requireFiniteReference(const Image<float>& reference, const char* what);
void requireFiniteReference(const Image<glm::vec3>& reference, const char* what);

//! Runs body(y0, y1) over [0, height) in parallel blocks of rows.
void forEachRowBlock(int height, const std::function<void(int y0, int y1)>& body);

struct WeightedMean {
    double mean = 0;        //!< NaN when no pixel has a positive weight
    std::size_t pixels = 0; //!< pixels with a positive weight
};

//! Weighted mean of value(i) over the pixels i of a width x height image. Rows are summed in
//! parallel and the row sums added in order, so the result does not depend on the thread count.
//! Pixels with weight 0 are skipped entirely (their value is not evaluated).
WeightedMean computeWeightedMean(int width, int height, MaskView mask,
                                 const std::function<double(std::size_t)>& value);

inline bool isFinite(float v)
{
    return std::isfinite(v);
}
inline bool isFinite(const glm::vec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

//! A planar single-channel image used by the filters.
struct Plane {
    int width = 0;
    int height = 0;
    std::vector<float> values;

    Plane() = default;
    Plane(int w, int h) : width(w), height(h), values(std::size_t(w) * h, 0.0f) {}
    float& at(int x, int y) { return values[std::size_t(y) * width + x]; }
    float at(int x, int y) const { return values[std::size_t(y) * width + x]; }
};

//! Correlation along rows with clamp-to-edge borders: out(x, y) = sum_i k[i] in(clamp(x + i - r),
//! y), r = (k.size() - 1) / 2 (odd sizes).
Plane filterRows(const Plane& in, const std::vector<float>& k);
//! The same along columns.
Plane filterColumns(const Plane& in, const std::vector<float>& k);
//! Separable correlation: filterColumns(filterRows(in, kx), ky).
Plane filterSeparable(const Plane& in, const std::vector<float>& kx, const std::vector<float>& ky);

} // namespace rtlab::metrics::detail
