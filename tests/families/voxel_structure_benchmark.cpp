// The voxel GI structures side by side on the same voxels (the data-structure metrics of
// metrics/structure_metrics.h): bytes per active voxel split into topology and payload, build
// time, random and coherent lookup time, for
//   dense_grid           one 3D texture over the scene's box at the finest voxel size (what a
//                        single cascade level holding every voxel needs)
//   cascades             the Tomorrow Children's clipmap: levels of 32^3 doubling in extent until
//                        the coarsest holds the box, the finest at the same voxel size (memory
//                        only: it holds the finest voxels only near the camera)
//   adaptive_voxel_tree  Quantum Break's 64-ary tree (voxel_tree.h), partially dilated, depth 2
//                        below a dense first level of root cells of 16^3 leaves (the talk: "the
//                        first level of the tree can have arbitrary dimensions"), payload for
//                        every element (nodes too: the seamless interpolation reads them), its
//                        records' masks shared in a table (the default); `_undilated` without
//                        the partial dilation; `_inline_masks` with the talk's 12-byte records
//                        (64-bit mask + offset in each); `_depth3` one level deeper below root
//                        cells of 64^3 leaves (fewer root cells, one more level per lookup)
//   svo                  Crassin et al.'s sparse voxel octree (sparse_voxel_octree.h): node tiles
//                        of 2x2x2 with one 32-bit child pointer per node, down to the next power
//                        of two above the lattice, payload for every node (cone tracing reads the
//                        filtered interior nodes)
//   openvdb              OpenVDB Vec3SGrid (5-4-3 tree), random lookups by the uncached
//                        tree().getValue, coherent ones through a ValueAccessor
//   nanovdb              NanoVDB converted from that grid (openToNanoVDB), same two lookups
// The voxels: the cells of a lattice over the static scene (no characters, frame 0) that a
// triangle meets (families/voxel_gi/voxelize.h listCellsMeetingTriangles), at 128, 256 and 512
// cells along the box's longest side, for cornell_box and tomorrow_town; and the narrow-band
// level set of a sphere of radius 230 voxels (half-width 3 voxels, 4.0 M voxels: a band 6 voxels
// thick instead of a surface shell one voxel thick). Payload: one RGB float value (12 bytes) per
// voxel in every structure.
//
//   build/tests/families/voxel_structure_benchmark [--benchmark_filter=<regex>]
//   build/tests/families/voxel_structure_benchmark --quick   # cornell_box at 32 and 64 (ctest)
// Counters: voxels (active), topology_B (bytes per active voxel), payload_B, total_B,
// mask_floor_B (adaptive_voxel_tree: its child masks at their combinatorial minimum, the part of
// the topology no code of each node's mask on its own goes below; sharing the masks between
// nodes does), masks (adaptive_voxel_tree: distinct masks in its table), and items_per_second =
// lookups per second for the lookup rows (ns per lookup = 1e9 / it). The lookup_random_gpu rows
// (adaptive_voxel_tree, svo: the structures whose technique runs on Vulkan) run the random
// lookups through the cone gathers' Vulkan lookups (tests/families/shaders), one dispatch per
// iteration, checked against the CPU lookups.

#include "sparse_voxel_octree.h" // techniques/voxel_gi/svo
#include "voxel_tree.h"          // techniques/voxel_gi/adaptive_voxel_tree

#include "families/voxel_gi/voxelize.h"
#include "gpu/commands.h"
#include "gpu/context.h"
#include "gpu/pipeline.h"
#include "gpu/resources.h"
#include "gpu/shader_compiler.h"
#include "metrics/structure_metrics.h"
#include "scene/scene.h"
#include "scene/scene_file.h"

#include <benchmark/benchmark.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

using namespace rtlab;

namespace {

struct Voxels {
    glm::ivec3 cells{0};                 //!< lattice size
    std::vector<glm::ivec3> active;      //!< sorted by (z, y, x)
    std::vector<glm::ivec3> randomOrder; //!< the same voxels shuffled
};

glm::vec3 payloadOf(const glm::ivec3& c) { return glm::vec3(c) * 1e-3f + 0.5f; }

//! The narrow-band level set of a sphere of radius r voxels (the active voxels of OpenVDB's
//! createLevelSetSphere at its default half-width of 3 voxels: centres within 3 voxels of the
//! sphere): the data set on which the topology target of 0.4 B/voxel was estimated (a band 6
//! voxels thick, about 36 voxels per 4^3 node against about 15 for a voxelized surface).
Voxels makeNarrowBandSphere(int radius)
{
    Voxels v;
    const int n = 2 * radius + 8;
    v.cells = glm::ivec3(n);
    const double centre = 0.5 * double(n);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const glm::dvec3 p = glm::dvec3(x, y, z) + 0.5 - centre;
                if (std::abs(std::sqrt(glm::dot(p, p)) - double(radius)) < 3.0)
                    v.active.emplace_back(x, y, z);
            }
    return v;
}

const Voxels& getVoxels(const std::string& sceneName, int resolution)
{
    static std::map<std::pair<std::string, int>, Voxels> cache;
    auto it = cache.find({sceneName, resolution});
    if (it != cache.end())
        return it->second;
    if (sceneName == "narrow_band_sphere") {
        Voxels v = makeNarrowBandSphere(resolution);
        v.randomOrder = v.active;
        std::shuffle(v.randomOrder.begin(), v.randomOrder.end(), std::mt19937(1));
        if (v.randomOrder.size() > (1u << 18))
            v.randomOrder.resize(1u << 18);
        return cache.emplace(std::make_pair(sceneName, resolution), std::move(v)).first->second;
    }
    const scene::Scene s = scene::loadScene(sceneName);
    const scene::RenderScene g = s.assembleRenderScene(s.meshSdfModels(0), {}, 0);
    const glm::dvec3 lo(g.boundsMin), hi(g.boundsMax);
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    const double cell = extent / resolution;
    Voxels v;
    v.cells = glm::max(glm::ivec3(glm::ceil((hi - lo) / cell)) + 1, glm::ivec3(1));
    v.active = voxelgi::listCellsMeetingTriangles(g, lo - 0.5 * cell, cell, v.cells);
    v.randomOrder = v.active;
    std::shuffle(v.randomOrder.begin(), v.randomOrder.end(), std::mt19937(1));
    if (v.randomOrder.size() > (1u << 18))
        v.randomOrder.resize(1u << 18);
    return cache.emplace(std::make_pair(sceneName, resolution), std::move(v)).first->second;
}

// One structure: build from the voxels, its footprint, and a lookup returning the payload (or 0).
// What a structure's lookup on Vulkan needs: its shader (tests/families/shaders), the topology
// as 32-bit words, one float of payload per element (the value's x), and its push constants.
struct GpuLookup {
    std::string shader;
    std::vector<std::uint32_t> topology;
    std::vector<float> payload;
    std::vector<glm::ivec4> constants; //!< the last one's x, y are set to the count and the level
    int level = 0;
};

class Structure {
public:
    virtual ~Structure() = default;
    virtual void build(const Voxels& v) = 0;
    virtual metrics::StructureFootprint footprint() const = 0;
    //! Sum of the looked-up values' x (the checksum that keeps the work).
    virtual double lookupRandom(const std::vector<glm::ivec3>& q) const = 0;
    virtual double lookupCoherent(const std::vector<glm::ivec3>& q) const { return lookupRandom(q); }
    virtual bool canLookup() const { return true; }
    //! Bytes of the child masks at their combinatorial minimum (NaN: no child masks).
    virtual double getMaskFloorBytes() const { return std::nan(""); }
    //! Distinct masks in a shared mask table (NaN: none).
    virtual double getMaskCount() const { return std::nan(""); }
    //! The structure's lookup on Vulkan, where the technique runs one (none: empty shader).
    virtual GpuLookup getGpuLookup() const { return {}; }
};

class DenseGrid final : public Structure {
public:
    void build(const Voxels& v) override
    {
        mCells = v.cells;
        mValues.assign(std::size_t(v.cells.x) * std::size_t(v.cells.y) * std::size_t(v.cells.z),
                       glm::vec3(0.0f));
        for (const auto& c : v.active)
            mValues[index(c)] = payloadOf(c);
    }
    metrics::StructureFootprint footprint() const override
    {
        return {.topologyBytes = 0, .payloadBytes = metrics::usedBytes(mValues), .nodeCount = 0};
    }
    double lookupRandom(const std::vector<glm::ivec3>& q) const override
    {
        double sum = 0.0;
        for (const auto& c : q)
            sum += mValues[index(c)].x;
        return sum;
    }

private:
    std::size_t index(const glm::ivec3& c) const
    {
        return std::size_t(c.x) + std::size_t(mCells.x) * (std::size_t(c.y) + std::size_t(mCells.y) * std::size_t(c.z));
    }
    glm::ivec3 mCells{0};
    std::vector<glm::vec3> mValues;
};

// Memory of the clipmap only: levels of 32^3 from the finest voxel size up to the level holding
// the box, one value per voxel.
class Cascades final : public Structure {
public:
    void build(const Voxels& v) override
    {
        const int longest = std::max({v.cells.x, v.cells.y, v.cells.z});
        mLevels = 1;
        while (32 * (1 << (mLevels - 1)) < longest)
            ++mLevels;
    }
    metrics::StructureFootprint footprint() const override
    {
        return {.topologyBytes = 0,
                .payloadBytes = std::size_t(mLevels) * 32u * 32u * 32u * sizeof(glm::vec3),
                .nodeCount = 0};
    }
    double lookupRandom(const std::vector<glm::ivec3>&) const override { return 0.0; }
    bool canLookup() const override { return false; }

private:
    int mLevels = 1;
};

class Avt final : public Structure {
public:
    Avt(const voxelgi::VoxelTreeBuildOptions& options, int depth) : mOptions(options), mDepth(depth)
    {
    }
    void build(const Voxels& v) override
    {
        voxelgi::VoxelTreeLayout layout;
        layout.depth = mDepth;
        const int rootLeaves = 1 << (2 * mDepth);
        layout.rootCells = glm::max((v.cells + rootLeaves - 1) / rootLeaves, glm::ivec3(1));
        mTree = voxelgi::AdaptiveVoxelTree::build(layout, v.active, mOptions);
        mPayload.assign(mTree.getElementCount(), glm::vec3(0.0f));
        for (const auto& c : v.active)
            mPayload[std::size_t(mTree.find(mDepth, c))] = payloadOf(c);
    }
    metrics::StructureFootprint footprint() const override
    {
        return {.topologyBytes = mTree.getTopologyBytes(),
                .payloadBytes = metrics::usedBytes(mPayload),
                .nodeCount = mTree.getNodeCount()};
    }
    double lookupRandom(const std::vector<glm::ivec3>& q) const override
    {
        double sum = 0.0;
        for (const auto& c : q) {
            const std::int64_t i = mTree.find(mDepth, c);
            sum += i >= 0 ? mPayload[std::size_t(i)].x : 0.0f;
        }
        return sum;
    }
    // A node with k of its 64 children present is one of C(64, k) masks: a code that knows k
    // and nothing of the pattern spends log2 C(64, k) bits on it at best. The tree stores each
    // mask as 64 bits, inline (the talk's node) or once in a table of distinct masks.
    double getMaskFloorBytes() const override
    {
        double bits = 0.0;
        for (std::size_t r = 0; r < mTree.getNodeCount(); ++r) {
            const int k = std::popcount(mTree.getRecord(r).getMask());
            bits +=
                (std::lgamma(65.0) - std::lgamma(k + 1.0) - std::lgamma(65.0 - k)) / std::log(2.0);
        }
        return bits / 8.0;
    }

    GpuLookup getGpuLookup() const override
    {
        // The dense first level's roots and the records as the cone gather uploads them.
        voxelgi::GpuTreeTopology packed = voxelgi::packTopologyForGpu(mTree);
        GpuLookup g{.shader = "tree_lookup.comp", .topology = std::move(packed.words)};
        g.payload.resize(mPayload.size());
        for (std::size_t i = 0; i < mPayload.size(); ++i)
            g.payload[i] = mPayload[i].x;
        g.constants = {glm::ivec4(mTree.getLayout().rootCells, int(packed.recordStart)),
                       packed.masks, glm::ivec4(0)};
        g.level = mDepth;
        return g;
    }
    double getMaskCount() const override
    {
        return mTree.getNodeMasks() == voxelgi::NodeMasks::Shared ? double(mTree.getMaskTable().size())
                                                                 : NAN;
    }

private:
    voxelgi::VoxelTreeBuildOptions mOptions;
    int mDepth;
    voxelgi::AdaptiveVoxelTree mTree;
    std::vector<glm::vec3> mPayload;
};

class Svo final : public Structure {
public:
    void build(const Voxels& v) override
    {
        const int longest = std::max({v.cells.x, v.cells.y, v.cells.z});
        int depth = 0;
        while ((1 << depth) < longest)
            ++depth;
        mTopology = voxelgi::OctreeTopology::build(depth, v.active);
        mPayload.assign(mTopology.child.size(), glm::vec3(0.0f));
        for (std::size_t i = 0; i < v.active.size(); ++i)
            mPayload[mTopology.leafNode[i]] = payloadOf(v.active[i]);
    }
    metrics::StructureFootprint footprint() const override
    {
        return {.topologyBytes = mTopology.getBytes(),
                .payloadBytes = metrics::usedBytes(mPayload),
                .nodeCount = mTopology.child.size()};
    }
    double lookupRandom(const std::vector<glm::ivec3>& q) const override
    {
        double sum = 0.0;
        for (const auto& c : q) {
            const std::int64_t i = mTopology.find(mTopology.depth, c);
            sum += i >= 0 ? mPayload[std::size_t(i)].x : 0.0f;
        }
        return sum;
    }

    GpuLookup getGpuLookup() const override
    {
        GpuLookup g{.shader = "octree_lookup.comp", .topology = mTopology.child};
        g.payload.resize(mPayload.size());
        for (std::size_t i = 0; i < mPayload.size(); ++i)
            g.payload[i] = mPayload[i].x;
        g.constants = {glm::ivec4(0)};
        g.level = mTopology.depth;
        return g;
    }

private:
    voxelgi::OctreeTopology mTopology;
    std::vector<glm::vec3> mPayload;
};

// Payload bytes of a VDB: the leaves' value buffers (512 values each, active or not); topology:
// everything else the grid reports (nodes, masks, the root table).
class OpenVdb final : public Structure {
public:
    void build(const Voxels& v) override
    {
        mGrid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        auto acc = mGrid->getAccessor();
        for (const auto& c : v.active) {
            const glm::vec3 p = payloadOf(c);
            acc.setValue(openvdb::Coord(c.x, c.y, c.z), openvdb::Vec3s(p.x, p.y, p.z));
        }
    }
    metrics::StructureFootprint footprint() const override
    {
        const std::size_t total = std::size_t(mGrid->memUsage());
        const std::size_t leaves = std::size_t(mGrid->tree().leafCount());
        const std::size_t payload = leaves * 512u * sizeof(openvdb::Vec3s);
        return {.topologyBytes = total - std::min(total, payload), .payloadBytes = payload,
                .nodeCount = std::size_t(mGrid->tree().nodeCount().size())};
    }
    double lookupRandom(const std::vector<glm::ivec3>& q) const override
    {
        double sum = 0.0;
        const auto& tree = mGrid->tree();
        for (const auto& c : q)
            sum += tree.getValue(openvdb::Coord(c.x, c.y, c.z)).x();
        return sum;
    }
    double lookupCoherent(const std::vector<glm::ivec3>& q) const override
    {
        double sum = 0.0;
        auto acc = mGrid->getConstAccessor();
        for (const auto& c : q)
            sum += acc.getValue(openvdb::Coord(c.x, c.y, c.z)).x();
        return sum;
    }
    const openvdb::Vec3SGrid& getGrid() const { return *mGrid; }

private:
    openvdb::Vec3SGrid::Ptr mGrid;
};

class NanoVdb final : public Structure {
public:
    void build(const Voxels& v) override
    {
        if (!mSource) {
            mSource = std::make_unique<OpenVdb>();
            mSource->build(v); // not timed apart: the conversion is the build measured below
        }
        mHandle = nanovdb::openToNanoVDB(mSource->getGrid());
        mGrid = mHandle.grid<nanovdb::Vec3f>();
    }
    metrics::StructureFootprint footprint() const override
    {
        const std::size_t total = std::size_t(mHandle.size());
        const std::size_t leaves = std::size_t(mGrid->tree().nodeCount(0));
        const std::size_t payload = leaves * 512u * sizeof(nanovdb::Vec3f);
        return {.topologyBytes = total - std::min(total, payload), .payloadBytes = payload,
                .nodeCount = leaves};
    }
    double lookupRandom(const std::vector<glm::ivec3>& q) const override
    {
        double sum = 0.0;
        const auto& tree = mGrid->tree();
        for (const auto& c : q)
            sum += tree.getValue(nanovdb::Coord(c.x, c.y, c.z))[0];
        return sum;
    }
    double lookupCoherent(const std::vector<glm::ivec3>& q) const override
    {
        double sum = 0.0;
        auto acc = mGrid->getAccessor();
        for (const auto& c : q)
            sum += acc.getValue(nanovdb::Coord(c.x, c.y, c.z))[0];
        return sum;
    }

private:
    std::unique_ptr<OpenVdb> mSource;
    nanovdb::GridHandle<nanovdb::HostBuffer> mHandle;
    const nanovdb::NanoGrid<nanovdb::Vec3f>* mGrid = nullptr;
};

std::unique_ptr<Structure> makeStructure(const std::string& name)
{
    if (name == "dense_grid")
        return std::make_unique<DenseGrid>();
    if (name == "cascades")
        return std::make_unique<Cascades>();
    if (name == "adaptive_voxel_tree")
        return std::make_unique<Avt>(voxelgi::VoxelTreeBuildOptions{}, 2);
    if (name == "adaptive_voxel_tree_undilated")
        return std::make_unique<Avt>(voxelgi::VoxelTreeBuildOptions{.dilate = false}, 2);
    if (name == "adaptive_voxel_tree_inline_masks")
        return std::make_unique<Avt>(
            voxelgi::VoxelTreeBuildOptions{.masks = voxelgi::NodeMasks::Inline}, 2);
    if (name == "adaptive_voxel_tree_depth3")
        return std::make_unique<Avt>(voxelgi::VoxelTreeBuildOptions{}, 3);
    if (name == "svo")
        return std::make_unique<Svo>();
    if (name == "openvdb")
        return std::make_unique<OpenVdb>();
    return std::make_unique<NanoVdb>();
}

void setMemoryCounters(benchmark::State& state, const Structure& s, const Voxels& v)
{
    const metrics::StructureFootprint f = s.footprint();
    const double n = double(std::max<std::size_t>(v.active.size(), 1));
    state.counters["voxels"] = double(v.active.size());
    state.counters["topology_B"] = double(f.topologyBytes) / n;
    state.counters["payload_B"] = double(f.payloadBytes) / n;
    state.counters["total_B"] = double(f.topologyBytes + f.payloadBytes) / n;
    if (const double floor = s.getMaskFloorBytes(); !std::isnan(floor))
        state.counters["mask_floor_B"] = floor / n;
    if (const double masks = s.getMaskCount(); !std::isnan(masks))
        state.counters["masks"] = masks;
}

void runBuild(benchmark::State& state, const std::string& sceneName, int resolution, const std::string& name)
{
    const Voxels& v = getVoxels(sceneName, resolution);
    auto s = makeStructure(name);
    s->build(v); // the NanoVDB source grid is made here, outside the timed loop
    for (auto _ : state) {
        s->build(v);
        benchmark::ClobberMemory();
    }
    setMemoryCounters(state, *s, v);
}

void runLookups(benchmark::State& state, const std::string& sceneName, int resolution, const std::string& name,
                bool coherent)
{
    const Voxels& v = getVoxels(sceneName, resolution);
    auto s = makeStructure(name);
    s->build(v);
    // Random: active voxels in shuffled order; coherent: every active voxel in (z, y, x) order.
    const std::vector<glm::ivec3>& q = coherent ? v.active : v.randomOrder;
    double checksum = 0.0;
    for (auto _ : state) {
        checksum = coherent ? s->lookupCoherent(q) : s->lookupRandom(q);
        benchmark::DoNotOptimize(checksum);
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(q.size()));
    setMemoryCounters(state, *s, v);
}

// Random lookups on Vulkan (lavapipe here): the same shuffled queries, one per invocation, one
// dispatch per iteration, timed by the wall clock around submit and wait (lavapipe's timestamps
// are not trustworthy: see the README). The results are checked against the CPU lookups once.
void runGpuLookups(benchmark::State& state, const std::string& sceneName, int resolution,
                   const std::string& name)
{
    static gpu::Context context;
    const Voxels& v = getVoxels(sceneName, resolution);
    auto s = makeStructure(name);
    s->build(v);
    GpuLookup g = s->getGpuLookup();
    const std::vector<glm::ivec3>& q = v.randomOrder;
    gpu::ShaderCompilerOptions options;
    options.includeDirs = {
        gpu::findShaderDir("techniques/voxel_gi/adaptive_voxel_tree_cones/shaders",
                           RTLAB_TREE_SHADER_DIR),
        gpu::findShaderDir("techniques/voxel_gi/svo/shaders", RTLAB_SVO_SHADER_DIR)};
    const gpu::ShaderCompiler compiler(options);
    gpu::ComputePipelineDesc desc;
    desc.name = name + ".lookup";
    desc.spirv =
        compiler
            .compileFile(gpu::findShaderDir("tests/families/shaders", RTLAB_BENCHMARK_SHADER_DIR) /
                         g.shader)
            .spirv;
    desc.bindings = {{0, gpu::BindingType::StorageBuffer},
                     {1, gpu::BindingType::StorageBuffer},
                     {2, gpu::BindingType::StorageBuffer},
                     {3, gpu::BindingType::StorageBuffer}};
    desc.pushConstantSize = std::uint32_t(g.constants.size() * sizeof(glm::ivec4));
    const gpu::ComputePipeline pipeline = context.createPipeline(desc);
    g.constants.back() = glm::ivec4(int(q.size()), g.level, 0, 0);
    std::vector<glm::ivec4> queries(q.size());
    for (std::size_t i = 0; i < q.size(); ++i)
        queries[i] = glm::ivec4(q[i], 0);
    const auto upload = [&](const auto& values, const char* label) {
        using T = typename std::decay_t<decltype(values)>::value_type;
        gpu::Buffer b =
            context.createBuffer({std::max<std::size_t>(values.size(), 1) * sizeof(T), label});
        b.template uploadSpan<T>(values);
        return b;
    };
    const gpu::Buffer topology = upload(g.topology, "lookup.topology");
    const gpu::Buffer payload = upload(g.payload, "lookup.payload");
    const gpu::Buffer queryBuffer = upload(queries, "lookup.queries");
    const gpu::Buffer results = context.createBuffer({q.size() * sizeof(float), "lookup.results"});
    const auto dispatch = [&] {
        context.run([&](gpu::CommandList& cmd) {
            cmd.dispatch(pipeline,
                         {gpu::Binding::storageBuffer(0, topology),
                          gpu::Binding::storageBuffer(1, payload),
                          gpu::Binding::storageBuffer(2, queryBuffer),
                          gpu::Binding::storageBuffer(3, results)},
                         gpu::PushConstants(g.constants.data(), desc.pushConstantSize),
                         gpu::GroupCount{gpu::computeGroupCount(q.size(), 64)}, "lookup");
        });
    };
    dispatch();
    const std::vector<float> got = results.downloadVector<float>(q.size());
    double gpuSum = 0.0;
    for (float x : got)
        gpuSum += x;
    const double cpuSum = s->lookupRandom(q);
    // The same floats summed in another order: 1e-6 relative.
    if (std::abs(gpuSum - cpuSum) > 1e-6 * std::abs(cpuSum)) {
        state.SkipWithError("the Vulkan lookups differ from the CPU lookups");
        return;
    }
    for (auto _ : state)
        dispatch();
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(q.size()));
    setMemoryCounters(state, *s, v);
}

} // namespace

int main(int argc, char** argv)
{
    openvdb::initialize();
    bool quick = false;
    std::vector<char*> args;
    for (int i = 0; i < argc; ++i) {
        if (std::strcmp(argv[i], "--quick") == 0)
            quick = true;
        else
            args.push_back(argv[i]);
    }
    static char minTime[] = "--benchmark_min_time=0.01";
    if (quick)
        args.push_back(minTime);
    int n = int(args.size());
    benchmark::Initialize(&n, args.data());
    const std::vector<std::string> scenes =
        quick ? std::vector<std::string>{"cornell_box"} : std::vector<std::string>{"cornell_box", "tomorrow_town"};
    const std::vector<int> resolutions = quick ? std::vector<int>{32, 64} : std::vector<int>{128, 256, 512};
    std::vector<std::pair<std::string, int>> sets;
    for (const std::string& sceneName : scenes)
        for (int r : resolutions)
            sets.emplace_back(sceneName, r);
    if (!quick)
        sets.emplace_back("narrow_band_sphere", 230); // r = 230 voxels: 4.0 M active voxels
    for (const auto& [sceneName, r] : sets)
        for (const std::string name :
             {"dense_grid", "cascades", "adaptive_voxel_tree", "adaptive_voxel_tree_undilated",
              "adaptive_voxel_tree_inline_masks", "adaptive_voxel_tree_depth3", "svo", "openvdb",
              "nanovdb"}) {
            // A dense grid over the band's box would take 468^3 x 12 bytes (1.2 GB).
            if (sceneName == "narrow_band_sphere" && name == "dense_grid")
                continue;
            const std::string prefix = sceneName + "/" + std::to_string(r) + "/" + name;
            benchmark::RegisterBenchmark(
                (prefix + "/build").c_str(),
                [=](benchmark::State& s) { runBuild(s, sceneName, r, name); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime();
            if (name == "cascades")
                continue;
            if (name == "adaptive_voxel_tree" || name == "svo")
                benchmark::RegisterBenchmark(
                    (prefix + "/lookup_random_gpu").c_str(),
                    [=](benchmark::State& s) { runGpuLookups(s, sceneName, r, name); })
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime();
            for (bool coherent : {false, true})
                benchmark::RegisterBenchmark(
                    (prefix + (coherent ? "/lookup_coherent" : "/lookup_random")).c_str(),
                    [=](benchmark::State& s) { runLookups(s, sceneName, r, name, coherent); })
                    ->Unit(benchmark::kMillisecond)
                    ->UseRealTime();
        }
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
