#include "families/voxel_gi/voxelize_gpu.h"

#include "core/error.h"
#include "gpu/shader_compiler.h"

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>

namespace rtlab::voxelgi {

namespace {

struct ColumnConstants {
    glm::ivec4 size{0};     // R, S, solid
    glm::ivec4 boxBegin{0};
    glm::ivec4 boxEnd{0};
    glm::vec4 scale{0.0f};  // voxel size, ray spacing
    glm::ivec4 ray{0};      // x: the ray within the column
};
static_assert(sizeof(ColumnConstants) == 80, "must match voxelize_columns.comp");

struct ResolveConstants {
    glm::ivec4 size{0}; // R, S
};

struct GpuTriangle {
    glm::vec4 p[3];
    glm::vec4 normal; // w: material index bits
};
static_assert(sizeof(GpuTriangle) == 64, "must match voxelize_columns.comp");

gpu::ComputePipeline makePipeline(gpu::Context& context, const char* file, const char* label,
                                  std::uint32_t bindings, std::size_t pushConstants)
{
    gpu::ComputePipelineDesc desc;
    desc.name = label;
    desc.spirv = gpu::ShaderCompiler().compileFile(VoxelizerGpu::getShaderDir() / file).spirv;
    for (std::uint32_t b = 0; b < bindings; ++b)
        desc.bindings.push_back({b, gpu::BindingType::StorageBuffer});
    desc.pushConstantSize = std::uint32_t(pushConstants);
    return context.createPipeline(desc);
}

} // namespace

std::filesystem::path VoxelizerGpu::getShaderDir()
{
    return gpu::findShaderDir("framework/families/voxel_gi/shaders",
                              std::filesystem::path(RTLAB_VOXEL_GI_SHADER_DIR));
}

gpu::Buffer& VoxelizerGpu::reserve(gpu::Buffer& buffer, std::size_t bytes, const char* name,
                                   bool hostVisible)
{
    bytes = std::max<std::size_t>(bytes, 16);
    if (!buffer.isValid() || buffer.getSize() < bytes)
        buffer = mContext->createBuffer({.size = bytes, .name = name, .hostVisible = hostVisible});
    return buffer;
}

VoxelGrid VoxelizerGpu::voxelize(gpu::Context& context, const scene::RenderScene& scene,
                                 const VoxelRegion& region, const VoxelizeOptions& options,
                                 VoxelizeStats* stats)
{
    checkVoxelizeArguments(region, options, kMaxResolution);
    const auto start = std::chrono::steady_clock::now();
    ++mCounters.calls;
    if (mContext != &context || !mColumns.isValid()) {
        const Counters kept = mCounters;
        *this = VoxelizerGpu();
        mCounters = kept;
        mContext = &context;
        mColumns = makePipeline(context, "voxelize_columns.comp", kColumnsLabel, 8, sizeof(ColumnConstants));
        mResolve = makePipeline(context, "voxelize_resolve.comp", kResolveLabel, 6, sizeof(ResolveConstants));
    }
    const int R = region.resolution;
    const int S = options.supersampling;
    glm::ivec3 boxBegin, boxEnd;
    getVoxelizeBox(region, options, boxBegin, boxEnd);
    const glm::dvec3 lo = region.origin, hi = region.getMaxCorner();
    VoxelizeStats local;

    // The valid triangles that meet the region's columns along some axis, in their scene order
    // (the fragments' tie-break), relative to the region's min corner; and per axis the columns
    // of the box their projection's bounds overlap ("voxel row" buckets of the C++ path, split
    // by column too).
    const std::size_t triCount = scene.triangleCount();
    std::vector<GpuTriangle> tris;
    std::vector<std::array<glm::ivec4, 3>> spans; // per kept triangle and axis: cu0, cu1, cv0, cv1
    for (std::size_t t = 0; t < triCount; ++t) {
        glm::dvec3 p[3];
        for (int k = 0; k < 3; ++k)
            p[k] = glm::dvec3(scene.positions[scene.indices[3 * t + std::size_t(k)]]);
        const glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
        const double len = glm::length(n);
        if (!(len > 0.0) || !std::isfinite(len))
            continue;
        const glm::dvec3 tmin = glm::min(p[0], glm::min(p[1], p[2]));
        const glm::dvec3 tmax = glm::max(p[0], glm::max(p[1], p[2]));
        int overlapping = 0;
        for (int a = 0; a < 3; ++a)
            overlapping += (tmax[a] >= lo[a] && tmin[a] <= hi[a]) ? 1 : 0;
        if (overlapping >= 2)
            ++local.trianglesConsidered;
        std::array<glm::ivec4, 3> span;
        bool any = false;
        for (int a = 0; a < 3; ++a) {
            const int u = (a + 1) % 3, v = (a + 2) % 3;
            glm::ivec4& s = span[std::size_t(a)];
            s = glm::ivec4(0, -1, 0, -1);
            if (tmax[u] < lo[u] || tmin[u] > hi[u] || tmax[v] < lo[v] || tmin[v] > hi[v])
                continue;
            s.x = std::max(boxBegin[u], int(std::floor((tmin[u] - lo[u]) / region.voxelSize)));
            s.y = std::min(boxEnd[u] - 1, int(std::floor((tmax[u] - lo[u]) / region.voxelSize)));
            s.z = std::max(boxBegin[v], int(std::floor((tmin[v] - lo[v]) / region.voxelSize)));
            s.w = std::min(boxEnd[v] - 1, int(std::floor((tmax[v] - lo[v]) / region.voxelSize)));
            any = any || (s.x <= s.y && s.z <= s.w);
        }
        if (!any)
            continue;
        GpuTriangle g;
        for (int k = 0; k < 3; ++k)
            g.p[k] = glm::vec4(glm::vec3(p[k] - lo), 0.0f);
        float material;
        const std::uint32_t m = scene.triangleMaterial[t];
        std::memcpy(&material, &m, sizeof(material));
        g.normal = glm::vec4(glm::vec3(n / len), material);
        tris.push_back(g);
        spans.push_back(span);
    }
    const std::size_t columns = std::size_t(R) * std::size_t(R);
    std::vector<std::uint32_t> binStart(3 * columns + 1, 0);
    for (const auto& span : spans)
        for (int a = 0; a < 3; ++a) {
            const glm::ivec4& s = span[std::size_t(a)];
            for (int cv = s.z; cv <= s.w; ++cv)
                for (int cu = s.x; cu <= s.y; ++cu)
                    ++binStart[std::size_t(a) * columns + std::size_t(cu) + std::size_t(R) * std::size_t(cv) + 1];
        }
    std::uint32_t largestBin = 0;
    for (std::size_t i = 1; i < binStart.size(); ++i) {
        largestBin = std::max(largestBin, binStart[i]);
        binStart[i] += binStart[i - 1];
    }
    if (largestBin > kMaxTrianglesPerColumn) {
        // One invocation loops over its column's triangles; past this many, lavapipe's cap on
        // loop iterations could cut it short: the exact C++ path.
        ++mCounters.fallbacks;
        mCounters.callMs +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        return voxelizeTriangles(scene, region, options, stats);
    }
    std::vector<std::uint32_t> bins(binStart.back());
    {
        std::vector<std::uint32_t> fill(binStart.begin(), binStart.end() - 1);
        for (std::size_t t = 0; t < spans.size(); ++t)
            for (int a = 0; a < 3; ++a) {
                const glm::ivec4& s = spans[t][std::size_t(a)];
                for (int cv = s.z; cv <= s.w; ++cv)
                    for (int cu = s.x; cu <= s.y; ++cu)
                        bins[fill[std::size_t(a) * columns + std::size_t(cu) + std::size_t(R) * std::size_t(cv)]++] =
                            std::uint32_t(t);
            }
    }
    std::vector<glm::vec4> materials(std::max<std::size_t>(scene.materials.size(), 1) * 2, glm::vec4(0.0f));
    for (std::size_t m = 0; m < scene.materials.size(); ++m) {
        materials[2 * m] = glm::vec4(scene.materials[m].albedo, 0.0f);
        materials[2 * m + 1] = glm::vec4(scene.materials[m].emission, 0.0f);
    }
    if (!tris.empty())
        reserve(mTriangles, tris.size() * sizeof(GpuTriangle), "voxelize.triangles").uploadSpan<GpuTriangle>(tris);
    else
        reserve(mTriangles, sizeof(GpuTriangle), "voxelize.triangles");
    reserve(mMaterials, materials.size() * sizeof(glm::vec4), "voxelize.materials").uploadSpan<glm::vec4>(materials);
    reserve(mBinStart, binStart.size() * sizeof(std::uint32_t), "voxelize.bin_start").uploadSpan<std::uint32_t>(binStart);
    if (!bins.empty())
        reserve(mBins, bins.size() * sizeof(std::uint32_t), "voxelize.bins").uploadSpan<std::uint32_t>(bins);
    else
        reserve(mBins, 16, "voxelize.bins");
    mCounters.uploadBytes += tris.size() * sizeof(GpuTriangle) + materials.size() * sizeof(glm::vec4) +
                             (binStart.size() + bins.size()) * sizeof(std::uint32_t);

    const std::size_t voxels = region.getVoxelCount();
    reserve(mCounts, voxels * 9 * sizeof(std::uint32_t), "voxelize.counts");
    reserve(mFaceSums, voxels * kFaceCount * 2 * sizeof(glm::vec4), "voxelize.face_sums");
    reserve(mNormalSums, voxels * 3 * sizeof(glm::vec4), "voxelize.normal_sums");
    // Written once by the resolve and read back: host-visible. The accumulators above take the
    // atomics and the inputs are read once per ray of the columns: device memory.
    reserve(mStats, 4 * sizeof(std::uint32_t), "voxelize.stats", true);
    reserve(mFaces, voxels * kFaceCount * sizeof(glm::vec4), "voxelize.faces", true);
    reserve(mEmission, voxels * kFaceCount * sizeof(glm::vec4), "voxelize.emission", true);
    reserve(mNormals, voxels * sizeof(glm::vec4), "voxelize.normals", true);

    ColumnConstants columnConstants;
    columnConstants.size = {R, S, options.solid ? 1 : 0, 0};
    columnConstants.boxBegin = glm::ivec4(boxBegin, 0);
    columnConstants.boxEnd = glm::ivec4(boxEnd, 0);
    columnConstants.scale = {float(region.voxelSize), float(region.voxelSize / S), 0.0f, 0.0f};
    ResolveConstants resolveConstants;
    resolveConstants.size = {R, S, 0, 0};
    const gpu::RunResult result = mContext->run([&](gpu::CommandList& cmd) {
        cmd.fillBuffer(mCounts, 0u, "voxelize.clear");
        cmd.fillBuffer(mFaceSums, 0u, "voxelize.clear");
        cmd.fillBuffer(mNormalSums, 0u, "voxelize.clear");
        cmd.fillBuffer(mStats, 0u, "voxelize.clear");
        // One dispatch per ray of the columns, in the C++ path's order (rows of rays, then rays).
        for (int ray = 0; ray < S * S; ++ray) {
            columnConstants.ray.x = ray;
            cmd.dispatch(mColumns,
                         {gpu::Binding::storageBuffer(0, mTriangles), gpu::Binding::storageBuffer(1, mMaterials),
                          gpu::Binding::storageBuffer(2, mBinStart), gpu::Binding::storageBuffer(3, mBins),
                          gpu::Binding::storageBuffer(4, mCounts), gpu::Binding::storageBuffer(5, mFaceSums),
                          gpu::Binding::storageBuffer(6, mNormalSums), gpu::Binding::storageBuffer(7, mStats)},
                         gpu::PushConstants(columnConstants),
                         gpu::GroupCount{gpu::computeGroupCount(3 * std::uint64_t(columns), 64), 1, 1},
                         kColumnsLabel);
        }
        cmd.dispatch(mResolve,
                     {gpu::Binding::storageBuffer(0, mCounts), gpu::Binding::storageBuffer(1, mFaceSums),
                      gpu::Binding::storageBuffer(2, mNormalSums), gpu::Binding::storageBuffer(3, mFaces),
                      gpu::Binding::storageBuffer(4, mEmission), gpu::Binding::storageBuffer(5, mNormals)},
                     gpu::PushConstants(resolveConstants),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(voxels), 64), 1, 1}, kResolveLabel);
    });
    mCounters.submitMs += result.cpuSubmitMs;
    const std::vector<std::uint32_t> counters = mStats.downloadVector<std::uint32_t>(4);
    VoxelGrid grid;
    if (counters[1] > 0) {
        // Some ray met more surfaces than the shader keeps: the exact C++ path.
        ++mCounters.fallbacks;
        grid = voxelizeTriangles(scene, region, options, stats);
    } else {
        local.fragments = counters[0];
        const std::vector<glm::vec4> faces = mFaces.downloadVector<glm::vec4>(voxels * kFaceCount);
        const std::vector<glm::vec4> emission = mEmission.downloadVector<glm::vec4>(voxels * kFaceCount);
        const std::vector<glm::vec4> normals = mNormals.downloadVector<glm::vec4>(voxels);
        grid.region = region;
        grid.faces = faces;
        grid.emission.resize(voxels * kFaceCount);
        for (std::size_t i = 0; i < grid.emission.size(); ++i)
            grid.emission[i] = glm::vec3(emission[i]);
        grid.normal.resize(voxels);
        grid.flags.resize(voxels);
        for (std::size_t v = 0; v < voxels; ++v) {
            grid.normal[v] = glm::vec3(normals[v]);
            grid.flags[v] = std::uint8_t(normals[v].w);
        }
        local.solidVoxels = finalizeVoxelGrid(grid);
        local.surfaceVoxels = grid.surfaceVoxels.size();
        if (stats)
            *stats = local;
    }
    mCounters.callMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return grid;
}

} // namespace rtlab::voxelgi
