#pragma once
// Deterministic image generators for the image metric tests.

#include "core/image.h"

#include <glm/vec3.hpp>

#include <cmath>
#include <cstdint>
#include <random>

namespace rtlab::metrics::testing {

//! Uniform [0, 1) from the standard-specified mt19937, so results match on every platform.
class TestRandom {
public:
    explicit TestRandom(std::uint32_t seed) : mEngine(seed) {}
    double uniform() { return (double(mEngine()) + 0.5) / 4294967296.0; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    //! Standard normal by Box-Muller.
    double normal()
    {
        const double u1 = uniform(), u2 = uniform();
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
    }

private:
    std::mt19937 mEngine;
};

inline Image<float> makeRandomScalar(int w, int h, std::uint32_t seed, double lo, double hi)
{
    TestRandom rng(seed);
    Image<float> image(w, h);
    for (float& p : image.pixels)
        p = float(rng.uniform(lo, hi));
    return image;
}

inline Image<glm::vec3> makeRandomRgb(int w, int h, std::uint32_t seed, double lo, double hi)
{
    TestRandom rng(seed);
    Image<glm::vec3> image(w, h);
    for (glm::vec3& p : image.pixels)
        p = glm::vec3(float(rng.uniform(lo, hi)), float(rng.uniform(lo, hi)),
                      float(rng.uniform(lo, hi)));
    return image;
}

//! A smooth colourful pattern in [0.2, 0.8]: sinusoids of a few pixels' period.
inline Image<glm::vec3> makePattern(int w, int h)
{
    Image<glm::vec3> image(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            image.at(x, y) = glm::vec3(0.5f + 0.3f * float(std::sin(0.31 * x + 0.17 * y)),
                                       0.5f + 0.3f * float(std::cos(0.23 * x - 0.29 * y)),
                                       0.5f + 0.3f * float(std::sin(0.11 * x * y / 7.0)));
    return image;
}

} // namespace rtlab::metrics::testing
