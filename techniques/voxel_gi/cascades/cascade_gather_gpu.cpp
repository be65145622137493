#include "cascade_gather_gpu.h"

#include "core/error.h"
#include "gpu/shader_compiler.h"

#include <glm/vec4.hpp>

#include <algorithm>
#include <cstdlib>

namespace rtlab::voxelgi {

namespace {

struct GatherConstants {
    glm::ivec4 size{0};  // width, height, levels, resolution
    glm::vec4 march{0};  // level-0 voxel size, tan(half-angle), start offset, step scale
    glm::ivec4 flags{0}; // visibility given, max steps
};
static_assert(sizeof(GatherConstants) == 48, "must match cascade_gather.comp");

struct LevelDesc {
    glm::vec4 origin{0.0f};
    glm::vec4 centre{0.0f, 0.0f, 0.0f, -1.0f};
};

gpu::Buffer makeBuffer(gpu::Context& context, std::size_t bytes, const char* name)
{
    return context.createBuffer({std::max<std::size_t>(bytes, 16), name});
}

} // namespace

std::filesystem::path CascadeGatherGpu::getShaderDir()
{
    if (const char* root = std::getenv("RTLAB_SOURCE_DIR"); root != nullptr && *root != '\0')
        return std::filesystem::path(root) / "techniques" / "voxel_gi" / "cascades" / "shaders";
    return std::filesystem::path(RTLAB_TECHNIQUE_DIR) / "shaders";
}

void CascadeGatherGpu::gatherCones(gpu::Context& context, const CascadeVolume& volume,
                                   const scene::GBuffer& gbuffer, std::vector<glm::vec3>& out)
{
    const CascadeSettings& settings = volume.getSettings();
    if (!settings.precombine)
        throw Error("cascades: the Vulkan gather reads the pre-combined direction buffers "
                    "(precombine: true)");
    if (mContext != &context) {
        *this = CascadeGatherGpu();
        mContext = &context;
    }
    if (!mPipeline.isValid()) {
        const gpu::ShaderCompiler compiler;
        gpu::ComputePipelineDesc desc;
        desc.name = kDispatchLabel;
        desc.spirv = compiler.compileFile(getShaderDir() / "cascade_gather.comp").spirv;
        for (std::uint32_t b = 0; b < 6; ++b)
            desc.bindings.push_back({b, gpu::BindingType::StorageBuffer});
        desc.pushConstantSize = sizeof(GatherConstants);
        mPipeline = context.createPipeline(desc);
        std::vector<glm::vec4> cones(kConeCount);
        for (int k = 0; k < kConeCount; ++k)
            cones[std::size_t(k)] = glm::vec4(glm::vec3(volume.getCones().directions[std::size_t(k)]), 0.0f);
        mCones = makeBuffer(context, cones.size() * sizeof(glm::vec4), "cascades.cones");
        mCones.uploadSpan<glm::vec4>(cones);
    }
    mLastUploadBytes = 0;
    const int n = volume.getLevelCount();
    const int R = settings.resolution;
    const std::size_t levelVoxels = std::size_t(R) * std::size_t(R) * std::size_t(R);
    const std::size_t levelBytes = levelVoxels * kConeCount * sizeof(glm::vec4);
    if (mCombinedLevelVoxels != levelVoxels || mCombinedLevelCount != n) {
        mCombined = makeBuffer(context, levelBytes * std::size_t(n), "cascades.combined");
        mCombinedLevelVoxels = levelVoxels;
        mCombinedLevelCount = n;
        mUploadedStamps.assign(std::size_t(n), 0);
    }
    // Everything relative to the coarsest voxelized level's centre (float precision far away).
    glm::dvec3 anchor(0.0);
    for (int i = n - 1; i >= 0; --i)
        if (volume.getLevel(i).voxelized) {
            anchor = volume.getLevel(i).centre;
            break;
        }
    std::vector<LevelDesc> levels(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        const auto& level = volume.getLevel(i);
        if (!level.voxelized || level.combined.size() != levelVoxels * kConeCount)
            continue;
        const VoxelRegion& r = level.region;
        levels[std::size_t(i)].origin = glm::vec4(glm::vec3(r.origin - anchor), float(r.voxelSize));
        levels[std::size_t(i)].centre = glm::vec4(glm::vec3(level.centre - anchor),
                                                  float((0.5 * r.resolution - 1.0) * r.voxelSize));
        const std::uint64_t stamp = std::max(level.voxelStamp, level.lightStamp);
        if (mUploadedStamps[std::size_t(i)] != stamp) {
            mCombined.upload(level.combined.data(), levelBytes, levelBytes * std::size_t(i));
            mUploadedStamps[std::size_t(i)] = stamp;
            mLastUploadBytes += levelBytes;
        }
    }
    if (!mLevels.isValid() || mLevels.getSize() < levels.size() * sizeof(LevelDesc))
        mLevels = makeBuffer(context, levels.size() * sizeof(LevelDesc), "cascades.levels");
    mLevels.uploadSpan<LevelDesc>(levels);

    const int w = gbuffer.width, h = gbuffer.height;
    const std::size_t pixels = std::size_t(w) * std::size_t(h);
    if (mPixels != pixels) {
        mPositions = makeBuffer(context, pixels * sizeof(glm::vec4), "cascades.positions");
        mNormals = makeBuffer(context, pixels * sizeof(glm::vec4), "cascades.normals");
        mOutput = makeBuffer(context, pixels * kConeCount * sizeof(glm::vec4), "cascades.cones");
        mPixels = pixels;
    }
    std::vector<glm::vec4> positions(pixels), normals(pixels);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
            const glm::dvec3 p(gbuffer.position.at(x, y));
            const bool surface = gbuffer.hasSurface(x, y) && std::isfinite(p.x + p.y + p.z);
            positions[i] = glm::vec4(glm::vec3(surface ? p - anchor : glm::dvec3(0.0)),
                                     surface ? 1.0f : 0.0f);
            normals[i] = glm::vec4(gbuffer.normal.at(x, y), 0.0f);
        }
    mPositions.uploadSpan<glm::vec4>(positions);
    mNormals.uploadSpan<glm::vec4>(normals);
    mLastUploadBytes += 2 * pixels * sizeof(glm::vec4);

    GatherConstants constants;
    constants.size = {w, h, n, R};
    constants.march = {float(settings.voxelSize), float(volume.getCones().tanHalfAngle),
                       float(settings.startOffset), float(settings.stepScale)};
    constants.flags = {0, 1024, 0, 0};
    const gpu::RunResult result = context.run([&](gpu::CommandList& cmd) {
        cmd.dispatch(mPipeline,
                     {gpu::Binding::storageBuffer(0, mLevels), gpu::Binding::storageBuffer(1, mCombined),
                      gpu::Binding::storageBuffer(2, mPositions), gpu::Binding::storageBuffer(3, mNormals),
                      gpu::Binding::storageBuffer(4, mOutput), gpu::Binding::storageBuffer(5, mCones)},
                     gpu::PushConstants(constants),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(w), 8),
                                     gpu::computeGroupCount(std::uint64_t(h), 8), 1},
                     kDispatchLabel);
    });
    mLastGpuMs = result.sumGpuMs(kDispatchLabel);
    const std::vector<glm::vec4> e = mOutput.downloadVector<glm::vec4>(pixels * kConeCount);
    out.resize(pixels * kConeCount);
    for (std::size_t i = 0; i < out.size(); ++i)
        out[i] = glm::vec3(e[i]);
}

} // namespace rtlab::voxelgi
