// adaptive_voxel_tree: Quantum Break's 64-ary adaptive voxel tree used as an adaptive irradiance
// volume, reconstructed per pixel with seamless interpolation across levels.
//
// Registry key: voxel_gi/adaptive_voxel_tree
//
// Talk: A. Silvennoinen and V. Timonen, "Multi-Scale Global Illumination in Quantum Break",
// SIGGRAPH 2015 Advances in Real-Time Rendering (seed shared/seeds/002_2c73d3b2bb6f7a13.txt,
// "Adaptive Voxel Tree" to "world space cells").
//
// Quantity: indirect diffuse irradiance at the G-buffer pixels, E = sum over bounces k = 1..B of
// E_k (reference.h "indirect" with bounces = B), as cascades computes it.
//
// Algorithm (voxel_tree.h):
// 1. voxelize: the static scene's box (padded by half a leaf) is split into a dense grid of root
//    cells of 4^depth leaves each; a leaf exists where a triangle meets it ("mark it as solid if
//    it intersects any of the triangles", exact triangle-box test,
//    families/voxel_gi/voxelize.h listCellsMeetingTriangles); the upper levels are its parents,
//    partially dilated. Rebuilt only when the static geometry changes (a dig).
// 2. inject light = the bake: one irradiance probe per element (every node and leaf) at its
//    centre. Its payload is the indirect irradiance about the six axis directions, each
//    estimated by the ground truth's path tracer (reference.h "indirect", the same bounces and
//    lights) with `bake_samples` paths; stored as an ambient cube (6 RGB values) or, with
//    `payload: sh_l1`, as the L1 irradiance E(n) = a + b.n fitted to those six values (least
//    squares; 4 RGB values). Quantum Break precomputes its GI offline: the bake is the
//    light_injection pass, timed apart from the gather, and skipped while the geometry and
//    lights are unchanged. Its time goes to the row's bake_ms, not technique_ms.
// 3. gather: per pixel, the seamless trilinear interpolation of the probes around the pixel
//    (at most two levels; corners missing at the finer level interpolated from its parent
//    level), the weights multiplied by the normal-based anti-leak term, then the payload
//    evaluated for the pixel's normal: E(n) = sum_i n_i^2 E_{axis i, sign n_i} for the ambient
//    cube, a + b.n (clamped at 0) for sh_l1. `interpolation: plain` uses one level only (missing
//    corners dropped), the comparison the talk makes.
// Characters and the occlusion family's cone visibilities are not used for the indirect light
// (the probes are static).
// 4. the sky: when the lit frame takes its sky from the probes, the bake also stores, per probe
//    and axis in the same payload form, the irradiance from the sky and the emissive surfaces
//    straight (reference.h "direct" without the point lights), so walls and roofs beyond any screen-space radius shadow the sky: the sky transport
//    of Quantum Break's probes. The lit frame takes it instead of the sky lobes (voxel_gi.h
//    combineConeSky), times the cosine-weighted mean of the occlusion family's 16 visibilities
//    when it gives them (the small-scale occlusion the probes' leaves are too coarse for).
// The tree as the structure of the 16-cone tracing: technique adaptive_voxel_tree_cones.
// Not yet: this gather on Vulkan (the tree's lookup is there: adaptive_voxel_tree_cones's
// shaders/tree_find.glsl).
//
// Parameters
// | name          | type  | default      | range / choices     | unit                         |
// |---------------|-------|--------------|---------------------|------------------------------|
// | resolution    | int   | 64           | [4, 4096]           | leaves along the longest side |
// | depth         | int   | 3            | [1, 6]              | levels below the root cells  |
// | payload       | enum  | ambient_cube | ambient_cube, sh_l1 |                              |
// | interpolation | enum  | seamless     | seamless, plain     |                              |
// | anti_leak     | bool  | true         |                     |                              |
// | dilate        | bool  | true         |                     | partial dilation (upper levels) |
// | node_masks    | enum  | shared       | shared, inline      |                              |
// | normal_offset | float | 0.5          | [0, 4]              | leaves along the normal      |
// | bake_samples  | int   | 32           | [1, 65536]          | paths per probe and axis     |
// | bounces       | int   | 2            | [1, 8]              |                              |
//
// node_masks: shared keeps the child masks in one table of the tree's distinct masks, each
// record a bit field of 12 + log2(table size) bits (voxel_tree.h); inline keeps the talk's
// 12-byte record (64-bit mask + offset). Lookups give the same elements either way.
//
// Config example:
//   techniques:
//     voxel_gi: {technique: adaptive_voxel_tree, params: {resolution: 128, payload: sh_l1}}

#include "voxel_tree.h"

#include "core/error.h"
#include "families/voxel_gi/cone_tracing.h"
#include "families/voxel_gi/voxel_gi.h"
#include "families/voxel_gi/voxelize.h"
#include "reference/reference.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <string>

namespace {

using namespace rtlab;

constexpr int kAxes = 6; // +x, -x, +y, -y, +z, -z (voxelize.h's face order)
constexpr int kProbesPerRow = 64; // probes per row of the bake's G-buffer (6 axes each)

class AdaptiveVoxelTreeGi final : public plugin::VoxelGiTechnique {
public:
    static plugin::TechniqueInfo describe()
    {
        return {.summary = "64-ary adaptive voxel tree of baked irradiance probes, seamless "
                           "interpolation across levels",
                .reference = "Silvennoinen & Timonen, Multi-Scale Global Illumination in "
                             "Quantum Break, SIGGRAPH 2015",
                .seed = "002_2c73d3b2bb6f7a13.txt"};
    }

    static config::ParamSchema declareParams()
    {
        config::ParamSchema schema;
        schema.addInt("resolution", 64, 4, 4096, "leaves", "leaves along the longest side of the "
                                                           "static scene's box");
        schema.addInt("depth", 3, 1, 6, "", "tree levels below the dense root cells (4^depth "
                                            "leaves per root cell and axis)");
        schema.addEnum("payload", "ambient_cube", {"ambient_cube", "sh_l1"},
                       "probe payload: irradiance about the 6 axes, or L1 (constant + linear)");
        schema.addEnum("interpolation", "seamless", {"seamless", "plain"},
                       "across levels (missing corners from the parent) or one level only");
        schema.addBool("anti_leak", true, "normal-based weight multiplied into the trilinear weights");
        schema.addBool("dilate", true, "partial dilation of the upper levels");
        schema.addEnum("node_masks", "shared", {"shared", "inline"},
                       "the node records' child masks in one table of the distinct masks (a "
                       "bit-packed record of 12 + log2(table) bits), or in each record (the "
                       "talk's 12 bytes: mask + offset); lookups give the same elements");
        schema.addFloat("normal_offset", 0.5, 0.0, 4.0, "leaves",
                        "the pixel's lookup point moved along its normal (away from probes "
                        "inside the surface it lies on)");
        schema.addInt("bake_samples", 32, 1, 65536, "paths", "paths per probe and axis in the bake");
        schema.addInt("bounces", 2, 1, 8, "", "reflections before the light reaches the pixel");
        return schema;
    }

    explicit AdaptiveVoxelTreeGi(const config::ParamSet& p)
        : mResolution(int(p.getInt("resolution"))), mDepth(int(p.getInt("depth"))),
          mShL1(p.getString("payload") == "sh_l1"), mPlain(p.getString("interpolation") == "plain"),
          mAntiLeak(p.getBool("anti_leak")), mDilate(p.getBool("dilate")),
          mInlineMasks(p.getString("node_masks") == "inline"),
          mNormalOffset(p.getFloat("normal_offset")), mBakeSamples(int(p.getInt("bake_samples"))),
          mBounces(int(p.getInt("bounces")))
    {
    }

    config::ParamSet effectiveParams() const override
    {
        config::ParamSet p;
        p.set("resolution", std::int64_t(mResolution));
        p.set("depth", std::int64_t(mDepth));
        p.set("payload", std::string(mShL1 ? "sh_l1" : "ambient_cube"));
        p.set("interpolation", std::string(mPlain ? "plain" : "seamless"));
        p.set("anti_leak", mAntiLeak);
        p.set("dilate", mDilate);
        p.set("node_masks", std::string(mInlineMasks ? "inline" : "shared"));
        p.set("normal_offset", mNormalOffset);
        p.set("bake_samples", std::int64_t(mBakeSamples));
        p.set("bounces", std::int64_t(mBounces));
        return p;
    }

    plugin::VoxelGiDefinition definition() const override
    {
        return {.bounces = mBounces, .precomputedLight = true};
    }

    plugin::VoxelGiStep voxelize(const plugin::VoxelGiFrame& frame) override
    {
        if (!frame.force && mBuilt && frame.geometryKey == mGeometryKey)
            return plugin::VoxelGiStep::skipped("the static geometry is unchanged since the build");
        const scene::RenderScene& g = *frame.geometry;
        mGeometryKey = frame.geometryKey;
        mBuilt = true;
        mBakedKey.clear();
        mTree.reset();
        mPayload.clear();
        mSkyPayload.clear();
        if (g.indices.empty())
            return plugin::VoxelGiStep::done("no geometry: an empty tree");
        // The box: the geometry's bounds padded by half a leaf, so that no surface lies on the
        // box's faces; root cells of 4^depth leaves cover it.
        const glm::dvec3 lo(g.boundsMin), hi(g.boundsMax);
        if (!std::isfinite(lo.x + lo.y + lo.z + hi.x + hi.y + hi.z))
            throw Error("adaptive_voxel_tree: the scene's bounds are not finite (a vertex is "
                        "NaN or infinite)");
        const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
        const double minExtent =
            1e-6 * std::max(1.0, glm::length(glm::max(glm::abs(lo), glm::abs(hi))));
        mLeafSize = std::max(extent, minExtent) / double(mResolution);
        mOrigin = lo - 0.5 * mLeafSize;
        voxelgi::VoxelTreeLayout layout;
        layout.depth = mDepth;
        const double rootSize = mLeafSize * std::ldexp(1.0, 2 * mDepth);
        for (int a = 0; a < 3; ++a)
            layout.rootCells[a] = std::max(1, int(std::ceil((hi[a] - lo[a] + mLeafSize) / rootSize)));
        const std::vector<glm::ivec3> leaves = voxelgi::listCellsMeetingTriangles(
            g, mOrigin, mLeafSize, layout.getCells(mDepth));
        mTree.emplace(voxelgi::AdaptiveVoxelTree::build(
            layout, leaves,
            {.dilate = mDilate,
             .masks = mInlineMasks ? voxelgi::NodeMasks::Inline : voxelgi::NodeMasks::Shared}));
        return plugin::VoxelGiStep::done(
            "built the tree: " + std::to_string(mTree->getLeafCount()) + " leaves, " +
            std::to_string(mTree->getNodeCount()) + " nodes (" + std::to_string(layout.rootCells.x) +
            "x" + std::to_string(layout.rootCells.y) + "x" + std::to_string(layout.rootCells.z) +
            " root cells, leaf " + std::to_string(mLeafSize) + ")");
    }

    plugin::VoxelGiStep injectLight(const plugin::VoxelGiFrame& frame) override
    {
        const std::string key = mGeometryKey + voxelgi::computeLightsKey(*frame.geometry) +
                                (frame.coneSky ? " with the sky" : "");
        if (!frame.force && key == mBakedKey)
            return plugin::VoxelGiStep::skipped("baked for this geometry and these lights");
        mBakedKey = key;
        if (!mTree)
            return plugin::VoxelGiStep::done("no probes to bake");
        bake(*frame.geometry, frame.coneSky);
        return plugin::VoxelGiStep::done(
            "baked " + std::to_string(mTree->getElementCount()) + " probes x 6 axes x " +
            std::to_string(mBakeSamples) + " paths in " + std::to_string(mBakeSeconds) + " s");
    }

    void gather(const plugin::VoxelGiInput& input, Image<glm::vec3>& irradiance) override
    {
        irradiance = evaluateAtPixels(*input.gbuffer, mPayload, nullptr);
    }

    std::string combineConeSky(const plugin::VoxelGiInput& input, Image<glm::vec3>& irradiance) override
    {
        if (!mTree || mSkyPayload.empty())
            return "no sky baked into the probes";
        const bool cones = input.coneVisibility != nullptr &&
                           input.coneVisibility->size() == std::size_t(voxelgi::kConeCount);
        irradiance = evaluateAtPixels(*input.gbuffer, mSkyPayload, cones ? input.coneVisibility : nullptr);
        return {};
    }

    bool computeLookupLevels(const plugin::VoxelGiInput& input,
                             Image<std::uint8_t>& levels) override
    {
        const scene::GBuffer& g = *input.gbuffer;
        levels = Image<std::uint8_t>(g.width, g.height, kNoLevel);
        if (!mTree || mPayload.empty())
            return false;
        tbb::parallel_for(0, g.height, [&](int y) {
            for (int x = 0; x < g.width; ++x)
                if (g.hasSurface(x, y))
                    levels.at(x, y) = std::uint8_t(
                        getStencil(glm::dvec3(g.position.at(x, y)), glm::dvec3(g.normal.at(x, y)))
                            .level);
        });
        return true;
    }

    plugin::VoxelGiMemory memory() const override
    {
        if (!mTree)
            return {};
        return {.topologyBytes = mTree->getTopologyBytes(),
                .payloadBytes = (mPayload.size() + mSkyPayload.size()) * sizeof(glm::vec3)};
    }

    std::vector<std::pair<std::string, double>> counters() const override
    {
        if (!mTree)
            return {};
        return {{"leaf_size", mLeafSize},
                {"leaves", double(mTree->getLeafCount())},
                {"nodes", double(mTree->getNodeCount())},
                {"mask_table", double(mTree->getMaskTable().size())}, // 0: inline masks
                {"probes", double(mTree->getElementCount())},
                {"bake_s", mBakeSeconds}};
    }

private:
    int payloadVectors() const { return mShL1 ? 4 : kAxes; }

    // The six axis irradiances of every probe by the ground truth's estimator: one G-buffer
    // "pixel" per probe and axis, at the probe's centre with the axis as its normal.
    void bake(const scene::RenderScene& geometry, bool withSky)
    {
        const auto start = std::chrono::steady_clock::now();
        const std::vector<glm::ivec4> cells = mTree->listElementCells();
        const std::size_t probes = cells.size();
        scene::GBuffer g;
        g.width = kProbesPerRow * kAxes;
        g.height = int((probes + kProbesPerRow - 1) / kProbesPerRow);
        g.depth = Image<float>(g.width, g.height, 1.0f);
        g.position = Image<glm::vec3>(g.width, g.height, glm::vec3(0.0f));
        g.normal = Image<glm::vec3>(g.width, g.height, glm::vec3(0.0f));
        g.albedo = Image<glm::vec3>(g.width, g.height, glm::vec3(1.0f));
        g.emission = Image<glm::vec3>(g.width, g.height, glm::vec3(0.0f));
        g.materialId = Image<std::uint32_t>(g.width, g.height, scene::kNoMaterial);
        for (std::size_t i = 0; i < probes; ++i) {
            const glm::dvec3 centre = getCentre(cells[i]);
            for (int a = 0; a < kAxes; ++a) {
                const int x = int(i % kProbesPerRow) * kAxes + a, y = int(i / kProbesPerRow);
                g.position.at(x, y) = glm::vec3(centre);
                g.normal.at(x, y) = voxelgi::getFaceNormal(a);
                g.materialId.at(x, y) = 0;
            }
        }
        const reference::ReferenceSettings s = reference::makeFixedSampleSettings(
            reference::Quantity::Indirect, mBounces, mBakeSamples, 0xba4e0000ull);
        store(reference::computeReference(geometry, g, s).irradiance, probes, mPayload);
        // The sky and the emitters straight, when the frame takes its sky from the probes:
        // "direct" of the scene without its point lights (which the frame lights with their
        // shadow maps).
        mSkyPayload.clear();
        if (!withSky) {
            mBakeSeconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            return;
        }
        scene::RenderScene skyAndEmitters = geometry;
        skyAndEmitters.pointLights.clear();
        const reference::ReferenceSettings sky = reference::makeFixedSampleSettings(
            reference::Quantity::Direct, 1, mBakeSamples, 0xba4e5c00ull);
        store(reference::computeReference(skyAndEmitters, g, sky).irradiance, probes, mSkyPayload);
        mBakeSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }

    // The payload of every probe from its six axis irradiances (the bake's image, one row of
    // kProbesPerRow probes x 6 axes).
    void store(const Image<glm::vec3>& e, std::size_t probes, std::vector<glm::vec3>& payload) const
    {
        const int m = payloadVectors();
        payload.assign(probes * std::size_t(m), glm::vec3(0.0f));
        for (std::size_t i = 0; i < probes; ++i) {
            std::array<glm::vec3, kAxes> axis{};
            for (int a = 0; a < kAxes; ++a)
                axis[std::size_t(a)] = e.at(int(i % kProbesPerRow) * kAxes + a, int(i / kProbesPerRow));
            glm::vec3* out = &payload[i * std::size_t(m)];
            if (!mShL1) {
                std::copy(axis.begin(), axis.end(), out);
                continue;
            }
            // Least-squares fit of E(n) = a + b.n to the six axis values: a is their mean, b
            // the half-differences of opposite axes.
            out[0] = (axis[0] + axis[1] + axis[2] + axis[3] + axis[4] + axis[5]) / 6.0f;
            out[1] = 0.5f * (axis[0] - axis[1]);
            out[2] = 0.5f * (axis[2] - axis[3]);
            out[3] = 0.5f * (axis[4] - axis[5]);
        }
    }

    glm::dvec3 getCentre(const glm::ivec4& cell) const
    {
        const double size = mLeafSize * std::ldexp(1.0, 2 * (mDepth - cell.w));
        return mOrigin + (glm::dvec3(glm::ivec3(cell)) + 0.5) * size;
    }

    voxelgi::TreeStencil getStencil(const glm::dvec3& p, const glm::dvec3& n) const
    {
        voxelgi::TreeQuery q;
        q.origin = mOrigin;
        q.leafSize = mLeafSize;
        q.mode = mPlain ? voxelgi::TreeInterpolation::Plain : voxelgi::TreeInterpolation::Seamless;
        if (mAntiLeak)
            q.normal = n;
        return voxelgi::interpolate(*mTree, q, p + n * (mNormalOffset * mLeafSize));
    }

    glm::dvec3 evaluate(const glm::dvec3& p, const glm::dvec3& n) const { return evaluate(p, n, mPayload); }

    // `values` (a payload) evaluated at every pixel with a surface, 0 elsewhere (and everywhere
    // before a bake); with `visibility` (16 images) times the pixel's cosine-weighted mean of
    // them (the cone irradiance weights sum to pi).
    Image<glm::vec3> evaluateAtPixels(const scene::GBuffer& g, const std::vector<glm::vec3>& values,
                                      const std::vector<Image<float>>* visibility) const
    {
        Image<glm::vec3> out(g.width, g.height, glm::vec3(0.0f));
        if (!mTree || values.empty())
            return out;
        const voxelgi::ConeSet coneSet = voxelgi::ConeSet::make(29.0);
        tbb::parallel_for(0, g.height, [&](int y) {
            for (int x = 0; x < g.width; ++x) {
                if (!g.hasSurface(x, y))
                    continue;
                const glm::dvec3 n(g.normal.at(x, y));
                const glm::dvec3 p(g.position.at(x, y));
                double visible = 1.0;
                if (visibility != nullptr) {
                    const auto w = voxelgi::computeIrradianceWeights(coneSet, n);
                    visible = 0.0;
                    for (int k = 0; k < voxelgi::kConeCount; ++k)
                        visible += w[std::size_t(k)] *
                                   std::clamp(double((*visibility)[std::size_t(k)].at(x, y)), 0.0, 1.0);
                    visible /= glm::pi<double>();
                }
                out.at(x, y) = glm::vec3(visible * evaluate(p, n, values));
            }
        });
        return out;
    }

    glm::dvec3 evaluate(const glm::dvec3& p, const glm::dvec3& n, const std::vector<glm::vec3>& values) const
    {
        const voxelgi::TreeStencil st = getStencil(p, n);
        const int m = payloadVectors();
        std::array<glm::dvec3, kAxes> v{};
        for (int i = 0; i < st.count; ++i) {
            const glm::vec3* payload = &values[std::size_t(st.index[std::size_t(i)]) * std::size_t(m)];
            for (int k = 0; k < m; ++k)
                v[std::size_t(k)] += double(st.weight[std::size_t(i)]) * glm::dvec3(payload[k]);
        }
        glm::dvec3 e;
        if (mShL1)
            e = v[0] + n.x * v[1] + n.y * v[2] + n.z * v[3];
        else
            e = n.x * n.x * v[n.x >= 0.0 ? 0 : 1] + n.y * n.y * v[n.y >= 0.0 ? 2 : 3] +
                n.z * n.z * v[n.z >= 0.0 ? 4 : 5];
        return glm::max(e, glm::dvec3(0.0));
    }

    int mResolution;
    int mDepth;
    bool mShL1;
    bool mPlain;
    bool mAntiLeak;
    bool mDilate;
    bool mInlineMasks = false;
    double mNormalOffset;
    int mBakeSamples;
    int mBounces;

    bool mBuilt = false;
    std::string mGeometryKey;
    std::string mBakedKey;
    std::optional<voxelgi::AdaptiveVoxelTree> mTree;
    glm::dvec3 mOrigin{0.0};
    double mLeafSize = 1.0;
    std::vector<glm::vec3> mPayload; //!< [probe * payloadVectors() + k]
    std::vector<glm::vec3> mSkyPayload; //!< the same for the sky and the emitters
    double mBakeSeconds = 0.0;
};

} // namespace

RTLAB_REGISTER_TECHNIQUE(voxel_gi, adaptive_voxel_tree, AdaptiveVoxelTreeGi)
