#include "families/voxel_gi/cone_combine_gpu.h"

#include "core/error.h"
#include "families/voxel_gi/cone_tracing.h"
#include "gpu/shader_compiler.h"

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

namespace rtlab::voxelgi {

namespace {

struct CombineConstants {
    glm::ivec4 size{0};  // full width, height; low width, height
    // factor, capsules, visibility given, 1 = the capsules at the traced pixels
    glm::ivec4 flags{0};
    glm::vec4 angle{0.0f};
    glm::vec4 anchor{0.0f};
};
static_assert(sizeof(CombineConstants) == 64, "must match cone_combine.comp");

constexpr std::uint32_t kBindings = 9;

} // namespace

std::filesystem::path ConeCombineGpu::getShaderDir()
{
    return gpu::findShaderDir("framework/families/voxel_gi/shaders",
                              std::filesystem::path(RTLAB_VOXEL_GI_SHADER_DIR));
}

gpu::Buffer& ConeCombineGpu::reserve(gpu::Buffer& buffer, std::size_t bytes, const char* name)
{
    bytes = std::max<std::size_t>(bytes, 16);
    if (!buffer.isValid() || buffer.getSize() < bytes)
        buffer = mContext->createBuffer({.size = bytes, .name = name, .hostVisible = true});
    return buffer;
}

void ConeCombineGpu::prepare(gpu::Context& context)
{
    if (mContext == &context && mPipeline.isValid())
        return;
    *this = ConeCombineGpu();
    mContext = &context;
    gpu::ComputePipelineDesc desc;
    desc.name = kDispatchLabel;
    // The directions as GLSL constants, to 9 significant digits (float round trip).
    std::string constants;
    for (const glm::dvec3& d : scene::getConeDirections()) {
        char text[96];
        std::snprintf(text, sizeof(text), "%svec3(%.9g, %.9g, %.9g)", constants.empty() ? "" : ", ",
                      float(d.x), float(d.y), float(d.z));
        constants += text;
    }
    desc.spirv =
        gpu::ShaderCompiler()
            .compileFile(getShaderDir() / "cone_combine.comp", {{"CONE_DIRECTIONS", constants}})
            .spirv;
    for (std::uint32_t b = 0; b < kBindings; ++b)
        desc.bindings.push_back({b, gpu::BindingType::StorageBuffer});
    desc.pushConstantSize = sizeof(CombineConstants);
    mPipeline = context.createPipeline(desc);
}

Image<glm::vec3> ConeCombineGpu::combine(gpu::Context& context, const ConeCombineInputs& in)
{
    if (in.coneRadiance == nullptr)
        throw Error("cone combine: no cone radiances given");
    return combine(context, uploadCones(context, *in.coneRadiance), in);
}

const gpu::Buffer& ConeCombineGpu::uploadCones(gpu::Context& context,
                                               const std::vector<glm::vec3>& coneRadiance)
{
    prepare(context);
    std::vector<glm::vec4> cones(coneRadiance.size());
    for (std::size_t i = 0; i < cones.size(); ++i)
        cones[i] = glm::vec4(coneRadiance[i], 0.0f);
    reserve(mUploadedCones, cones.size() * sizeof(glm::vec4), "voxel_gi.combine.cone_radiance");
    if (!cones.empty())
        mUploadedCones.uploadSpan<glm::vec4>(cones);
    return mUploadedCones;
}

Image<glm::vec3> ConeCombineGpu::combine(gpu::Context& context, const gpu::Buffer& coneRadiance,
                                         const ConeCombineInputs& in)
{
    const scene::GBuffer& full = *in.full;
    const ReducedGBuffer& reduced = *in.reduced;
    const int w = full.width, h = full.height;
    const std::size_t pixels = std::size_t(w) * std::size_t(h);
    const std::size_t lowPixels =
        std::size_t(reduced.gbuffer.width) * std::size_t(reduced.gbuffer.height);
    if (coneRadiance.getSize() < lowPixels * kConeCount * sizeof(glm::vec4))
        throw Error("cone combine: a cone buffer of " + std::to_string(coneRadiance.getSize()) +
                    " bytes for " + std::to_string(lowPixels) + " pixels x 16 cones");
    if (full.position.pixels.size() != pixels || full.normal.pixels.size() != pixels ||
        full.depth.pixels.size() != pixels || full.materialId.pixels.size() != pixels)
        throw Error("cone combine: the G-buffer's images are not " + std::to_string(w) + "x" +
                    std::to_string(h));
    prepare(context);
    mLastUploadBytes = 0;
    const auto upload = [&](gpu::Buffer& buffer, const void* data, std::size_t bytes,
                            const char* name) {
        reserve(buffer, bytes, name);
        if (bytes > 0)
            buffer.upload(data, bytes);
        mLastUploadBytes += bytes;
    };
    // The G-buffer's images as they are (no packing pass over the pixels).
    upload(mRepresentative, reduced.representative.data(),
           reduced.representative.size() * sizeof(int), "voxel_gi.combine.representative");
    upload(mPositions, full.position.pixels.data(), pixels * sizeof(glm::vec3),
           "voxel_gi.combine.positions");
    upload(mNormals, full.normal.pixels.data(), pixels * sizeof(glm::vec3),
           "voxel_gi.combine.normals");
    upload(mDepths, full.depth.pixels.data(), pixels * sizeof(float), "voxel_gi.combine.depths");
    upload(mMaterials, full.materialId.pixels.data(), pixels * sizeof(std::uint32_t),
           "voxel_gi.combine.materials");
    // The 16 visibility images one after the other ([cone][pixel]).
    const bool useVisibility =
        in.visibility != nullptr && in.visibility->size() == std::size_t(kConeCount);
    reserve(mVisibility, useVisibility ? pixels * kConeCount * sizeof(float) : 16,
            "voxel_gi.combine.visibility");
    if (useVisibility)
        for (int k = 0; k < kConeCount; ++k) {
            const Image<float>& image = (*in.visibility)[std::size_t(k)];
            if (image.pixels.size() != pixels)
                throw Error("cone combine: visibility image " + std::to_string(k) + " is " +
                            std::to_string(image.width) + "x" + std::to_string(image.height) +
                            ", not " + std::to_string(w) + "x" + std::to_string(h));
            mVisibility.upload(image.pixels.data(), pixels * sizeof(float),
                               std::size_t(k) * pixels * sizeof(float));
            mLastUploadBytes += pixels * sizeof(float);
        }
    // Capsules relative to the anchor (the camera), with what combineCones computes per capsule.
    const glm::dvec3 anchor(full.camera.position);
    std::vector<glm::vec4> capsules;
    if (in.capsules != nullptr)
        for (const scene::PosedCapsule& c : *in.capsules) {
            const glm::dvec3 a = glm::dvec3(c.capsule.a) - anchor,
                             u = glm::dvec3(c.capsule.b) - glm::dvec3(c.capsule.a);
            const double uu = glm::dot(u, u), r = double(c.capsule.radius);
            const double half = 0.5 * std::sqrt(uu);
            capsules.emplace_back(glm::vec3(a), float(r));
            capsules.emplace_back(glm::vec3(u), float(uu > 0.0 ? 1.0 / uu : 0.0));
            capsules.emplace_back(glm::vec3(a + 0.5 * u), float(half + r));
            capsules.emplace_back(float((40.0 * r) * (40.0 * r)),
                                  float((half + 40.0 * r) * (half + 40.0 * r)), 0.0f, 0.0f);
        }
    upload(mCapsules, capsules.data(), capsules.size() * sizeof(glm::vec4),
           "voxel_gi.combine.capsules");
    reserve(mOutput, pixels * sizeof(glm::vec4), "voxel_gi.combine.irradiance");

    CombineConstants constants;
    constants.size = {w, h, reduced.gbuffer.width, reduced.gbuffer.height};
    constants.flags = {reduced.factor, int(capsules.size() / 4), useVisibility ? 1 : 0, 0};
    constants.angle = {float(in.coneHalfAngle), float(std::cos(in.coneHalfAngle)),
                       float(std::sin(in.coneHalfAngle)),
                       float(2.0 * std::pow(std::sin(0.5 * in.coneHalfAngle), 2))};
    constants.anchor = glm::vec4(glm::vec3(anchor), 0.0f);
    const std::vector<gpu::Binding> bindings = {gpu::Binding::storageBuffer(0, coneRadiance),
                                                gpu::Binding::storageBuffer(1, mRepresentative),
                                                gpu::Binding::storageBuffer(2, mPositions),
                                                gpu::Binding::storageBuffer(3, mNormals),
                                                gpu::Binding::storageBuffer(4, mDepths),
                                                gpu::Binding::storageBuffer(5, mMaterials),
                                                gpu::Binding::storageBuffer(6, mVisibility),
                                                gpu::Binding::storageBuffer(7, mCapsules),
                                                gpu::Binding::storageBuffer(8, mOutput)};
    Image<glm::vec3> out(w, h, glm::vec3(0.0f));
    if (pixels == 0)
        return out;
    // The capsules at the traced pixels: a first dispatch over the reduced pixels multiplies the
    // cone radiances in place, then the combine runs without capsules.
    const bool traced = in.capsuleResolution == CapsuleResolution::Traced && !capsules.empty();
    CombineConstants tracedConstants = constants;
    tracedConstants.flags.w = 1;
    if (traced)
        constants.flags.y = 0;
    const gpu::RunResult result = context.run([&](gpu::CommandList& cmd) {
        if (traced)
            cmd.dispatch(mPipeline, bindings, gpu::PushConstants(tracedConstants),
                         gpu::GroupCount{
                             gpu::computeGroupCount(std::uint64_t(reduced.gbuffer.width), 8),
                             gpu::computeGroupCount(std::uint64_t(reduced.gbuffer.height), 8), 1},
                         kDispatchLabel);
        cmd.dispatch(mPipeline, bindings, gpu::PushConstants(constants),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(w), 8),
                                     gpu::computeGroupCount(std::uint64_t(h), 8), 1},
                     kDispatchLabel);
    });
    mLastGpuMs = result.sumGpuMs(kDispatchLabel);
    const std::vector<glm::vec4> e = mOutput.downloadVector<glm::vec4>(pixels);
    for (std::size_t i = 0; i < pixels; ++i)
        out.pixels[i] = glm::vec3(e[i]);
    return out;
}

bool shouldCombineOnGpu(const gpu::Context* context, bool gatheredOnGpu, std::string_view setting)
{
    if (context == nullptr || setting == "cpu")
        return false;
    if (setting == "vulkan")
        return true;
    return gatheredOnGpu && !context->getDeviceInfo().isCpu;
}

bool shouldGatherOnGpu(const gpu::Context* context, std::string_view setting)
{
    if (context == nullptr || setting == "cpu")
        return false;
    return setting == "vulkan" || !context->getDeviceInfo().isCpu;
}

void appendGatherCounters(std::vector<std::pair<std::string, double>>& counters, bool gatheredOnGpu,
                          std::optional<double> gatherGpuMs, std::size_t gatherUploadBytes,
                          double combineMs, bool combinedOnGpu, const ConeCombineGpu& combiner)
{
    const double none = std::nan("");
    counters.emplace_back("gather_on_gpu", gatheredOnGpu ? 1.0 : 0.0);
    counters.emplace_back("gather_gpu_ms", gatheredOnGpu && gatherGpuMs ? *gatherGpuMs : none);
    counters.emplace_back("gather_upload_bytes", gatheredOnGpu ? double(gatherUploadBytes) : 0.0);
    counters.emplace_back("combine_ms", combineMs);
    counters.emplace_back("combine_on_gpu", combinedOnGpu ? 1.0 : 0.0);
    counters.emplace_back("combine_gpu_ms", combinedOnGpu && combiner.getLastGpuMs()
                                                ? *combiner.getLastGpuMs()
                                                : none);
    counters.emplace_back("combine_upload_bytes",
                          combinedOnGpu ? double(combiner.getLastUploadBytes()) : 0.0);
}

Image<glm::vec3>
gatherConesReducedOnGpu(gpu::Context& context, ConeCombineGpu& combiner, const scene::GBuffer& full,
                        int traceStep, double coneHalfAngle,
                        const std::vector<Image<float>>* visibility,
                        const std::vector<scene::PosedCapsule>* capsules,
                        const std::function<const gpu::Buffer&(const scene::GBuffer&)>& traceCones,
                        double* combineMs, CapsuleResolution capsuleResolution)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const ReducedGBuffer reduced = reduceGBuffer(full, traceStep);
    const auto reducedAt = Clock::now();
    const gpu::Buffer& cones = traceCones(reduced.gbuffer);
    const auto tracedAt = Clock::now();
    ConeCombineInputs in;
    in.reduced = &reduced;
    in.full = &full;
    in.visibility = visibility;
    in.capsules = capsules;
    in.coneHalfAngle = coneHalfAngle;
    in.capsuleResolution = capsuleResolution;
    Image<glm::vec3> irradiance = combiner.combine(context, cones, in);
    if (combineMs != nullptr)
        *combineMs = std::chrono::duration<double, std::milli>((reducedAt - start) +
                                                               (Clock::now() - tracedAt))
                         .count();
    return irradiance;
}

} // namespace rtlab::voxelgi
