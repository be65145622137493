#include "experiment/stress.h"

#include "core/error.h"

#include <algorithm>
#include <chrono>
#include <exception>

namespace rtlab::experiment {
namespace {

std::string join(const std::vector<std::string>& items, const std::string& separator)
{
    std::string out;
    for (const auto& s : items)
        out += (out.empty() ? "" : separator) + s;
    return out;
}

bool isChosen(const std::vector<std::string>& chosen, const std::string& name)
{
    return chosen.empty() || std::find(chosen.begin(), chosen.end(), name) != chosen.end();
}

} // namespace

StressPlan planStress(const plugin::Registry& registry, const StressOptions& options)
{
    std::vector<std::string> withCases;
    for (const auto& name : registry.familyNames())
        if (const auto* f = registry.findFamily(name); f->stressCases)
            withCases.push_back(name);
    for (const auto& f : options.families)
        if (std::find(withCases.begin(), withCases.end(), f) == withCases.end())
            throw Error("--family " + f + ": no such family with stress cases (choices: " + join(withCases, ", ") + ")");

    StressPlan plan;
    std::vector<std::pair<std::string, std::size_t>> firstCase; // family -> index of its first case
    std::vector<std::string> allTechniques, allCases;
    for (const auto& family : withCases) {
        if (!isChosen(options.families, family))
            continue;
        firstCase.emplace_back(family, plan.cases.size());
        for (auto& c : registry.findFamily(family)->stressCases())
            plan.cases.push_back(std::move(c));
    }
    // Items are made after every case is stored, so that the pointers stay valid.
    for (std::size_t f = 0; f < firstCase.size(); ++f) {
        const std::string& family = firstCase[f].first;
        const std::size_t begin = firstCase[f].second;
        const std::size_t end = f + 1 < firstCase.size() ? firstCase[f + 1].second : plan.cases.size();
        for (std::size_t i = begin; i < end; ++i)
            allCases.push_back(plan.cases[i].name);
        for (const plugin::TechniqueEntry* t : registry.techniques(family)) {
            allTechniques.push_back(t->info.name);
            if (!isChosen(options.techniques, t->info.name))
                continue;
            for (std::size_t i = begin; i < end; ++i)
                if (isChosen(options.cases, plan.cases[i].name))
                    plan.items.push_back({t, &plan.cases[i]});
        }
    }
    for (const auto& t : options.techniques)
        if (std::find(allTechniques.begin(), allTechniques.end(), t) == allTechniques.end())
            throw Error("--technique " + t + ": no such technique in the chosen families (choices: " +
                        join(allTechniques, ", ") + ")");
    for (const auto& c : options.cases)
        if (std::find(allCases.begin(), allCases.end(), c) == allCases.end())
            throw Error("--case " + c + ": no such stress case in the chosen families (choices: " + join(allCases, ", ") +
                        ")");
    if (plan.items.empty())
        throw Error("nothing to stress: the chosen families, techniques and cases select no pair");
    return plan;
}

StressRecord runStressItem(const StressPlan::Item& item, const StressOptions& options)
{
    StressRecord r;
    r.family = item.technique->info.family;
    r.technique = item.technique->info.name;
    r.caseName = item.stressCase->name;
    r.group = item.stressCase->group;
    r.description = item.stressCase->description;
    const plugin::StressSettings settings{options.gpu, options.seed};
    const auto start = std::chrono::steady_clock::now();
    try {
        r.outcome = item.stressCase->run(*item.technique, settings);
    } catch (const std::exception& e) {
        r.outcome.fail(std::string("threw: ") + e.what());
    } catch (...) {
        r.outcome.fail("threw a non-standard exception");
    }
    r.milliseconds = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return r;
}

std::vector<StressRecord> runStress(const StressPlan& plan, const StressOptions& options,
                                    const std::function<void(const StressRecord&)>& onRecord)
{
    std::vector<StressRecord> records;
    records.reserve(plan.items.size());
    for (const auto& item : plan.items) {
        records.push_back(runStressItem(item, options));
        if (onRecord)
            onRecord(records.back());
    }
    return records;
}

ResultRow makeStressRow(const StressRecord& r)
{
    ResultRow row;
    row.set("family", r.family)
        .set("technique", r.technique)
        .set("case", r.caseName)
        .set("group", r.group)
        .set("passed", r.outcome.passed())
        .set("values", std::int64_t(r.outcome.values))
        .set("non_finite", std::int64_t(r.outcome.nonFinite))
        .set("out_of_range", std::int64_t(r.outcome.outOfRange))
        .set("deviation", r.outcome.deviation)
        .set("tolerance", r.outcome.tolerance)
        .set("ms", r.milliseconds)
        .set("failures", join(r.outcome.failures, "; "))
        .set("note", r.outcome.note)
        .set("description", r.description);
    return row;
}

} // namespace rtlab::experiment
