#include "families/voxel_gi/cone_combine_gpu.h"

#include "core/error.h"
#include "families/voxel_gi/cone_tracing.h"
#include "families/voxel_gi/voxel_gi.h"
#include "gpu/format.h"
#include "gpu/shader_compiler.h"

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

namespace rtlab::voxelgi {

struct CombineConstants {
    glm::ivec4 size{0};  // full width, height; low width, height
    // factor, capsules, visibility given, 1 = the capsules at the traced pixels
    glm::ivec4 flags{0};
    glm::vec4 angle{0.0f};
    glm::vec4 anchor{0.0f};
};
static_assert(sizeof(CombineConstants) == 64, "must match cone_combine.comp");

namespace {

constexpr std::uint32_t kBindings = 9;

CombineConstants makeConstants(int w, int h, glm::ivec2 low, int factor, int capsules, bool visibility,
                               double coneHalfAngle, const glm::dvec3& anchor)
{
    CombineConstants c;
    c.size = {w, h, low.x, low.y};
    c.flags = {factor, capsules, visibility ? 1 : 0, 0};
    c.angle = {float(coneHalfAngle), float(std::cos(coneHalfAngle)), float(std::sin(coneHalfAngle)),
               float(2.0 * std::pow(std::sin(0.5 * coneHalfAngle), 2))};
    c.anchor = glm::vec4(glm::vec3(anchor), 0.0f);
    return c;
}

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

void ConeCombineGpu::prepare(gpu::Context& context, bool resident)
{
    if (mContext != &context || !mPipeline.isValid()) {
        *this = ConeCombineGpu();
        mContext = &context;
    }
    if (mPipeline.isValid() && (!resident || mResidentPipeline.isValid()))
        return;
    // The directions as GLSL constants, to 9 significant digits (float round trip).
    std::string constants;
    for (const glm::dvec3& d : scene::getConeDirections()) {
        char text[96];
        std::snprintf(text, sizeof(text), "%svec3(%.9g, %.9g, %.9g)", constants.empty() ? "" : ", ",
                      float(d.x), float(d.y), float(d.z));
        constants += text;
    }
    if (!mPipeline.isValid()) {
        gpu::ComputePipelineDesc desc;
        desc.name = kDispatchLabel;
        desc.spirv = gpu::ShaderCompiler()
                         .compileFile(getShaderDir() / "cone_combine.comp", {{"CONE_DIRECTIONS", constants}})
                         .spirv;
        for (std::uint32_t b = 0; b < kBindings; ++b)
            desc.bindings.push_back({b, gpu::BindingType::StorageBuffer});
        desc.pushConstantSize = sizeof(CombineConstants);
        mPipeline = context.createPipeline(desc);
    }
    if (resident && !mResidentPipeline.isValid()) {
        gpu::ComputePipelineDesc desc;
        desc.name = kDispatchLabel;
        desc.spirv = gpu::ShaderCompiler()
                         .compileFile(getShaderDir() / "cone_combine.comp",
                                      {{"CONE_DIRECTIONS", constants}, {"GBUFFER_IMAGES", "1"}})
                         .spirv;
        desc.bindings = {{0, gpu::BindingType::StorageBuffer}, {1, gpu::BindingType::StorageBuffer},
                         {2, gpu::BindingType::StorageImage},  {3, gpu::BindingType::StorageImage},
                         {7, gpu::BindingType::StorageBuffer}, {8, gpu::BindingType::StorageImage},
                         {9, gpu::BindingType::StorageImage},  {10, gpu::BindingType::StorageImage},
                         {11, gpu::BindingType::StorageImage}, {12, gpu::BindingType::StorageImage}};
        desc.pushConstantSize = sizeof(CombineConstants);
        mResidentPipeline = context.createPipeline(desc);
        // Bound where the frame gives no visibilities (the shader does not read it then).
        mNoVisibility = context.createImage({gpu::ImageDimension::Image2D, gpu::Format::RGBA32Float, 1, 1, 1,
                                             gpu::ImageUsage::StorageAndSampled,
                                             "voxel_gi.combine.no_visibility"});
    }
}

int ConeCombineGpu::uploadCapsules(const std::vector<scene::PosedCapsule>* in, const glm::dvec3& anchor)
{
    // Relative to the anchor (the camera), with what combineCones computes per capsule.
    std::vector<glm::vec4> capsules;
    if (in != nullptr)
        for (const scene::PosedCapsule& c : *in) {
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
    const std::size_t bytes = capsules.size() * sizeof(glm::vec4);
    reserve(mCapsules, bytes, "voxel_gi.combine.capsules");
    if (bytes > 0)
        mCapsules.upload(capsules.data(), bytes);
    mLastUploadBytes += bytes;
    return int(capsules.size() / 4);
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
    const glm::dvec3 anchor(full.camera.position);
    const int capsuleCount = uploadCapsules(in.capsules, anchor);
    reserve(mOutput, pixels * sizeof(glm::vec4), "voxel_gi.combine.irradiance");

    const CombineConstants constants =
        makeConstants(w, h, {reduced.gbuffer.width, reduced.gbuffer.height}, reduced.factor, capsuleCount,
                      useVisibility, in.coneHalfAngle, anchor);
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
    runCombine(context, mPipeline, bindings, constants, in.capsuleResolution);
    const std::vector<glm::vec4> e = mOutput.downloadVector<glm::vec4>(pixels);
    for (std::size_t i = 0; i < pixels; ++i)
        out.pixels[i] = glm::vec3(e[i]);
    return out;
}

ConeCombineGpu::Recorder ConeCombineGpu::makeRecorder(const gpu::ComputePipeline& pipeline,
                                                      const std::vector<gpu::Binding>& bindings,
                                                      const CombineConstants& given,
                                                      CapsuleResolution capsuleResolution)
{
    // The capsules at the traced pixels: a first dispatch over the reduced pixels multiplies the
    // cone radiances in place, then the combine runs without capsules.
    CombineConstants constants = given;
    const bool traced = capsuleResolution == CapsuleResolution::Traced && constants.flags.y > 0;
    CombineConstants tracedConstants = constants;
    tracedConstants.flags.w = 1;
    if (traced)
        constants.flags.y = 0;
    const int w = constants.size.x, h = constants.size.y, lw = constants.size.z, lh = constants.size.w;
    return [&pipeline, bindings, constants, tracedConstants, traced, w, h, lw, lh](gpu::CommandList& cmd) {
        if (traced)
            cmd.dispatch(pipeline, bindings, gpu::PushConstants(tracedConstants),
                         gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(lw), 8),
                                         gpu::computeGroupCount(std::uint64_t(lh), 8), 1},
                         kDispatchLabel);
        cmd.dispatch(pipeline, bindings, gpu::PushConstants(constants),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(w), 8),
                                     gpu::computeGroupCount(std::uint64_t(h), 8), 1},
                     kDispatchLabel);
    };
}

void ConeCombineGpu::runCombine(gpu::Context& context, const gpu::ComputePipeline& pipeline,
                                const std::vector<gpu::Binding>& bindings, const CombineConstants& given,
                                CapsuleResolution capsuleResolution)
{
    const Recorder record = makeRecorder(pipeline, bindings, given, capsuleResolution);
    mLastGpuMs = context.run(record).sumGpuMs(kDispatchLabel);
}

const gpu::Image& ConeCombineGpu::combineResident(gpu::Context& context, const PixelConeDispatch& dispatch,
                                                  int factor, const ResidentCombineInputs& in,
                                                  const gpu::Buffer* cones)
{
    const Recorder record = prepareResident(context, dispatch, factor, in, cones);
    mLastGpuMs = context.run(record).sumGpuMs(kDispatchLabel);
    return mOutputImage;
}

ConeCombineGpu::Recorder ConeCombineGpu::prepareResident(gpu::Context& context, const PixelConeDispatch& dispatch,
                                                         int factor, const ResidentCombineInputs& in,
                                                         const gpu::Buffer* cones)
{
    if (in.gbuffer == nullptr || in.gbuffer->positionDepth == nullptr || in.gbuffer->normal == nullptr)
        throw Error("cone combine: the resident combine needs the G-buffer's GPU images");
    const plugin::VoxelGiGpuGBuffer& g = *in.gbuffer;
    const int w = g.width, h = g.height;
    const glm::ivec2 low = dispatch.getPixelsSize();
    if (low != glm::ivec2((w + factor - 1) / factor, (h + factor - 1) / factor))
        throw Error("cone combine: the cones were traced over " + std::to_string(low.x) + "x" +
                    std::to_string(low.y) + " pixels, not a " + std::to_string(w) + "x" +
                    std::to_string(h) + " G-buffer reduced by " + std::to_string(factor));
    const bool useVisibility = in.visibility[0] != nullptr;
    for (const gpu::Image* image : in.visibility) {
        if (useVisibility != (image != nullptr))
            throw Error("cone combine: give all four visibility images or none");
        if (image != nullptr &&
            (int(image->getDesc().width) != w || int(image->getDesc().height) != h ||
             image->getDesc().format != gpu::Format::RGBA32Float))
            throw Error("cone combine: the visibility image '" + image->getDesc().name + "' is " +
                        std::to_string(image->getDesc().width) + "x" + std::to_string(image->getDesc().height) +
                        " " + std::string(gpu::getFormatName(image->getDesc().format)) +
                        ", expected RGBA32Float " + std::to_string(w) + "x" + std::to_string(h));
    }
    prepare(context, true);
    mLastUploadBytes = 0;
    if (!mOutputImage.isValid() || int(mOutputImage.getDesc().width) != w ||
        int(mOutputImage.getDesc().height) != h)
        mOutputImage = context.createImage({gpu::ImageDimension::Image2D, gpu::Format::RGBA32Float,
                                            std::uint32_t(std::max(w, 1)), std::uint32_t(std::max(h, 1)), 1,
                                            gpu::ImageUsage::StorageAndSampled, "voxel_gi.irradiance"});
    const glm::dvec3 anchor(g.cameraPosition);
    const int capsuleCount = uploadCapsules(in.capsules, anchor);
    const CombineConstants constants =
        makeConstants(w, h, low, factor, capsuleCount, useVisibility, in.coneHalfAngle, anchor);
    const auto vis = [&](std::size_t k) -> const gpu::Image& {
        return useVisibility ? *in.visibility[k] : mNoVisibility;
    };
    const std::vector<gpu::Binding> bindings = {
        gpu::Binding::storageBuffer(0, cones != nullptr ? *cones : dispatch.getOutput()),
        gpu::Binding::storageBuffer(1, dispatch.getRepresentative()),
        gpu::Binding::storageImage(2, *g.positionDepth),
        gpu::Binding::storageImage(3, *g.normal),
        gpu::Binding::storageBuffer(7, mCapsules),
        gpu::Binding::storageImage(8, mOutputImage),
        gpu::Binding::storageImage(9, vis(0)),
        gpu::Binding::storageImage(10, vis(1)),
        gpu::Binding::storageImage(11, vis(2)),
        gpu::Binding::storageImage(12, vis(3))};
    return makeRecorder(mResidentPipeline, bindings, constants, in.capsuleResolution);
}

Image<glm::vec3> ConeCombineGpu::readBackResident() const
{
    if (!mOutputImage.isValid())
        throw Error("cone combine: no resident combine has run to read back");
    const int w = int(mOutputImage.getDesc().width), h = int(mOutputImage.getDesc().height);
    const std::vector<glm::vec4> e = mOutputImage.downloadVector<glm::vec4>();
    Image<glm::vec3> out(w, h, glm::vec3(0.0f));
    for (std::size_t i = 0; i < out.pixels.size() && i < e.size(); ++i)
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

const gpu::Image& gatherConesResident(
    gpu::Context& context, ConeCombineGpu& combiner, const plugin::VoxelGiGpuGBuffer& gbuffer, int traceStep,
    double coneHalfAngle, const std::array<const gpu::Image*, 4>& visibility,
    const std::vector<scene::PosedCapsule>* capsules,
    const std::function<const PixelConeDispatch&(const PixelSource&)>& traceCones, double* combineMs,
    CapsuleResolution capsuleResolution, ConeCombineGpu* skyCombiner)
{
    PixelSource source;
    source.gpu = &gbuffer;
    source.factor = traceStep;
    source.deferSubmission = true; // recorded with the combine below: one submission
    const PixelConeDispatch& dispatch = traceCones(source);
    const auto tracedAt = std::chrono::steady_clock::now();
    ResidentCombineInputs in;
    in.gbuffer = &gbuffer;
    in.visibility = visibility;
    in.capsules = capsules;
    in.coneHalfAngle = coneHalfAngle;
    in.capsuleResolution = capsuleResolution;
    // The reduction and the cones (as the technique recorded them), the light's combine and the
    // sky's in one submission.
    const ConeCombineGpu::Recorder light = combiner.prepareResident(context, dispatch, traceStep, in);
    ConeCombineGpu::Recorder sky;
    if (skyCombiner != nullptr)
        sky = skyCombiner->prepareResident(context, dispatch, traceStep, in, &dispatch.getSkyOutput());
    const gpu::RunResult result = context.run([&](gpu::CommandList& cmd) {
        if (dispatch.getRecorded())
            dispatch.getRecorded()(cmd);
        light(cmd);
        if (sky)
            sky(cmd);
    });
    if (dispatch.getRecorded())
        dispatch.setDeferredGpuMs(result.sumGpuMs(dispatch.getLabel()));
    combiner.setLastGpuMs(result.sumGpuMs(ConeCombineGpu::kDispatchLabel));
    const gpu::Image& out = *combiner.getResidentOutput();
    if (combineMs != nullptr)
        *combineMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tracedAt).count();
    return out;
}

} // namespace rtlab::voxelgi
