#include "pipeline/frame_graph.h"

#include "core/error.h"
#include "core/strings.h"

#include <algorithm>
#include <set>

namespace rtlab::pipeline {

void FrameGraph::addExternal(const std::string& resource, bool available, std::string reason)
{
    if (findExternal(resource) || findProducer(resource) >= 0)
        throw Error("frame graph: resource '" + resource + "' is declared twice");
    mExternals.push_back({resource, available, available ? std::string() : std::move(reason)});
}

void FrameGraph::addPass(PassDesc desc, std::function<PassOutcome()> run)
{
    for (const auto& p : mPasses)
        if (p.name == desc.name)
            throw Error("frame graph: two passes are named '" + desc.name + "'");
    auto checkKnown = [&](const std::string& r) {
        if (!findExternal(r) && findProducer(r) < 0)
            throw Error("frame graph: pass '" + desc.name + "' reads '" + r +
                        "', which is neither an external resource nor written by an earlier pass");
    };
    for (const auto& r : desc.reads)
        checkKnown(r);
    for (const auto& r : desc.optionalReads)
        checkKnown(r);
    for (const auto& w : desc.writes)
        if (findExternal(w) || findProducer(w) >= 0)
            throw Error("frame graph: pass '" + desc.name + "' writes '" + w +
                        "', which already has a producer");
    mPasses.push_back(std::move(desc));
    mCallbacks.push_back(std::move(run));
}

const FrameGraph::External* FrameGraph::findExternal(const std::string& resource) const
{
    for (const auto& e : mExternals)
        if (e.name == resource)
            return &e;
    return nullptr;
}

int FrameGraph::findProducer(const std::string& resource) const
{
    for (std::size_t i = 0; i < mPasses.size(); ++i)
        if (std::find(mPasses[i].writes.begin(), mPasses[i].writes.end(), resource) !=
            mPasses[i].writes.end())
            return int(i);
    return -1;
}

std::vector<PassRecord> FrameGraph::plan(const scene::FeatureSet& features,
                                         const std::vector<std::string>& outputs) const
{
    const std::size_t n = mPasses.size();
    std::vector<PassRecord> records(n);
    std::vector<bool> possible(n, true);
    // Forward: features, then inputs whose producer cannot run.
    for (std::size_t i = 0; i < n; ++i) {
        const PassDesc& pass = mPasses[i];
        records[i].name = pass.name;
        for (scene::SceneFeature f : pass.needs)
            if (!features.has(f)) {
                possible[i] = false;
                records[i].reason =
                    std::string("the scene has no ") + scene::FeatureSet::getName(f);
                break;
            }
        if (!possible[i])
            continue;
        for (const auto& r : pass.reads) {
            if (const External* e = findExternal(r)) {
                if (!e->available) {
                    possible[i] = false;
                    records[i].reason = "input '" + r + "' is not available: " + e->reason;
                    break;
                }
                continue;
            }
            const int producer = findProducer(r);
            if (!possible[std::size_t(producer)]) {
                possible[i] = false;
                records[i].reason = "input '" + r + "' is not produced: pass '" +
                                    mPasses[std::size_t(producer)].name + "' is skipped";
                break;
            }
        }
    }
    // Backward: keep a pass only when something that runs, or the run itself, reads its output.
    std::set<std::string> wanted;
    for (const auto& o : outputs) {
        if (!findExternal(o) && findProducer(o) < 0)
            throw Error("frame graph: the run asks for output '" + o + "', which no pass writes");
        wanted.insert(o);
    }
    std::vector<bool> live(n, false);
    for (std::size_t k = n; k-- > 0;) {
        if (!possible[k])
            continue;
        const PassDesc& pass = mPasses[k];
        live[k] = std::any_of(pass.writes.begin(), pass.writes.end(),
                              [&](const std::string& w) { return wanted.count(w) > 0; });
        if (!live[k]) {
            // Name the readers that would have consumed it, if any were skipped.
            std::vector<std::string> skippedReaders;
            for (std::size_t j = k + 1; j < n; ++j)
                for (const auto& w : pass.writes) {
                    const auto& reads = mPasses[j].reads;
                    const auto& optional = mPasses[j].optionalReads;
                    if (std::find(reads.begin(), reads.end(), w) != reads.end() ||
                        std::find(optional.begin(), optional.end(), w) != optional.end()) {
                        skippedReaders.push_back(mPasses[j].name);
                        break;
                    }
                }
            records[k].reason =
                skippedReaders.empty()
                    ? "no consumer: the run reads none of its outputs (" + joinList(pass.writes) +
                          ")"
                    : "no consumer: its readers (" + joinList(skippedReaders) + ") are skipped";
            continue;
        }
        for (const auto& r : pass.reads)
            wanted.insert(r);
        for (const auto& r : pass.optionalReads)
            wanted.insert(r);
    }
    for (std::size_t i = 0; i < n; ++i) {
        records[i].ran = possible[i] && live[i];
        if (records[i].ran)
            records[i].reason.clear();
    }
    return records;
}

std::vector<PassRecord> FrameGraph::execute(const scene::FeatureSet& features,
                                            const std::vector<std::string>& outputs)
{
    std::vector<PassRecord> records = plan(features, outputs);
    for (std::size_t i = 0; i < records.size(); ++i) {
        if (!records[i].ran)
            continue;
        PassOutcome outcome = mCallbacks[i]();
        if (!outcome.ran) {
            records[i].ran = false;
            records[i].reason = std::move(outcome.reason);
        }
    }
    return records;
}

std::string formatPassRecords(const std::vector<PassRecord>& records)
{
    std::string s;
    for (const auto& r : records) {
        if (!s.empty())
            s += ";";
        s += r.name + (r.ran ? ":run" : ":skipped(" + r.reason + ")");
    }
    return s;
}

} // namespace rtlab::pipeline
