#pragma once
// Shared by the SDF evaluator's tests: brute force with nothing of the evaluator, the bit-identity
// check against it, random edit lists, the gallery and the landscape, cube grids.

#include "sdf/evaluator.h"

#include "scene/procedural.h"

#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace rtlab::sdf::testing {

using scene::CsgEdit;
using scene::CsgOp;
using scene::CsgShape;
using scene::SdfModel;

inline bool isSameDouble(double a, double b)
{
    return std::memcmp(&a, &b, sizeof(double)) == 0 || (std::isnan(a) && std::isnan(b));
}

inline bool isSameFloat(float a, float b)
{
    return std::memcmp(&a, &b, sizeof(float)) == 0 || (std::isnan(a) && std::isnan(b));
}

// Brute force with nothing of the evaluator: SdfModel::evaluate at SampledField::position.
inline std::vector<double> evaluateRaw(const SdfModel& model, const SampledField& f, int frame)
{
    std::vector<double> out(f.values.size());
    for (int z = 0; z < f.samples.z; ++z)
        for (int y = 0; y < f.samples.y; ++y)
            for (int x = 0; x < f.samples.x; ++x)
                out[f.index(x, y, z)] = model.evaluate(f.position(x, y, z), frame);
    return out;
}

// Exact (bit-identical) where |d| <= band, clamped with the right sign elsewhere; the stored
// floats are the clamped doubles' toFieldValue().
inline void expectMatchesBruteForce(const SdfModel& model, const GridSpec& grid, int frame,
                                    EvaluationOptions options = {}, const std::string& what = "")
{
    options.keepExactValues = true;
    const EvaluationResult r = evaluateModel(model, grid, frame, options);
    const std::vector<double> raw = evaluateRaw(model, r.field, frame);
    std::size_t mismatches = 0, inBand = 0;
    std::ostringstream first;
    for (std::size_t i = 0; i < raw.size(); ++i) {
        const double expected = clampToBand(raw[i], r.band);
        inBand += std::abs(raw[i]) <= r.band ? 1 : 0;
        if (!isSameDouble(r.exactValues[i], expected) ||
            !isSameFloat(r.field.values[i], toFieldValue(expected))) {
            if (mismatches++ < 3)
                first << " [" << i << "] got " << r.exactValues[i] << " expected " << expected
                      << " (raw " << raw[i] << ")";
        }
    }
    EXPECT_EQ(mismatches, 0u) << what << " " << model.name << " frame " << frame << " samples "
                              << grid.samples.x << ":" << first.str();
    EXPECT_EQ(r.stats.samplesInBand, inBand) << what << " " << model.name;
}

inline glm::dquat makeRandomRotation(std::mt19937& rng)
{
    std::normal_distribution<double> n(0.0, 1.0);
    const glm::dquat q(n(rng), n(rng), n(rng), n(rng));
    return glm::normalize(q);
}

// A random edit list in [-1, 1]^3: every shape, op and soft blend, rotations, frames 0..3.
inline SdfModel makeRandomModel(unsigned seed, int editCount, double anisotropy = 3.0)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    SdfModel m;
    m.name = "random_" + std::to_string(seed);
    m.boundsMin = glm::dvec3(-1.2);
    m.boundsMax = glm::dvec3(1.2);
    for (int i = 0; i < editCount; ++i) {
        CsgEdit e;
        e.shape = CsgShape(int(u(rng) * 8.0) % 8);
        const double r = u(rng);
        e.op = i == 0 || r < 0.55 ? CsgOp::Add : (r < 0.85 ? CsgOp::Subtract : CsgOp::Intersect);
        e.center = glm::dvec3(u(rng), u(rng), u(rng)) * 1.6 - 0.8;
        const double base = 0.1 + 0.4 * u(rng);
        e.size =
            base * glm::dvec3(1.0 + (anisotropy - 1.0) * u(rng), 1.0 + (anisotropy - 1.0) * u(rng),
                              1.0 + (anisotropy - 1.0) * u(rng));
        e.rounding = e.shape == CsgShape::RoundedBox
                         ? 0.9 * u(rng) * std::min({e.size.x, e.size.y, e.size.z})
                         : 0.0;
        e.rotation = u(rng) < 0.7 ? makeRandomRotation(rng) : glm::dquat(1, 0, 0, 0);
        e.blend = u(rng) < 0.5 ? 0.0 : 0.02 + 0.4 * u(rng);
        e.material = std::uint32_t(u(rng) * 6.0);
        e.frame = u(rng) < 0.3 ? int(u(rng) * 4.0) : 0;
        m.edits.push_back(e);
    }
    return m;
}

inline const SdfModel& getLandscape()
{
    static const SdfModel land = [] {
        for (auto& m : scene::makeTomorrowTown().sdfModels)
            if (m.name == "landscape")
                return m;
        return SdfModel{};
    }();
    return land;
}

inline const std::vector<SdfModel>& getGallery()
{
    static const std::vector<SdfModel> models = scene::makeCsgGallery().sdfModels;
    return models;
}

inline GridSpec makeCubeGrid(double lo, double hi, int samples)
{
    GridSpec g;
    g.origin = glm::dvec3(lo);
    g.spacing = (hi - lo) / double(samples - 1);
    g.samples = glm::ivec3(samples);
    return g;
}

} // namespace rtlab::sdf::testing
