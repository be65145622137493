#include "pipeline/frame_graph.h"

#include "gpu/bus_counters.h"

#include "core/error.h"
#include "core/strings.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <set>

namespace rtlab::pipeline {

const char* getResourceKindName(ResourceKind kind)
{
    switch (kind) {
    case ResourceKind::Token:
        return "token";
    case ResourceKind::Value:
        return "value";
    case ResourceKind::Table:
        return "table";
    case ResourceKind::Mesh:
        return "mesh";
    case ResourceKind::CpuImage:
        return "cpu_image";
    case ResourceKind::GpuImage:
        return "gpu_image";
    case ResourceKind::GpuBuffer:
        return "gpu_buffer";
    }
    return "?";
}

std::string ResourceType::describe() const
{
    std::string s = getResourceKindName(kind);
    if (!format.empty())
        s += "<" + format + ">";
    if (width > 0 || height > 0)
        s += " " + std::to_string(width) + "x" + std::to_string(height);
    if (bytes > 0)
        s += " " + std::to_string(bytes) + " bytes";
    return s;
}

std::string ResourceRef::describe() const
{
    return type.describe();
}

struct FrameGraph::Slot {
    std::string name;
    std::type_index type = typeid(void);
    std::string poolKey; //!< non-empty for GPU images and buffers: released ones are reused
    std::shared_ptr<void> data;
    const void* external = nullptr;
    bool persistent = false;
};

FrameGraph::FrameGraph() = default;
FrameGraph::~FrameGraph() = default;

FrameGraph::Slot& FrameGraph::slot(const std::string& name)
{
    for (auto& s : mSlots)
        if (s->name == name)
            return *s;
    mSlots.push_back(std::make_unique<Slot>());
    mSlots.back()->name = name;
    return *mSlots.back();
}

void FrameGraph::addExternal(const ResourceRef& resource, bool available, std::string reason)
{
    if (findExternal(resource.name) || findProducer(resource.name) >= 0)
        throw Error("frame graph: resource '" + resource.name + "' is declared twice");
    mExternals.push_back({resource, available, available ? std::string() : std::move(reason)});
}

void FrameGraph::bindExternal(const std::string& name, std::type_index type, const void* data)
{
    Slot& s = slot(name);
    s.type = type;
    s.external = data;
    s.persistent = true;
}

void FrameGraph::setExternalAvailable(const std::string& resource, bool available,
                                      std::string reason)
{
    for (auto& e : mExternals)
        if (e.ref.name == resource) {
            e.available = available;
            e.reason = available ? std::string() : std::move(reason);
            return;
        }
    throw Error("frame graph: no external resource '" + resource + "'");
}

void FrameGraph::addPass(PassDesc desc, std::function<PassOutcome()> run)
{
    addPass(std::move(desc), [run = std::move(run)](PassContext&) { return run(); });
}

void FrameGraph::addPass(PassDesc desc, std::function<PassOutcome(PassContext&)> run)
{
    for (const auto& p : mPasses)
        if (p.name == desc.name)
            throw Error("frame graph: two passes are named '" + desc.name + "'");
    auto check = [&](const ResourceRef& r) {
        const ResourceRef* declared = findDeclaration(r.name);
        if (!declared)
            throw Error("frame graph: pass '" + desc.name + "' reads '" + r.name +
                        "', which is neither an external resource nor written by an earlier pass");
        // A token read orders the pass after the producer without touching the data.
        if (r.type.kind == ResourceKind::Token && r.cppType == typeid(void))
            return;
        if (declared->type != r.type || declared->cppType != r.cppType) {
            const int producer = findProducer(r.name);
            const std::string by =
                producer >= 0 ? "pass '" + mPasses[std::size_t(producer)].name + "' writes it"
                              : "it is an external resource";
            throw Error(
                "frame graph: pass '" + desc.name + "' reads '" + r.name + "' as " + r.describe() +
                (declared->type == r.type ? " (C++ " + std::string(r.cppType.name()) + ")" : "") +
                ", but " + by + " as " + declared->describe() +
                (declared->type == r.type ? " (C++ " + std::string(declared->cppType.name()) + ")"
                                          : ""));
        }
    };
    for (const auto& r : desc.reads)
        check(r);
    for (const auto& r : desc.optionalReads)
        check(r);
    for (const auto& w : desc.writes)
        if (findExternal(w.name) || findProducer(w.name) >= 0)
            throw Error("frame graph: pass '" + desc.name + "' writes '" + w.name +
                        "', which already has a producer");
    for (const auto& p : desc.persistent)
        if (std::none_of(desc.writes.begin(), desc.writes.end(),
                         [&](const ResourceRef& w) { return w.name == p; }))
            throw Error("frame graph: pass '" + desc.name + "' keeps '" + p +
                        "' across frames but does not write it");
    for (const auto& w : desc.writes) {
        Slot& s = slot(w.name);
        s.type = w.cppType;
        if (w.allocates)
            s.poolKey = w.type.describe() + " " + w.cppType.name();
        s.persistent = std::find(desc.persistent.begin(), desc.persistent.end(), w.name) !=
                       desc.persistent.end();
    }
    mPasses.push_back(std::move(desc));
    mCallbacks.push_back(std::move(run));
}

const FrameGraph::External* FrameGraph::findExternal(const std::string& resource) const
{
    for (const auto& e : mExternals)
        if (e.ref.name == resource)
            return &e;
    return nullptr;
}

int FrameGraph::findProducer(const std::string& resource) const
{
    for (std::size_t i = 0; i < mPasses.size(); ++i)
        for (const auto& w : mPasses[i].writes)
            if (w.name == resource)
                return int(i);
    return -1;
}

const ResourceRef* FrameGraph::findDeclaration(const std::string& resource) const
{
    if (const External* e = findExternal(resource))
        return &e->ref;
    const int producer = findProducer(resource);
    if (producer < 0)
        return nullptr;
    for (const auto& w : mPasses[std::size_t(producer)].writes)
        if (w.name == resource)
            return &w;
    return nullptr;
}

bool FrameGraph::holds(const std::string& resource) const
{
    for (const auto& s : mSlots)
        if (s->name == resource)
            return s->data != nullptr || s->external != nullptr;
    return false;
}

std::vector<PassRecord> FrameGraph::plan(const scene::FeatureSet& features,
                                         const std::vector<std::string>& outputs,
                                         bool culling) const
{
    const std::size_t n = mPasses.size();
    std::vector<PassRecord> records(n);
    std::vector<bool> possible(n, true);
    // Forward: features, then inputs whose producer cannot run.
    for (std::size_t i = 0; i < n; ++i) {
        const PassDesc& pass = mPasses[i];
        records[i].name = pass.name;
        records[i].timing = pass.timing;
        records[i].measurement = pass.measurement;
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
            if (const External* e = findExternal(r.name)) {
                if (!e->available) {
                    possible[i] = false;
                    records[i].reason = "input '" + r.name + "' is not available: " + e->reason;
                    break;
                }
                continue;
            }
            const int producer = findProducer(r.name);
            if (!possible[std::size_t(producer)]) {
                possible[i] = false;
                records[i].reason = "input '" + r.name + "' is not produced: pass '" +
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
    std::vector<bool> live(n, !culling);
    for (std::size_t k = n; culling && k-- > 0;) {
        if (!possible[k])
            continue;
        const PassDesc& pass = mPasses[k];
        live[k] = std::any_of(pass.writes.begin(), pass.writes.end(),
                              [&](const ResourceRef& w) { return wanted.count(w.name) > 0; });
        if (!live[k]) {
            // Name the readers that would have consumed it, if any were skipped.
            std::vector<std::string> skippedReaders, written;
            for (const auto& w : pass.writes)
                written.push_back(w.name);
            for (std::size_t j = k + 1; j < n; ++j) {
                bool reads = false;
                for (const auto& w : pass.writes)
                    for (const auto* list : {&mPasses[j].reads, &mPasses[j].optionalReads})
                        for (const auto& r : *list)
                            reads = reads || r.name == w.name;
                if (reads)
                    skippedReaders.push_back(mPasses[j].name);
            }
            records[k].reason =
                skippedReaders.empty()
                    ? "no consumer: the run reads none of its outputs (" + joinList(written) + ")"
                    : "no consumer: its readers (" + joinList(skippedReaders) + ") are skipped";
            continue;
        }
        for (const auto& r : pass.reads)
            wanted.insert(r.name);
        for (const auto& r : pass.optionalReads)
            wanted.insert(r.name);
    }
    for (std::size_t i = 0; i < n; ++i) {
        records[i].ran = possible[i] && live[i];
        if (records[i].ran)
            records[i].reason.clear();
    }
    // A pass that prepares data for its readers (PassDesc::forReaders) and runs only for
    // measurements is one: every running pass that reads one of its outputs measures, and the
    // run asks for none of them (the G-buffer copied to the CPU for the ground truth is not part
    // of the frame's time). Readers come later, so one backward sweep decides.
    const std::set<std::string> requested(outputs.begin(), outputs.end());
    for (std::size_t k = n; k-- > 0;) {
        if (!records[k].ran || records[k].measurement || !mPasses[k].forReaders)
            continue;
        bool read = false, onlyMeasured = true;
        for (const auto& w : mPasses[k].writes) {
            if (requested.count(w.name) > 0)
                onlyMeasured = false;
            for (std::size_t j = k + 1; j < n && onlyMeasured; ++j) {
                if (!records[j].ran)
                    continue;
                for (const auto* list : {&mPasses[j].reads, &mPasses[j].optionalReads})
                    for (const auto& r : *list)
                        if (r.name == w.name) {
                            read = true;
                            onlyMeasured = onlyMeasured && records[j].measurement;
                        }
            }
        }
        records[k].measurement = read && onlyMeasured;
    }
    return records;
}

std::vector<PassRecord> FrameGraph::execute(const scene::FeatureSet& features,
                                            const std::vector<std::string>& outputs)
{
    FrameOptions options;
    options.features = features;
    options.outputs = outputs;
    return execute(options);
}

namespace {

metrics::TimingReport makeSingleReport(double cpuMs, const metrics::GpuPassTimes& gpu)
{
    metrics::TimingReport report;
    report.firstUseMs = cpuMs;
    report.cpuMs = metrics::computeStats({cpuMs});
    for (const auto& [label, ms] : gpu)
        report.gpuMs[label] = metrics::computeStats({ms});
    return report;
}

} // namespace

std::vector<PassRecord> FrameGraph::execute(const FrameOptions& options)
{
    std::vector<PassRecord> records = plan(options.features, options.outputs, options.culling);
    mReleased.clear();
    mGpuAllocations = 0;
    mGpuReuses = 0;
    const std::size_t n = records.size();
    // The last running pass that reads each resource; outputs and persistent ones are kept.
    std::map<std::string, std::size_t> lastUse;
    for (std::size_t i = 0; i < n; ++i) {
        if (!records[i].ran)
            continue;
        for (const auto& w : mPasses[i].writes)
            lastUse.try_emplace(w.name, i);
        for (const auto* list : {&mPasses[i].reads, &mPasses[i].optionalReads})
            for (const auto& r : *list)
                lastUse[r.name] = std::max(lastUse[r.name], i);
    }
    const std::set<std::string> kept(options.outputs.begin(), options.outputs.end());
    // Non-persistent data left from the previous frame is gone (GPU resources to the pool).
    for (auto& s : mSlots)
        if (!s->persistent && s->data) {
            if (!s->poolKey.empty())
                mPool.emplace_back(s->poolKey, std::move(s->data));
            s->data.reset();
        }

    auto collect = [&] {
        return options.collectGpuTimes ? options.collectGpuTimes() : metrics::GpuPassTimes{};
    };
    for (std::size_t i = 0; i < n; ++i) {
        if (records[i].ran) {
            PassContext context(*this, i, options.frame, options.culling);
            PassOutcome outcome;
            std::string reused;
            if (options.culling && mPasses[i].reuse)
                reused = mPasses[i].reuse(context);
            collect(); // GPU work submitted before this pass is not its own
            const gpu::BusCounters busBefore = gpu::getBusCounters();
            int calls = 1;
            std::vector<double> hostMs; // per call: wall time less the waits on the device
            const auto call = [&] {
                const double waitedBefore = gpu::getBusCounters().waitMs;
                const auto start = std::chrono::steady_clock::now();
                outcome = mCallbacks[i](context);
                const double ms =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                        .count();
                hostMs.push_back(std::max(0.0, ms - (gpu::getBusCounters().waitMs - waitedBefore)));
                return ms;
            };
            if (!reused.empty()) {
                outcome = PassOutcome::skipped(reused);
            } else if (mPasses[i].timing == PassTiming::Repeated) {
                calls = 0;
                const metrics::TimingOptions timing = mPasses[i].timingOptions.value_or(options.timing);
                const auto report = metrics::measure(timing, [&] {
                    ++calls;
                    call();
                    return collect();
                });
                records[i].time = report;
                // The timed calls are the last max(1, repeats) (metrics::measure).
                const std::size_t timed = std::size_t(std::max(1, timing.repeats));
                hostMs.erase(hostMs.begin(), hostMs.end() - std::ptrdiff_t(std::min(timed, hostMs.size())));
            } else {
                records[i].time = makeSingleReport(call(), collect());
            }
            if (!hostMs.empty())
                records[i].hostMs = metrics::computeStats(std::move(hostMs)).median;
            {
                // Per call of the pass (a repeated one is called warm-up + repeats times).
                const gpu::BusCounters bus = gpu::getBusCounters() - busBefore;
                const std::uint64_t n = std::uint64_t(std::max(1, calls));
                records[i].uploadBytes = bus.uploadBytes / n;
                records[i].readbackBytes = bus.readbackBytes / n;
                records[i].submits = bus.submits / n;
                records[i].waits = bus.waits / n;
                records[i].waitMs = bus.waitMs / double(n);
            }
            if (!outcome.ran) {
                records[i].ran = false;
                records[i].reason = std::move(outcome.reason);
                records[i].time.reset();
            }
        }
        // Release what no later running pass reads.
        for (auto& s : mSlots) {
            if (s->persistent || !s->data || kept.count(s->name))
                continue;
            auto it = lastUse.find(s->name);
            if (it == lastUse.end() || it->second <= i) {
                if (!s->poolKey.empty())
                    mPool.emplace_back(s->poolKey, std::move(s->data));
                s->data.reset();
                mReleased.push_back(s->name);
            }
        }
    }
    return records;
}

const void* PassContext::get(const std::string& name, std::type_index type, bool optional) const
{
    const PassDesc& pass = mGraph.mPasses[mPass];
    const ResourceRef* declared = nullptr;
    for (const auto* list : {&pass.reads, &pass.optionalReads, &pass.writes})
        for (const auto& r : *list)
            if (r.name == name && r.cppType != typeid(void))
                declared = &r;
    if (!declared)
        throw Error("frame graph: pass '" + pass.name + "' uses '" + name +
                    "', which it does not declare with a type");
    if (declared->cppType != type)
        throw Error("frame graph: pass '" + pass.name + "' uses '" + name + "' as C++ " +
                    type.name() + ", declared as " + declared->cppType.name());
    for (const auto& s : mGraph.mSlots)
        if (s->name == name) {
            if (s->external)
                return s->external;
            if (s->data)
                return s->data.get();
        }
    if (optional)
        return nullptr;
    throw Error("frame graph: pass '" + pass.name + "' reads '" + name +
                "', which holds no data this frame");
}

void* PassContext::getForWrite(const std::string& name, std::type_index type)
{
    const PassDesc& pass = mGraph.mPasses[mPass];
    for (const auto& w : pass.writes)
        if (w.name == name) {
            if (w.cppType != type)
                throw Error("frame graph: pass '" + pass.name + "' writes '" + name + "' as C++ " +
                            type.name() + ", declared as " + w.cppType.name());
            FrameGraph::Slot& s = mGraph.slot(name);
            if (!s.data && !s.poolKey.empty()) {
                auto& pool = mGraph.mPool;
                for (auto it = pool.begin(); it != pool.end(); ++it)
                    if (it->first == s.poolKey) {
                        s.data = std::move(it->second);
                        pool.erase(it);
                        ++mGraph.mGpuReuses;
                        break;
                    }
            }
            if (!s.data) {
                s.data = w.make();
                if (!s.poolKey.empty())
                    ++mGraph.mGpuAllocations;
            }
            return s.data.get();
        }
    throw Error("frame graph: pass '" + pass.name + "' writes '" + name +
                "', which it does not declare");
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
