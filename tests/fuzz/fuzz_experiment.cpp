// Fuzz target: experiment files (experiment::parseExperiment) against a registry holding the
// three families' shapes (volume and screen domains) and techniques with every parameter type.

#include "experiment/experiment.h"
#include "fuzz_support.h"
#include "plugin/technique.h"

namespace {

using namespace rtlab;

class Dummy final : public plugin::Technique {
public:
    explicit Dummy(const config::ParamSet& p) : mParams(p) {}
    config::ParamSet effectiveParams() const override { return mParams; }

private:
    config::ParamSet mParams;
};

plugin::Registry makeRegistry()
{
    plugin::Registry r;
    const std::pair<const char*, plugin::FamilyDomain> families[] = {
        {"isosurface", plugin::FamilyDomain::Volume},
        {"occlusion", plugin::FamilyDomain::Screen},
        {"voxel_gi", plugin::FamilyDomain::Screen}};
    for (const auto& [name, domain] : families) {
        plugin::FamilyInfo f;
        f.name = name;
        f.domain = domain;
        f.metrics = {{"error", "errors"}, {"flicker", "flicker"}};
        r.addFamily(f);
        for (const char* technique : {"alpha", "beta"}) {
            plugin::TechniqueEntry e;
            e.info.name = technique;
            e.info.family = name;
            e.schema.addInt("count", 8, 1, 64, "", "an int");
            e.schema.addFloat("radius", 1.0, 0.0, 1e9, "world units", "a float");
            e.schema.addBool("jitter", true, "a bool");
            e.schema.addEnum("mode", "fast", {"fast", "exact"}, "an enum");
            e.create = [](const config::ParamSet& p) { return std::make_unique<Dummy>(p); };
            r.addTechnique(std::move(e));
        }
    }
    return r;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    static const plugin::Registry registry = makeRegistry();
    const std::string text(reinterpret_cast<const char*>(data), size);
    return fuzz::runExpectingOnlyRtlabErrors([&] { experiment::parseExperiment(text, "fuzz.yaml", registry); });
}
