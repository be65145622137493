#pragma once
// Stress cases: a family's hostile inputs (degenerate and huge geometry, extreme parameters,
// coordinates far from the origin, empty and full inputs, closed forms, randomised inputs from a
// seed), each a function that runs one technique and says what it found. The family declares
// them (FamilyInfo::stressCases); `rtlab stress` runs every registered technique through them and
// the family suites (tests/families/*_suite_test.cpp) assert that every case passes, so a new
// technique is stressed by registering and a stub technique fails (tests/families/stress_test.cpp).

#include "core/error.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace rtlab::gpu {
class Context;
} // namespace rtlab::gpu

namespace rtlab::plugin {

struct TechniqueEntry;

//! What a case may use.
struct StressSettings {
    //! The Vulkan device: cases of techniques with a GPU path run it too (and compare it with
    //! the C++ path where the family requires parity). Null: C++ paths only.
    gpu::Context* gpu = nullptr;
    //! Seeds the randomised cases; the same seed gives the same inputs.
    std::uint64_t seed = 1;
};

//! What one case found for one technique.
struct StressOutcome {
    std::size_t values = 0;     //!< output values checked
    std::size_t nonFinite = 0;  //!< NaN or inf among them
    std::size_t outOfRange = 0; //!< finite, but outside the family's range or the case's bounds
    //! The worst deviation from the case's closed form, in the case's unit (NaN: no closed form)
    //! and the deviation allowed. A case with several closed forms keeps the one with the largest
    //! deviation / tolerance.
    double deviation = std::numeric_limits<double>::quiet_NaN();
    double tolerance = std::numeric_limits<double>::quiet_NaN();
    std::vector<std::string> failures; //!< one line per failed check; empty: the case passed
    //! What a passing case wants said: e.g. that the technique refused the input with a clear
    //! error, which cases of invalid input accept in place of an output.
    std::string note;

    bool passed() const { return failures.empty(); }

    //! Counts `count` output values, `nonFiniteCount` of them NaN or inf and `outOfRangeCount`
    //! finite but out of range; any bad value is a failure described by `what`.
    void countValues(std::size_t count, std::size_t nonFiniteCount, std::size_t outOfRangeCount,
                     const std::string& what)
    {
        values += count;
        nonFinite += nonFiniteCount;
        outOfRange += outOfRangeCount;
        if (nonFiniteCount > 0)
            fail(what + ": " + std::to_string(nonFiniteCount) + " NaN/inf value(s)");
        if (outOfRangeCount > 0)
            fail(what + ": " + std::to_string(outOfRangeCount) + " value(s) out of range");
    }
    //! A check: records `what` as a failure unless ok.
    void check(bool ok, const std::string& what)
    {
        if (!ok)
            fail(what);
    }
    //! A closed-form comparison: fails when `dev` (NaN counts as failing) exceeds `tol`.
    void compare(double dev, double tol, const std::string& what)
    {
        const double ratio = std::isfinite(dev) ? dev / tol : std::numeric_limits<double>::infinity();
        const double worst = std::isfinite(deviation) ? deviation / tolerance
                                                      : -std::numeric_limits<double>::infinity();
        if (!std::isfinite(tolerance) || ratio > worst) {
            deviation = std::isfinite(dev) ? dev : std::numeric_limits<double>::infinity();
            tolerance = tol;
        }
        if (!(dev <= tol))
            fail(what + ": deviation " + std::to_string(dev) + " > tolerance " + std::to_string(tol));
    }
    void fail(const std::string& what) { failures.push_back(what); }
};

//! For cases of invalid input (NaN samples, NaN depths, NaN vertices), where refusing the input
//! with a clear error is as good as a valid output: runs `f` and records a refusal by
//! rtlab::Error or std::invalid_argument (what the family interfaces throw for bad arguments) in
//! the outcome's note. Other exceptions propagate: a technique that fails in another way fails.
template <class F> void runOrRefuse(StressOutcome& outcome, F&& f)
{
    try {
        f();
    } catch (const Error& e) {
        outcome.note = std::string("refused: ") + e.what();
    } catch (const std::invalid_argument& e) {
        outcome.note = std::string("refused: ") + e.what();
    }
}

//! One hostile input of a family, applied to any technique of it.
struct StressCase {
    std::string name;        //!< snake_case, unique within the family
    std::string group;       //!< e.g. "degenerate", "scale", "closed_form", "random"
    std::string description; //!< one line: the input and what is checked
    //! Runs a fresh instance of the technique (at its defaults unless the case says otherwise)
    //! on the input and checks its output. May throw: `rtlab stress` records a throw as a
    //! failure with its message.
    std::function<StressOutcome(const TechniqueEntry&, const StressSettings&)> run;
};

} // namespace rtlab::plugin
