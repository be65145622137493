#include "cascade_inject_gpu.h"

#include "cascade_gather_gpu.h"

#include "core/error.h"
#include "gpu/shader_compiler.h"

#include <glm/vec4.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace rtlab::voxelgi {

namespace {

struct InjectConstants {
    glm::ivec4 size{0};  // surface voxels, levels, resolution, point lights
    glm::vec4 march{0};  // level-0 voxel size, tan(half-angle), start offset (voxels), step scale
    glm::vec4 inject{0}; // voxel size of the lit level, shadow-cone tan, max opacity, 1 = sky
    glm::ivec4 flags{0}; // x: max steps
};
static_assert(sizeof(InjectConstants) == 64, "must match cascade_inject.comp");

constexpr int kFieldsPerFace = 3; // (emission, occupancy), direct, first bounce

} // namespace

gpu::Buffer& CascadeInjectGpu::reserve(gpu::Buffer& buffer, std::size_t bytes, const char* name,
                                       bool hostVisible)
{
    bytes = std::max<std::size_t>(bytes, 16);
    if (!buffer.isValid() || buffer.getSize() < bytes)
        buffer = mContext->createBuffer({.size = bytes, .name = name, .hostVisible = hostVisible});
    return buffer;
}

void CascadeInjectGpu::gatherIrradiance(gpu::Context& context, const CascadeVolume& volume, int li,
                                        const InjectionLights& lights, std::vector<FaceIrradiance>& out)
{
    const auto start = std::chrono::steady_clock::now();
    struct AddCallTime {
        Counters& counters;
        std::chrono::steady_clock::time_point start;
        ~AddCallTime()
        {
            counters.callMs +=
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        }
    } addCallTime{mCounters, start};
    if (mContext != &context || !mPipeline.isValid()) {
        *this = CascadeInjectGpu();
        mContext = &context;
        gpu::ComputePipelineDesc desc;
        desc.name = kDispatchLabel;
        desc.spirv = gpu::ShaderCompiler().compileFile(CascadeGatherGpu::getShaderDir() / "cascade_inject.comp").spirv;
        for (std::uint32_t b = 0; b < 7; ++b)
            desc.bindings.push_back({b, gpu::BindingType::StorageBuffer});
        desc.pushConstantSize = sizeof(InjectConstants);
        mPipeline = context.createPipeline(desc);
        std::vector<glm::vec4> directions(kConeCount);
        for (int k = 0; k < kConeCount; ++k)
            directions[std::size_t(k)] = glm::vec4(glm::vec3(volume.getCones().directions[std::size_t(k)]), 0.0f);
        reserve(mCones, directions.size() * sizeof(glm::vec4), "cascades.inject.cones").uploadSpan<glm::vec4>(directions);
    }
    // Nothing to light (a level whose region holds no surface, e.g. the finest level around a
    // camera in the air): no light buffers go up and nothing is dispatched.
    if (volume.getLevel(li).grid.surfaceVoxels.empty()) {
        out.clear();
        return;
    }
    const CascadeSettings& settings = volume.getSettings();
    const int n = volume.getLevelCount();
    const int R = settings.resolution;
    const std::size_t levelFaces = std::size_t(R) * std::size_t(R) * std::size_t(R) * kFaceCount;
    const std::size_t levelBytes = levelFaces * kFieldsPerFace * sizeof(glm::vec4);
    if (mFieldLevelFaces != levelFaces || mUploadedRevision.size() != std::size_t(n)) {
        mFields = mContext->createBuffer({levelBytes * std::size_t(n), "cascades.inject.fields"});
        mFieldLevelFaces = levelFaces;
        mUploadedRevision.assign(std::size_t(n), 0);
    }
    const glm::dvec3 anchor = getGpuAnchor(volume);
    const std::vector<GpuCascadeLevel> levels = describeGpuLevels(volume, anchor, false);
    reserve(mLevels, levels.size() * sizeof(GpuCascadeLevel), "cascades.inject.levels", true)
        .uploadSpan<GpuCascadeLevel>(levels);
    // The light buffers of the levels that changed since they went up.
    std::vector<glm::vec4> packed;
    for (int i = 0; i < n; ++i) {
        const auto& level = volume.getLevel(i);
        if (!level.voxelized || mUploadedRevision[std::size_t(i)] == level.lightRevision)
            continue;
        packed.resize(levelFaces * kFieldsPerFace);
        tbb::parallel_for(std::size_t(0), levelFaces, [&](std::size_t f) {
            packed[f * 3 + 0] = glm::vec4(level.light[kEmission][f], level.alpha[f]);
            packed[f * 3 + 1] = glm::vec4(level.light[kDirect][f], 0.0f);
            packed[f * 3 + 2] = glm::vec4(level.light[kBounce1][f], 0.0f);
        });
        mFields.upload(packed.data(), levelBytes, levelBytes * std::size_t(i));
        mUploadedRevision[std::size_t(i)] = level.lightRevision;
        mCounters.uploadBytes += levelBytes;
    }
    // The surface voxels to light, the sky and the point lights.
    const auto& level = volume.getLevel(li);
    const auto& surface = level.grid.surfaceVoxels;
    out.assign(surface.size(), FaceIrradiance{});
    std::vector<glm::vec4> voxels(surface.size() * 2);
    for (std::size_t s = 0; s < surface.size(); ++s) {
        const std::uint32_t v = surface[s];
        const int x = int(v % std::uint32_t(R)), y = int((v / std::uint32_t(R)) % std::uint32_t(R)),
                  z = int(v / (std::uint32_t(R) * std::uint32_t(R)));
        voxels[2 * s] = glm::vec4(glm::vec3(level.region.getVoxelCentre(x, y, z) - anchor), 0.0f);
        voxels[2 * s + 1] = glm::vec4(level.grid.normal[v], 0.0f);
    }
    reserve(mVoxels, voxels.size() * sizeof(glm::vec4), "cascades.inject.voxels", true)
        .uploadSpan<glm::vec4>(voxels);
    std::vector<glm::vec4> sky(kConeCount, glm::vec4(0.0f));
    for (int k = 0; k < kConeCount; ++k)
        sky[std::size_t(k)] = glm::vec4(lights.skyPerCone[std::size_t(k)], 0.0f);
    reserve(mSky, sky.size() * sizeof(glm::vec4), "cascades.inject.sky", true)
        .uploadSpan<glm::vec4>(sky);
    std::vector<glm::vec4> pointLights;
    if (lights.pointLights != nullptr)
        for (const scene::PointLight& l : *lights.pointLights) {
            pointLights.emplace_back(glm::vec3(glm::dvec3(l.position) - anchor), 0.0f);
            pointLights.emplace_back(l.intensity, 0.0f);
        }
    if (!pointLights.empty())
        reserve(mLights, pointLights.size() * sizeof(glm::vec4), "cascades.inject.lights", true)
            .uploadSpan<glm::vec4>(pointLights);
    else
        reserve(mLights, 16, "cascades.inject.lights", true);
    const std::size_t outCount = surface.size() * 3 * kFaceCount;
    // The per-call inputs above and this output cross the bus once: host-visible; the light
    // fields, read by every cone step, stay in device memory.
    reserve(mOutput, outCount * sizeof(glm::vec4), "cascades.inject.irradiance", true);
    mCounters.uploadBytes += voxels.size() * sizeof(glm::vec4) + sky.size() * sizeof(glm::vec4) +
                             pointLights.size() * sizeof(glm::vec4);

    const InjectionSettings inject = volume.getInjectionSettings();
    InjectConstants constants;
    constants.size = {int(surface.size()), n, R, int(pointLights.size() / 2)};
    constants.march = {float(settings.voxelSize), float(volume.getCones().tanHalfAngle),
                       float(inject.startOffset), float(inject.march.stepScale)};
    constants.inject = {float(level.region.voxelSize), float(inject.pointLightTan),
                        float(inject.march.maxOpacity), lights.hasSky ? 1.0f : 0.0f};
    constants.flags = {inject.march.maxSteps, 0, 0, 0};
    const std::vector<gpu::Binding> bindings = {
        gpu::Binding::storageBuffer(0, mLevels), gpu::Binding::storageBuffer(1, mFields),
        gpu::Binding::storageBuffer(2, mVoxels), gpu::Binding::storageBuffer(3, mOutput),
        gpu::Binding::storageBuffer(4, mCones),  gpu::Binding::storageBuffer(5, mSky),
        gpu::Binding::storageBuffer(6, mLights)};
    const gpu::RunResult result = mContext->run([&](gpu::CommandList& cmd) {
        cmd.dispatch(mPipeline, bindings, gpu::PushConstants(constants),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(surface.size()), 64), 1, 1},
                     kDispatchLabel);
    });
    ++mCounters.dispatches;
    mCounters.submitMs += result.cpuSubmitMs;
    if (const auto ms = result.sumGpuMs(kDispatchLabel))
        mCounters.gpuMs += *ms;
    else
        mCounters.timed = false;
    const std::vector<glm::vec4> e = mOutput.downloadVector<glm::vec4>(outCount);
    for (std::size_t s = 0; s < surface.size(); ++s)
        for (int field = 0; field < 3; ++field)
            for (int face = 0; face < kFaceCount; ++face)
                out[s].e[std::size_t(kDirect + field)][std::size_t(face)] =
                    glm::vec3(e[(s * 3 + std::size_t(field)) * kFaceCount + std::size_t(face)]);
}

} // namespace rtlab::voxelgi
