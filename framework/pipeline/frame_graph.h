#pragma once
// The frame graph: a frame is a list of passes, each declaring the typed resources it reads and
// writes and the scene features it needs. The graph owns the resources, hands passes typed
// handles, times every pass, and culls before each frame (ARCHITECTURE.md, "skip what a scene
// doesn't need"; the rule of the UE4 VR talk in shared/seeds/001_5c6096db92814698.txt: "the
// fastest code is that which does not run"):
//   1. a pass whose required feature the scene lacks is skipped;
//   2. a pass that reads a resource no available producer makes is skipped (and so on downstream);
//   3. a pass none of whose outputs is read by a pass that runs, or requested by the run, is
//      skipped (walking backwards from the requested outputs).
// The rest run in declaration order. A pass may still find at run time that its work is already
// done (a cache hit, unchanged geometry) and report itself skipped with that reason; its outputs
// then count as available. Every pass ends with a record: ran (with its CPU and GPU time), or
// skipped and why.
//
// Resources. A resource has a name and a type (ResourceType: GPU image with format and size, GPU
// buffer, CPU image, mesh, table of values, value, or a token that only orders passes) and, when
// it holds data, a C++ type. Writers and readers name it through a typed handle Resource<T>; the
// graph checks when a pass is added that every reader expects the type its producer writes, and
// names both passes and both types when they differ. The graph creates a resource's storage when
// its producer first writes it and releases it after the last pass of the frame that reads it,
// unless the resource is persistent (kept across frames: caches, uploaded scenes) or an output the
// run asked for. Released GPU images and buffers go to a pool and serve the next writer of the
// same type (the next frame's, or a later pass's), so a frame allocates no GPU memory once warm.
//
// The graph is built once per run and executed once per frame:
//
//   FrameGraph graph;
//   const auto scene = graph.addExternal<scene::Scene>("scene", ResourceType::value("scene"),
//   &theScene); const Resource<Image<float>> ao{"ao", ResourceType::cpuImage("float")};
//   graph.addPass({.name = "occlusion", .reads = {view}, .writes = {ao}, .timing =
//   PassTiming::Repeated},
//                 [&](PassContext& ctx) { ctx.write(ao) = compute(ctx.read(view)); return
//                 PassOutcome{}; });
//   for (int frame = 0; frame < frames; ++frame)
//       FrameResult r = graph.execute({.features = f, .outputs = {"metric.error"}, .frame =
//       frame});

#include "metrics/timing.h"
#include "scene/scene.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <typeindex>
#include <vector>

namespace rtlab::pipeline {

enum class ResourceKind { Token, Value, Table, Mesh, CpuImage, GpuImage, GpuBuffer };
const char* getResourceKindName(ResourceKind kind);

//! What a resource holds, as declared by its producer and expected by its readers.
struct ResourceType {
    ResourceKind kind = ResourceKind::Token;
    std::string format; //!< image texel ("rgba32f", "float", "vec3"), or what a value/table is
    int width = 0;      //!< 0: not fixed when the graph is built
    int height = 0;
    std::size_t bytes = 0; //!< GPU buffers; 0: not fixed

    static ResourceType token() { return {}; }
    static ResourceType value(std::string what) { return {ResourceKind::Value, std::move(what)}; }
    static ResourceType table(std::string what) { return {ResourceKind::Table, std::move(what)}; }
    static ResourceType mesh(std::string what = "triangles")
    {
        return {ResourceKind::Mesh, std::move(what)};
    }
    static ResourceType cpuImage(std::string texel, int w = 0, int h = 0)
    {
        return {ResourceKind::CpuImage, std::move(texel), w, h};
    }
    static ResourceType gpuImage(std::string format, int w = 0, int h = 0)
    {
        return {ResourceKind::GpuImage, std::move(format), w, h};
    }
    static ResourceType gpuBuffer(std::string what, std::size_t bytes = 0)
    {
        return {ResourceKind::GpuBuffer, std::move(what), 0, 0, bytes};
    }
    //! "gpu_image<rgba32f> 320x180", "cpu_image<float>", "token".
    std::string describe() const;
    bool operator==(const ResourceType&) const = default;
};

//! A resource as a pass names it: name, declared type, and the C++ type of its data (void for
//! tokens). Converts from a string for tokens (`.writes = {"metric.error"}`).
struct ResourceRef {
    std::string name;
    ResourceType type;
    std::type_index cppType = typeid(void);
    std::function<std::shared_ptr<void>()> make; //!< default-constructs the data (not for tokens)
    bool allocates = false; //!< `make` allocates device memory (GPU images, buffers): pooled

    ResourceRef(std::string n) : name(std::move(n)) {}
    ResourceRef(const char* n) : name(n) {}
    ResourceRef(std::string n, ResourceType t, std::type_index cpp,
                std::function<std::shared_ptr<void>()> m)
        : name(std::move(n)), type(std::move(t)), cppType(cpp), make(std::move(m))
    {
    }
    //! "cpu_image<float> (N6rtlab5ImageIfEE)" style: the type and the C++ type's name.
    std::string describe() const;
};

//! A typed handle: the name and type of a resource whose data is a T. The graph creates the data
//! with `create` when the producer first writes it (default-constructed when unset: CPU data; GPU
//! images and buffers give a function that allocates them on the device, pipeline/gpu_resources.h).
template <class T> struct Resource {
    std::string name;
    ResourceType type;
    std::function<std::shared_ptr<T>()> create;

    operator ResourceRef() const
    {
        auto make = create;
        ResourceRef ref(name, type, typeid(T), [make]() -> std::shared_ptr<void> {
            return make ? std::static_pointer_cast<void>(make())
                        : std::static_pointer_cast<void>(std::make_shared<T>());
        });
        ref.allocates = bool(create) && (type.kind == ResourceKind::GpuImage ||
                                         type.kind == ResourceKind::GpuBuffer);
        return ref;
    }
};

class PassContext;

//! What a pass reports after its callback: ran (the default), or found its work already done.
struct PassOutcome {
    bool ran = true;
    std::string reason; //!< why it did nothing, when !ran

    static PassOutcome skipped(std::string why) { return {false, std::move(why)}; }
};

//! How the graph times a pass.
enum class PassTiming {
    Once,     //!< one call, its CPU wall time (and GPU time when it ran GPU work)
    Repeated, //!< the timing harness (metrics/timing.h): first use, warm-up, median of repeats;
              //!< the pass must give the same result every call
};

struct PassDesc {
    std::string name;                       //!< unique in the graph, snake_case
    std::vector<ResourceRef> reads;         //!< required inputs
    std::vector<ResourceRef> optionalReads; //!< used when available, never a reason to skip
    std::vector<ResourceRef> writes;        //!< each resource has exactly one producer
    std::vector<scene::SceneFeature> needs; //!< every one must be in the frame's features
    PassTiming timing = PassTiming::Once;
    std::vector<std::string> persistent; //!< written resources kept across frames
    //! Asked before the pass runs, when culling is on: a non-empty answer says why the pass's
    //! outputs (persistent ones) are still valid, and the pass is skipped with that reason
    //! (unchanged geometry, an unchanged camera). Not timed.
    std::function<std::string(const PassContext&)> reuse;
    //! True for passes that measure the frame rather than make it (ground truths, metrics, image
    //! files): they are left out of the frame's time.
    bool measurement = false;
    //! True for a pass that only prepares data for its readers (a read-back of GPU results to
    //! the CPU, a CPU view of the G-buffer): in a frame where only measurements read its outputs
    //! it counts as a measurement too (its record says so), so the frame's time leaves it out.
    bool forReaders = false;
    //! PassTiming::Repeated with other warm-up and repeats than the run's (e.g. an expensive
    //! preparation timed once).
    std::optional<metrics::TimingOptions> timingOptions;
};

//! How a pass ended in one frame.
struct PassRecord {
    std::string name;
    bool ran = false;
    std::string reason; //!< why it was skipped; empty when it ran
    PassTiming timing = PassTiming::Once;
    //! From PassDesc, or derived for a pass PassDesc::forReaders whose outputs only
    //! measurements read this frame.
    bool measurement = false;
    //! When it ran: the CPU wall time (and GPU pass times) the graph measured.
    std::optional<metrics::TimingReport> time;
    //! When it ran: what crossed the bus per call of the pass (gpu/bus_counters.h): bytes
    //! uploaded and read back, queue submissions, host waits on a fence and their wall time.
    std::uint64_t uploadBytes = 0;
    std::uint64_t readbackBytes = 0;
    std::uint64_t submits = 0;
    std::uint64_t waits = 0;
    double waitMs = 0.0;
    //! The pass's host time: per call its CPU wall time less its waits on the device, the median
    //! over the timed calls (a repeated pass's repeats; its first use and warm-ups, which wait
    //! differently, are left out).
    double hostMs = 0.0;
};

class FrameGraph;

//! What a pass's callback gets: typed access to the resources it declared, and the frame.
class PassContext {
public:
    int frame() const { return mFrame; }
    //! False when culling is off for this frame: a pass must then redo work it would reuse.
    bool mayReuse() const { return mMayReuse; }

    //! The data of a resource the pass reads (or wrote earlier, or keeps across frames). Throws
    //! rtlab::Error when it is not available.
    template <class T> const T& read(const Resource<T>& r) const
    {
        return *static_cast<const T*>(get(r.name, typeid(T), false));
    }
    //! The data of an optional read, or nullptr.
    template <class T> const T* tryRead(const Resource<T>& r) const
    {
        return static_cast<const T*>(get(r.name, typeid(T), true));
    }
    //! The storage of a resource the pass writes, created by the graph on first use.
    template <class T> T& write(const Resource<T>& r)
    {
        return *static_cast<T*>(getForWrite(r.name, typeid(T)));
    }

private:
    friend class FrameGraph;
    PassContext(FrameGraph& graph, std::size_t pass, int frame, bool mayReuse)
        : mGraph(graph), mPass(pass), mFrame(frame), mMayReuse(mayReuse)
    {
    }
    const void* get(const std::string& name, std::type_index type, bool optional) const;
    void* getForWrite(const std::string& name, std::type_index type);

    FrameGraph& mGraph;
    std::size_t mPass;
    int mFrame;
    bool mMayReuse;
};

//! One frame's settings.
struct FrameOptions {
    scene::FeatureSet features;
    std::vector<std::string> outputs; //!< resources the run keeps (metrics, images)
    int frame = 0;
    bool culling = true; //!< false: no pass is skipped for having no consumer or reusing work
    metrics::TimingOptions timing; //!< for PassTiming::Repeated
    //! Drains the GPU's run log: the pass times of everything submitted since the last call.
    //! Empty for CPU-only graphs.
    std::function<metrics::GpuPassTimes()> collectGpuTimes;
};

class FrameGraph {
public:
    FrameGraph();
    ~FrameGraph();
    FrameGraph(const FrameGraph&) = delete;
    FrameGraph& operator=(const FrameGraph&) = delete;

    //! A resource that exists before the first pass (the scene, the camera, ...). One that is not
    //! available this frame makes its readers skip with `reason`.
    void addExternal(const ResourceRef& resource, bool available = true, std::string reason = "");
    //! An external whose data the caller owns (`data` must outlive the graph).
    template <class T>
    Resource<T> addExternal(const std::string& name, ResourceType type, const T* data)
    {
        Resource<T> r{name, std::move(type)};
        addExternal(ResourceRef(r), true, "");
        bindExternal(name, typeid(T), data);
        return r;
    }
    //! Changes an external's availability for the next frames.
    void setExternalAvailable(const std::string& resource, bool available, std::string reason = "");

    //! Declares a pass. Passes run in declaration order, so every resource a pass reads must be
    //! an external or written by an earlier pass, with the type that producer declared; throws
    //! rtlab::Error otherwise (naming both passes and types), for a duplicate name, or for a
    //! resource with two producers.
    void addPass(PassDesc desc, std::function<PassOutcome(PassContext&)> run);
    void addPass(PassDesc desc, std::function<PassOutcome()> run);

    //! Decides which passes run, without running anything. Throws for an unknown output.
    std::vector<PassRecord> plan(const scene::FeatureSet& features,
                                 const std::vector<std::string>& outputs,
                                 bool culling = true) const;
    //! plan(), then runs and times the passes that survive, in order, and releases each
    //! non-persistent resource after its last reader. Exceptions from a pass propagate.
    std::vector<PassRecord> execute(const FrameOptions& options);
    std::vector<PassRecord> execute(const scene::FeatureSet& features,
                                    const std::vector<std::string>& outputs);

    const std::vector<PassDesc>& passes() const { return mPasses; }
    //! True when an external or a pass already declares `resource`.
    bool declares(const std::string& resource) const
    {
        return findDeclaration(resource) != nullptr;
    }
    //! True when the resource's data exists now (written this frame or kept from an earlier one).
    bool holds(const std::string& resource) const;
    //! Resources released during the last execute() (their names), for tests and logs.
    const std::vector<std::string>& lastReleased() const { return mReleased; }
    //! GPU images and buffers the last execute() allocated, and those it took from the pool of
    //! released ones of the same type (a released GPU resource is kept for the next writer of
    //! its type instead of being freed; a pass writing one overwrites all of it).
    int lastGpuAllocations() const { return mGpuAllocations; }
    int lastGpuReuses() const { return mGpuReuses; }

private:
    friend class PassContext;
    struct Slot;
    struct External {
        ResourceRef ref;
        bool available = true;
        std::string reason;
    };
    void bindExternal(const std::string& name, std::type_index type, const void* data);
    const External* findExternal(const std::string& resource) const;
    int findProducer(const std::string& resource) const; //!< pass index, -1 when none
    const ResourceRef* findDeclaration(const std::string& resource) const;
    Slot& slot(const std::string& name);

    std::vector<External> mExternals;
    std::vector<PassDesc> mPasses;
    std::vector<std::function<PassOutcome(PassContext&)>> mCallbacks;
    std::vector<std::unique_ptr<Slot>> mSlots;
    std::vector<std::string> mReleased;
    //! Released GPU resources by type (ResourceType::describe() + C++ type), for reuse.
    std::vector<std::pair<std::string, std::shared_ptr<void>>> mPool;
    int mGpuAllocations = 0;
    int mGpuReuses = 0;
};

//! "gbuffer:run;reference:skipped(read from the cache)" (the results table's `passes` column).
std::string formatPassRecords(const std::vector<PassRecord>& records);

} // namespace rtlab::pipeline
