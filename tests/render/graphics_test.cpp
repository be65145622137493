// Graphics support of the gpu module on its own: shader stages by extension, coverage of a
// triangle at pixel centres, the provoking vertex, facing and culling, clears and loads, depth
// readback, draw timing, and the errors that recording a draw reports.

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.h"
#include "gpu/context.h"
#include "gpu/graphics.h"
#include "gpu/shader_compiler.h"
#include "render_test_support.h"

namespace rtlab::render::test {
namespace {

using namespace rtlab::gpu;

constexpr std::uint32_t kSize = 16;
constexpr std::uint32_t kClearValue = 0xdeadbeefu;

struct Vertex {
    glm::vec4 clip;
    std::uint32_t value;
};

// A triangle given in pixel coordinates (x right, y down), none of whose edges passes within
// 0.18 px of a pixel centre. A -> B -> C is clockwise on screen.
const glm::dvec2 kA(3.9, 1.4), kB(12.1, 5.6), kC(4.3, 13.4);

// Signed distance (pixels) of p from the line a -> b; positive on the right of the direction
// of travel as seen on screen (y down), which is the inside of a clockwise triangle.
double edgeDistance(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p)
{
    const glm::dvec2 d = b - a;
    return (d.x * (p.y - a.y) - d.y * (p.x - a.x)) / std::hypot(d.x, d.y);
}

class GraphicsTest : public gpu::test::GpuTest {
protected:
    GraphicsPipeline createPipeline(CullMode cull = CullMode::None, bool depth = true)
    {
        GraphicsPipelineDesc desc;
        desc.name = "flat value";
        desc.vertexSpirv =
            getCompiler().compileFile(getRenderTestShaderDir() / "clip_space.vert").spirv;
        desc.fragmentSpirv =
            getCompiler().compileFile(getRenderTestShaderDir() / "flat_value.frag").spirv;
        desc.vertexBindings = {{0, sizeof(Vertex)}};
        desc.vertexAttributes = {{0, 0, VertexFormat::Float4, 0},
                                 {1, 0, VertexFormat::Uint, sizeof(glm::vec4)}};
        desc.colorFormats = {Format::R32Uint, Format::RGBA32Float};
        desc.depthTest = depth;
        desc.cullMode = cull;
        desc.pushConstantSize = sizeof(glm::vec4);
        return getContext().createGraphicsPipeline(desc);
    }

    RenderTarget createTarget(bool depth = true)
    {
        RenderTargetDesc desc;
        desc.width = kSize;
        desc.height = kSize;
        desc.name = "test target";
        ColorAttachmentDesc value;
        value.format = Format::R32Uint;
        value.clearUint = {kClearValue, 0, 0, 0};
        ColorAttachmentDesc color;
        color.format = Format::RGBA32Float;
        color.clearFloat = {0.5f, 0.25f, 0.125f, 0.0f};
        desc.colors = {value, color};
        desc.depth = depth;
        desc.depthClear = 1.0f;
        return getContext().createRenderTarget(desc);
    }

    Buffer createVertices(float z)
    {
        auto toClip = [&](glm::dvec2 p) {
            return glm::vec4(float(2.0 * p.x / kSize - 1.0), float(2.0 * p.y / kSize - 1.0), z,
                             1.0f);
        };
        const std::vector<Vertex> vertices = {{toClip(kA), 7}, {toClip(kB), 8}, {toClip(kC), 9}};
        Buffer b = getContext().createBuffer({sizeof(Vertex) * 3, "vertices", true});
        b.uploadSpan<Vertex>(vertices);
        return b;
    }

    Buffer createIndices(std::vector<std::uint32_t> indices)
    {
        Buffer b = getContext().createBuffer({indices.size() * 4, "indices", true});
        b.uploadSpan<std::uint32_t>(indices);
        return b;
    }

    // +1 inside the triangle, -1 outside, 0 within `margin` pixels of an edge.
    static int classifyPixel(std::uint32_t x, std::uint32_t y, double margin)
    {
        const glm::dvec2 p(x + 0.5, y + 0.5);
        const double d =
            std::min({edgeDistance(kA, kB, p), edgeDistance(kB, kC, p), edgeDistance(kC, kA, p)});
        return d > margin ? 1 : (d < -margin ? -1 : 0);
    }
};

TEST(ShaderStageTest, StageFollowsTheFileExtension)
{
    EXPECT_EQ(getShaderStage("a/b.vert"), ShaderStage::Vertex);
    EXPECT_EQ(getShaderStage("b.frag"), ShaderStage::Fragment);
    EXPECT_EQ(getShaderStage("c.comp"), ShaderStage::Compute);
    EXPECT_EQ(getShaderStage("d.glsl"), ShaderStage::Compute);
    EXPECT_EQ(getShaderStage("noextension"), ShaderStage::Compute);
}

TEST_F(GraphicsTest, SameSourceAsVertexAndFragmentShaderGetsDifferentCacheKeys)
{
    const std::string source = "#version 450\nvoid main() {}\n";
    const CompiledShader vert = getCompiler().compileSource(source, "empty.vert");
    const CompiledShader frag = getCompiler().compileSource(source, "empty.frag");
    const CompiledShader comp = getCompiler().compileSource(
        "#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n", "empty.comp");
    EXPECT_EQ(vert.stage, ShaderStage::Vertex);
    EXPECT_EQ(frag.stage, ShaderStage::Fragment);
    EXPECT_EQ(comp.stage, ShaderStage::Compute);
    EXPECT_NE(vert.cacheKey, frag.cacheKey);
    EXPECT_NE(vert.spirv, frag.spirv); // different execution models
    // A second compilation comes from the cache, per stage.
    EXPECT_TRUE(getCompiler().compileSource(source, "again.frag").cacheHit);
    EXPECT_EQ(getCompiler().compileSource(source, "again.frag").spirv, frag.spirv);
}

TEST_F(GraphicsTest, TriangleCoversExactlyThePixelCentresInsideIt)
{
    const GraphicsPipeline pipeline = createPipeline();
    RenderTarget target = createTarget();
    const Buffer vertices = createVertices(0.25f);
    const Buffer indices = createIndices({0, 2, 1}); // A, C, B: counter-clockwise on screen
    const RunResult run = getContext().run([&](CommandList& cmd) {
        cmd.drawIndexed(pipeline, target, {{&vertices}, &indices, 3},
                        PushConstants(glm::vec4(1.0f, 2.0f, 3.0f, 0.0f)), "triangle");
    });
    const std::vector<std::uint32_t> values = target.downloadColorVector<std::uint32_t>(0);
    const std::vector<glm::vec4> colors = target.downloadColorVector<glm::vec4>(1);
    const std::vector<float> depth = target.downloadDepth();
    int inside = 0;
    for (std::uint32_t y = 0; y < kSize; ++y) {
        for (std::uint32_t x = 0; x < kSize; ++x) {
            const std::size_t i = y * kSize + x;
            const int where = classifyPixel(x, y, 0.1);
            ASSERT_NE(where, 0) << "test triangle passes too close to pixel " << x << "," << y;
            if (where > 0) {
                ++inside;
                EXPECT_EQ(values[i], 7u) << "the first vertex provokes; pixel " << x << "," << y;
                EXPECT_EQ(colors[i], glm::vec4(1.0f, 2.0f, 3.0f, 1.0f)) << x << "," << y;
                EXPECT_EQ(depth[i], 0.25f) << x << "," << y;
            } else {
                EXPECT_EQ(values[i], kClearValue) << x << "," << y;
                EXPECT_EQ(colors[i], glm::vec4(0.5f, 0.25f, 0.125f, 0.0f)) << x << "," << y;
                EXPECT_EQ(depth[i], 1.0f) << x << "," << y;
            }
        }
    }
    EXPECT_GT(inside, 40);
    ASSERT_EQ(run.commands.size(), 1u);
    EXPECT_EQ(run.commands[0].label, "triangle");
    if (getContext().hasGpuTimestamps()) {
        const std::optional<double> ms = run.sumGpuMs("triangle");
        ASSERT_TRUE(ms.has_value());
        EXPECT_GT(*ms, 0.0);
        EXPECT_TRUE(std::isfinite(*ms));
    }
}

TEST_F(GraphicsTest, FirstIndexOfEachTriangleProvokesFlatOutputs)
{
    const GraphicsPipeline pipeline = createPipeline();
    RenderTarget target = createTarget();
    const Buffer vertices = createVertices(0.5f);
    const Buffer indices = createIndices({2, 1, 0}); // C, B, A: same orientation as A, C, B
    getContext().run([&](CommandList& cmd) {
        cmd.drawIndexed(pipeline, target, {{&vertices}, &indices, 3}, PushConstants(glm::vec4(0)));
    });
    const std::vector<std::uint32_t> values = target.downloadColorVector<std::uint32_t>(0);
    for (std::uint32_t y = 0; y < kSize; ++y) {
        for (std::uint32_t x = 0; x < kSize; ++x) {
            if (classifyPixel(x, y, 0.1) > 0) {
                EXPECT_EQ(values[y * kSize + x], 9u) << x << "," << y;
            }
        }
    }
}

TEST_F(GraphicsTest, ClockwiseOnScreenIsBackFacingAndBackCullingDropsIt)
{
    RenderTarget target = createTarget();
    const Buffer vertices = createVertices(0.5f);
    const Buffer clockwise = createIndices({0, 1, 2});
    const GraphicsPipeline twoSided = createPipeline(CullMode::None);
    getContext().run([&](CommandList& cmd) {
        cmd.drawIndexed(twoSided, target, {{&vertices}, &clockwise, 3},
                        PushConstants(glm::vec4(0)));
    });
    std::vector<glm::vec4> colors = target.downloadColorVector<glm::vec4>(1);
    for (std::uint32_t y = 0; y < kSize; ++y) {
        for (std::uint32_t x = 0; x < kSize; ++x) {
            if (classifyPixel(x, y, 0.1) > 0) {
                EXPECT_EQ(colors[y * kSize + x].w, -1.0f) << "back facing at " << x << "," << y;
            }
        }
    }

    const GraphicsPipeline culling = createPipeline(CullMode::Back);
    getContext().run([&](CommandList& cmd) {
        cmd.drawIndexed(culling, target, {{&vertices}, &clockwise, 3}, PushConstants(glm::vec4(0)));
    });
    const std::vector<std::uint32_t> values = target.downloadColorVector<std::uint32_t>(0);
    for (std::uint32_t v : values)
        EXPECT_EQ(v, kClearValue);
}

TEST_F(GraphicsTest, DrawWithoutClearKeepsWhatTheTargetHolds)
{
    const GraphicsPipeline pipeline = createPipeline();
    RenderTarget target = createTarget();
    const Buffer near = createVertices(0.25f);
    const Buffer far = createVertices(0.75f);
    const Buffer indices = createIndices({0, 2, 1});
    IndexedDraw second{{&far}, &indices, 3};
    second.clear = false;
    getContext().run([&](CommandList& cmd) {
        cmd.drawIndexed(pipeline, target, {{&near}, &indices, 3}, PushConstants(glm::vec4(1.0f)));
        // Behind what the first draw left: fails the depth test everywhere.
        cmd.drawIndexed(pipeline, target, second, PushConstants(glm::vec4(2.0f)));
    });
    const std::vector<glm::vec4> colors = target.downloadColorVector<glm::vec4>(1);
    const std::vector<float> depth = target.downloadDepth();
    for (std::uint32_t y = 0; y < kSize; ++y) {
        for (std::uint32_t x = 0; x < kSize; ++x) {
            if (classifyPixel(x, y, 0.1) <= 0)
                continue;
            EXPECT_EQ(colors[y * kSize + x].x, 1.0f) << x << "," << y;
            EXPECT_EQ(depth[y * kSize + x], 0.25f) << x << "," << y;
        }
    }
}

TEST_F(GraphicsTest, MistakesInADrawAreReportedWhenRecorded)
{
    const GraphicsPipeline pipeline = createPipeline();
    RenderTarget target = createTarget();
    RenderTarget noDepth = createTarget(false);
    const Buffer vertices = createVertices(0.5f);
    const Buffer indices = createIndices({0, 2, 1});
    Buffer storageOnly = getContext().createBuffer({64, "storage only"});
    const PushConstants push(glm::vec4(0.0f));
    auto expectError = [&](const IndexedDraw& draw, const RenderTarget& t, PushConstants p,
                           const std::string& fragment) {
        try {
            getContext().run([&](CommandList& cmd) { cmd.drawIndexed(pipeline, t, draw, p); });
            ADD_FAILURE() << "no error for: " << fragment;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    };
    expectError({{&vertices}, &indices, 3}, noDepth, push, "no depth attachment");
    expectError({{&vertices}, &indices, 3}, target, PushConstants(), "push constants");
    expectError({{&storageOnly}, &indices, 3}, target, push, "vertexIndexUsage");
    expectError({{}, &indices, 3}, target, push, "vertex buffers");
    expectError({{&vertices}, &indices, 2}, target, push, "multiple of 3");
    expectError({{&vertices}, &indices, 6}, target, push, "exceed the index buffer");

    GraphicsPipelineDesc bad;
    bad.name = "bad";
    bad.vertexSpirv = {1, 2, 3};
    bad.fragmentSpirv = {1, 2, 3};
    bad.colorFormats = {Format::RGBA32Float};
    bad.vertexBindings = {{1, 16}};
    EXPECT_THROW(getContext().createGraphicsPipeline(bad), Error); // bindings not from 0
    EXPECT_THROW(getContext().createRenderTarget({0, 4, {}, true, 1.0f, "empty"}), Error);
}

} // namespace
} // namespace rtlab::render::test
