#include "bentcone_ssdo_gpu.h"

#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "render/gbuffer_pass.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

namespace rtlab::bentcone_ssdo {

namespace {

//! Push constants; layout matches `Params` in shaders/bentcone_ssdo.comp.
struct PushData {
    float projScale[2];
    float projOffset[2];
    float size[2];
    float radius;
    float depthBias;
    float shWeight;
    std::int32_t sampleCount;
    std::int32_t coneMode;
    float padding;
    float coneCap[4];
};
static_assert(sizeof(PushData) == 64);

constexpr std::uint32_t kGroupSize = 8;
//! The frame buffer: rotations, cones, then the pattern (N) and the aperture table (N + 1).
constexpr int kFrameHeaderVec4 = kCellCount + kConeCount;

std::filesystem::path getShaderDir()
{
    return gpu::findShaderDir("techniques/occlusion/bentcone_ssdo/shaders",
                              std::filesystem::path(RTLAB_TECHNIQUE_DIR) / "shaders");
}

} // namespace

struct GpuPath::State {
    gpu::Context* context = nullptr;
    gpu::ComputePipeline pipeline;
    int width = 0;
    int height = 0;
    int sampleCount = 0;
    gpu::Buffer frameBuffer;
    gpu::Image depth;
    gpu::Image normal;
    gpu::Image bentAmbient;
    gpu::Image aperture;
    std::array<gpu::Image, 4> visibility;
    std::vector<float> normalTexels; //!< staging for the vec3 -> RGBA32F conversion
    bool computed = false;           //!< a compute() has filled the output images
};

GpuPath::GpuPath() = default;
GpuPath::~GpuPath() = default;
GpuPath::GpuPath(GpuPath&&) noexcept = default;
GpuPath& GpuPath::operator=(GpuPath&&) noexcept = default;

void GpuPath::compute(gpu::Context& context, const FrameSetup& frame,
                      const plugin::OcclusionInput& input, plugin::OcclusionOutput& out)
{
    if (!mState || mState->context != &context)
        mState = std::make_unique<State>();
    State& s = *mState;
    if (!s.pipeline.isValid()) {
        s.context = &context;
        gpu::ShaderCompilerOptions options;
        options.includeDirs.push_back(render::getRenderShaderDir());
        const gpu::ShaderCompiler compiler(options);
        gpu::ComputePipelineDesc desc;
        desc.name = "bentcone_ssdo.main";
        desc.spirv = compiler.compileFile(getShaderDir() / "bentcone_ssdo.comp").spirv;
        desc.bindings = {{0, gpu::BindingType::StorageImage},  {1, gpu::BindingType::StorageImage},
                         {2, gpu::BindingType::StorageBuffer}, {3, gpu::BindingType::StorageImage},
                         {4, gpu::BindingType::StorageImage},  {5, gpu::BindingType::StorageImage},
                         {6, gpu::BindingType::StorageImage},  {7, gpu::BindingType::StorageImage},
                         {8, gpu::BindingType::StorageImage}};
        desc.pushConstantSize = sizeof(PushData);
        s.pipeline = context.createPipeline(desc);
    }

    const int w = frame.width, h = frame.height;
    const int sampleCount = int(frame.pattern.size());
    if (w != s.width || h != s.height) {
        auto makeImage = [&](gpu::Format format, const char* name) {
            return context.createImage({gpu::ImageDimension::Image2D, format, std::uint32_t(w),
                                        std::uint32_t(h), 1, gpu::ImageUsage::Storage, name});
        };
        s.depth = makeImage(gpu::Format::R32Float, "bentcone_ssdo.depth");
        s.normal = makeImage(gpu::Format::RGBA32Float, "bentcone_ssdo.normal");
        s.bentAmbient = makeImage(gpu::Format::RGBA32Float, "bentcone_ssdo.bent_ambient");
        s.aperture = makeImage(gpu::Format::R32Float, "bentcone_ssdo.aperture");
        for (int i = 0; i < 4; ++i)
            s.visibility[std::size_t(i)] =
                makeImage(gpu::Format::RGBA32Float, "bentcone_ssdo.visibility");
        s.width = w;
        s.height = h;
    }
    if (sampleCount != s.sampleCount) {
        s.frameBuffer = context.createBuffer(
            {std::size_t(kFrameHeaderVec4 + 2 * sampleCount + 1) * sizeof(glm::vec4),
             "bentcone_ssdo.frame"});
        s.sampleCount = sampleCount;
    }

    // Frame constants: rotations, view-space cone directions, pattern.
    std::vector<glm::vec4> frameData;
    frameData.reserve(std::size_t(kFrameHeaderVec4 + 2 * sampleCount + 1));
    for (const glm::vec2& r : frame.rotations)
        frameData.emplace_back(r.x, r.y, 0.0f, 0.0f);
    for (const glm::vec3& d : frame.coneDirections)
        frameData.emplace_back(d, 0.0f);
    frameData.insert(frameData.end(), frame.pattern.begin(), frame.pattern.end());
    frameData.insert(frameData.end(), frame.apertureTable.begin(), frame.apertureTable.end());
    s.frameBuffer.upload(frameData.data(), frameData.size() * sizeof(glm::vec4));

    // The frame's G-buffer stays on the GPU when the input has it there: bind it, upload nothing.
    const bool onGpu = input.gpuLinearDepth != nullptr && input.gpuNormal != nullptr;
    if (!onGpu) {
        s.depth.upload(input.linearDepth->pixels.data(),
                       input.linearDepth->pixels.size() * sizeof(float));
        s.normalTexels.resize(std::size_t(w) * h * 4);
        for (std::size_t i = 0; i < input.normal->pixels.size(); ++i) {
            const glm::vec3& n = input.normal->pixels[i];
            s.normalTexels[i * 4 + 0] = n.x;
            s.normalTexels[i * 4 + 1] = n.y;
            s.normalTexels[i * 4 + 2] = n.z;
            s.normalTexels[i * 4 + 3] = 0.0f;
        }
        s.normal.upload(s.normalTexels.data(), s.normalTexels.size() * sizeof(float));
    }
    const gpu::Image& depthImage = onGpu ? *input.gpuLinearDepth : s.depth;
    const gpu::Image& normalImage = onGpu ? *input.gpuNormal : s.normal;

    const Cap coneCap = getDirectionCap();
    const PushData push{{frame.projection.scale.x, frame.projection.scale.y},
                        {frame.projection.offset.x, frame.projection.offset.y},
                        {float(w), float(h)},
                        frame.settings.radius,
                        frame.settings.depthBias,
                        float(std::numbers::pi / sampleCount),
                        sampleCount,
                        frame.settings.coneIntersection == ConeIntersection::Smoothstep ? 1 : 0,
                        0.0f,
                        {coneCap.angle, coneCap.cosine, coneCap.sine, coneCap.versine}};
    context.run([&](gpu::CommandList& cmd) {
        cmd.dispatch(s.pipeline,
                     {gpu::Binding::storageImage(0, depthImage),
                      gpu::Binding::storageImage(1, normalImage),
                      gpu::Binding::storageBuffer(2, s.frameBuffer),
                      gpu::Binding::storageImage(3, s.bentAmbient),
                      gpu::Binding::storageImage(4, s.aperture),
                      gpu::Binding::storageImage(5, s.visibility[0]),
                      gpu::Binding::storageImage(6, s.visibility[1]),
                      gpu::Binding::storageImage(7, s.visibility[2]),
                      gpu::Binding::storageImage(8, s.visibility[3])},
                     gpu::PushConstants(push),
                     gpu::GroupCount{gpu::computeGroupCount(std::uint64_t(w), kGroupSize),
                                     gpu::computeGroupCount(std::uint64_t(h), kGroupSize), 1},
                     "bentcone_ssdo.main");
    });

    out = plugin::OcclusionOutput();
    for (std::size_t g = 0; g < 4; ++g)
        out.gpu.coneVisibility[g] = &s.visibility[g];
    s.computed = true;
    if (input.readBack)
        readBack(out);
}

void GpuPath::readBack(plugin::OcclusionOutput& out) const
{
    if (!mState || !mState->computed)
        throw Error("bentcone_ssdo: nothing computed on the GPU to read back");
    const State& s = *mState;
    const int w = s.width, h = s.height;
    const std::vector<float> bentAmbient = s.bentAmbient.downloadVector<float>();
    const std::vector<float> aperture = s.aperture.downloadVector<float>();
    out.ambient = Image<float>(w, h);
    out.bentNormal = Image<glm::vec3>(w, h);
    out.coneAperture = Image<float>(w, h);
    out.coneVisibility.assign(std::size_t(kConeCount), Image<float>(w, h));
    const std::size_t pixelCount = std::size_t(w) * h;
    for (std::size_t i = 0; i < pixelCount; ++i) {
        out.bentNormal.pixels[i] =
            glm::vec3(bentAmbient[i * 4 + 0], bentAmbient[i * 4 + 1], bentAmbient[i * 4 + 2]);
        out.ambient.pixels[i] = bentAmbient[i * 4 + 3];
        out.coneAperture.pixels[i] = aperture[i];
    }
    for (int group = 0; group < 4; ++group) {
        const std::vector<float> texels = s.visibility[std::size_t(group)].downloadVector<float>();
        for (int c = 0; c < 4; ++c) {
            std::vector<float>& target = out.coneVisibility[std::size_t(group * 4 + c)].pixels;
            for (std::size_t i = 0; i < pixelCount; ++i)
                target[i] = texels[i * 4 + std::size_t(c)];
        }
    }
    for (std::size_t g = 0; g < 4; ++g)
        out.gpu.coneVisibility[g] = &s.visibility[g];
}

} // namespace rtlab::bentcone_ssdo
