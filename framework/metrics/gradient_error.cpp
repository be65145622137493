#include "gradient_error.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rtlab::metrics {
namespace {

bool hasSurface(float depth)
{
    return std::isfinite(depth) && depth > 0.0f;
}

template <class A, class B>
void requireSameSize(const A& a, const B& b, const char* what)
{
    if (a.width != b.width || a.height != b.height)
        throw std::invalid_argument(std::string(what) + ": images of different sizes (" +
                                    std::to_string(a.width) + "x" + std::to_string(a.height) +
                                    " and " + std::to_string(b.width) + "x" +
                                    std::to_string(b.height) + ")");
}

bool isFinite(const glm::vec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

} // namespace

Image<std::uint8_t> makeSmoothPairMask(const Image<float>& depth, const Image<glm::vec3>& normal,
                                       double relativeJump, double minCosine)
{
    if (!(relativeJump > 0.0))
        throw std::invalid_argument("makeSmoothPairMask: relativeJump must be > 0, got " +
                                    std::to_string(relativeJump));
    if (!(minCosine >= -1.0 && minCosine <= 1.0))
        throw std::invalid_argument("makeSmoothPairMask: minCosine must be in [-1, 1], got " +
                                    std::to_string(minCosine));
    requireSameSize(depth, normal, "makeSmoothPairMask");
    Image<std::uint8_t> mask(depth.width, depth.height, 0);
    const auto smooth = [&](int x0, int y0, int x1, int y1) {
        const float d0 = depth.at(x0, y0);
        const float d1 = depth.at(x1, y1);
        if (!hasSurface(d0) || !hasSurface(d1))
            return false;
        if (std::abs(double(d0) - double(d1)) > relativeJump * std::min(double(d0), double(d1)))
            return false;
        return double(glm::dot(normal.at(x0, y0), normal.at(x1, y1))) >= minCosine;
    };
    for (int y = 0; y < depth.height; ++y)
        for (int x = 0; x < depth.width; ++x) {
            std::uint8_t bits = 0;
            if (x + 1 < depth.width && smooth(x, y, x + 1, y))
                bits |= 1u;
            if (y + 1 < depth.height && smooth(x, y, x, y + 1))
                bits |= 2u;
            mask.at(x, y) = bits;
        }
    return mask;
}

LabelledPairs splitPairsByLabel(const Image<std::uint8_t>& smoothPairs,
                                const Image<std::uint8_t>& labels, std::uint8_t none)
{
    requireSameSize(smoothPairs, labels, "splitPairsByLabel");
    LabelledPairs out{Image<std::uint8_t>(labels.width, labels.height, 0),
                      Image<std::uint8_t>(labels.width, labels.height, 0)};
    for (int y = 0; y < labels.height; ++y)
        for (int x = 0; x < labels.width; ++x) {
            const std::uint8_t bits = smoothPairs.at(x, y);
            const std::uint8_t a = labels.at(x, y);
            if (a == none)
                continue;
            for (int k = 0; k < 2; ++k) {
                const int x1 = x + (k == 0), y1 = y + (k == 1);
                if (((bits >> k) & 1u) == 0 || x1 >= labels.width || y1 >= labels.height)
                    continue;
                const std::uint8_t b = labels.at(x1, y1);
                if (b == none)
                    continue;
                (a == b ? out.within : out.across).at(x, y) |= std::uint8_t(1u << k);
            }
        }
    return out;
}

GradientError computeGradientError(const Image<glm::vec3>& test,
                                   const Image<glm::vec3>& reference,
                                   const Image<glm::vec3>* referenceStdErr,
                                   const Image<std::uint8_t>& smoothPairs)
{
    requireSameSize(test, reference, "computeGradientError");
    requireSameSize(test, smoothPairs, "computeGradientError");
    if (referenceStdErr != nullptr)
        requireSameSize(test, *referenceStdErr, "computeGradientError");
    double squared = 0.0;
    double noise = 0.0;
    std::size_t pairs = 0;
    const auto add = [&](int x0, int y0, int x1, int y1) {
        const glm::vec3 t0 = test.at(x0, y0), t1 = test.at(x1, y1);
        const glm::vec3 r0 = reference.at(x0, y0), r1 = reference.at(x1, y1);
        if (!isFinite(t0) || !isFinite(t1) || !isFinite(r0) || !isFinite(r1))
            return;
        const glm::dvec3 d = (glm::dvec3(t0) - glm::dvec3(t1)) - (glm::dvec3(r0) - glm::dvec3(r1));
        squared += glm::dot(d, d) / 3.0;
        if (referenceStdErr != nullptr) {
            const glm::dvec3 s0(referenceStdErr->at(x0, y0)), s1(referenceStdErr->at(x1, y1));
            const double v = (glm::dot(s0, s0) + glm::dot(s1, s1)) / 3.0;
            if (std::isfinite(v))
                noise += v;
        }
        ++pairs;
    };
    for (int y = 0; y < test.height; ++y)
        for (int x = 0; x < test.width; ++x) {
            const std::uint8_t bits = smoothPairs.at(x, y);
            if ((bits & 1u) && x + 1 < test.width)
                add(x, y, x + 1, y);
            if ((bits & 2u) && y + 1 < test.height)
                add(x, y, x, y + 1);
        }
    GradientError e;
    e.pairs = pairs;
    if (pairs == 0)
        return e;
    const double mse = squared / double(pairs);
    const double floor = noise / double(pairs);
    e.rmse = std::sqrt(mse);
    e.noiseFloor = std::sqrt(floor);
    e.excess = std::sqrt(std::max(0.0, mse - floor));
    return e;
}

} // namespace rtlab::metrics
