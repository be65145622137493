#pragma once
// Rasterisation: graphics pipelines (vertex + fragment SPIR-V), render targets (several colour
// attachments and an optional D32_SFLOAT depth attachment) and indexed draws recorded through
// CommandList::drawIndexed, timed like dispatches.
//
//   gpu::RenderTarget target = ctx.createRenderTarget({w, h, {{gpu::Format::RGBA32Float}}});
//   gpu::GraphicsPipeline pipe = ctx.createGraphicsPipeline(desc); // same colour formats
//   gpu::RunResult r = ctx.run([&](gpu::CommandList& cmd) {
//       cmd.drawIndexed(pipe, target, {{&vertices}, &indices, indexCount},
//                       gpu::PushConstants(params), "draw");
//   });
//   std::vector<float> texels = target.downloadColorVector<float>(0);
//
// Conventions: the viewport covers the whole target with framebuffer y pointing down (row 0 is
// the top), depth range [0, 1]. Triangles that are counter-clockwise on screen are front facing
// (with a y-flipped Vulkan projection, those that are counter-clockwise seen from their front in
// a right-handed world). Flat-shaded outputs take the first vertex of each triangle. Graphics
// pipelines have no descriptor sets: data reaches the shaders through vertex attributes and
// push constants (visible to both stages). Attachments are in VK_IMAGE_LAYOUT_GENERAL between
// commands.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gpu/format.h"
#include "gpu/resources.h"

namespace rtlab::gpu {

namespace detail {
struct GraphicsPipelineState;
struct RenderTargetState;
} // namespace detail

//! Format of one vertex attribute (32-bit components).
enum class VertexFormat {
    Float,  //!< float, VK_FORMAT_R32_SFLOAT
    Float2, //!< vec2
    Float3, //!< vec3
    Float4, //!< vec4
    Uint,   //!< uint, VK_FORMAT_R32_UINT
};

//! Size of an attribute of this format in bytes.
std::uint32_t getVertexFormatSize(VertexFormat format);

//! One vertex buffer binding, advanced per vertex. Buffer i of a draw feeds binding i.
struct VertexBinding {
    std::uint32_t binding = 0;
    std::uint32_t stride = 0; //!< bytes between consecutive vertices
};

//! layout(location = location) in ... of the vertex shader.
struct VertexAttribute {
    std::uint32_t location = 0;
    std::uint32_t binding = 0;
    VertexFormat format = VertexFormat::Float3;
    std::uint32_t offset = 0; //!< bytes from the start of the vertex
};

//! Which triangles are discarded before rasterisation.
enum class CullMode { None, Back, Front };

//! Everything needed to build a graphics pipeline for triangle lists.
struct GraphicsPipelineDesc {
    std::string name;                          //!< shown in errors and as the default label
    std::vector<std::uint32_t> vertexSpirv;    //!< e.g. CompiledShader::spirv of a .vert
    std::vector<std::uint32_t> fragmentSpirv;  //!< of a .frag
    std::vector<VertexBinding> vertexBindings; //!< bindings 0..n-1, each exactly once
    std::vector<VertexAttribute> vertexAttributes;
    //! Formats of the colour attachments: fragment output location i writes colorFormats[i].
    std::vector<Format> colorFormats;
    //! Test against and write a D32_SFLOAT depth attachment (compare "less"); the target
    //! must then have one.
    bool depthTest = true;
    CullMode cullMode = CullMode::None;
    std::uint32_t pushConstantSize = 0; //!< bytes, multiple of 4; 0 = none
};

//! A graphics pipeline with its layout and render pass. Move-only.
class GraphicsPipeline {
public:
    GraphicsPipeline();
    ~GraphicsPipeline();
    GraphicsPipeline(GraphicsPipeline&&) noexcept;
    GraphicsPipeline& operator=(GraphicsPipeline&&) noexcept;

    bool isValid() const { return mState != nullptr; }
    const std::string& getName() const;
    std::uint32_t getPushConstantSize() const;
    //! Internal state (defined in gpu/graphics_internal.h).
    detail::GraphicsPipelineState& getState() const;

private:
    friend class Context;
    explicit GraphicsPipeline(std::unique_ptr<detail::GraphicsPipelineState> state);
    std::unique_ptr<detail::GraphicsPipelineState> mState;
};

//! A colour attachment of a render target.
struct ColorAttachmentDesc {
    Format format = Format::RGBA32Float;
    std::string name;
    //! Value a clearing draw writes first (float formats; RGBA8Unorm in [0, 1]).
    std::array<float, 4> clearFloat{0.0f, 0.0f, 0.0f, 0.0f};
    //! Value a clearing draw writes first (R32Uint; only the first component is used).
    std::array<std::uint32_t, 4> clearUint{0, 0, 0, 0};
};

//! Description of a render target. All attachments have the same size.
struct RenderTargetDesc {
    std::uint32_t width = 1;                 //!< pixels
    std::uint32_t height = 1;                //!< pixels
    std::vector<ColorAttachmentDesc> colors; //!< attachment i = fragment output location i
    bool depth = true;                       //!< with a D32_SFLOAT depth attachment
    float depthClear = 1.0f;                 //!< depth a clearing draw starts from
    std::string name;
};

//! Colour attachments and an optional depth attachment that draws render into. Move-only.
//! Attachments can be read back; their texels are tightly packed, row 0 first (the top).
class RenderTarget {
public:
    RenderTarget();
    ~RenderTarget();
    RenderTarget(RenderTarget&&) noexcept;
    RenderTarget& operator=(RenderTarget&&) noexcept;

    bool isValid() const { return mState != nullptr; }
    //! The description it was created with (default names filled in).
    const RenderTargetDesc& getDesc() const;
    std::uint32_t getWidth() const;
    std::uint32_t getHeight() const;
    //! Bytes of colour attachment `index`: width * height * texel size.
    std::size_t getColorByteSize(std::size_t index) const;

    //! Reads colour attachment `index`; `size` must equal getColorByteSize(index).
    void downloadColor(std::size_t index, void* data, std::size_t size) const;
    //! Reads colour attachment `index` as an array of texel components.
    template <PlainData T> std::vector<T> downloadColorVector(std::size_t index) const
    {
        std::vector<T> values(getColorByteSize(index) / sizeof(T));
        downloadColor(index, values.data(), values.size() * sizeof(T));
        return values;
    }
    //! Reads the depth attachment (one float per pixel). Throws when there is none.
    std::vector<float> downloadDepth() const;

    //! Internal state (defined in gpu/graphics_internal.h).
    detail::RenderTargetState& getState() const;

private:
    friend class Context;
    explicit RenderTarget(std::unique_ptr<detail::RenderTargetState> state);
    std::unique_ptr<detail::RenderTargetState> mState;
};

//! One indexed draw of a triangle list (32-bit indices). The buffers must have been created
//! with BufferDesc::vertexIndexUsage and live until Context::run() returns.
struct IndexedDraw {
    std::vector<const Buffer*> vertexBuffers; //!< buffer i feeds vertex binding i
    const Buffer* indexBuffer = nullptr;
    std::uint32_t indexCount = 0; //!< multiple of 3; 0 draws nothing (the clear still happens)
    std::uint32_t firstIndex = 0;
    std::int32_t vertexOffset = 0; //!< added to every index
    //! Clear every attachment to its clear value before drawing; false draws over what the
    //! target holds.
    bool clear = true;
};

class CommandList;

//! Label of attachment copies in RunResult when none is given.
inline constexpr std::string_view kAttachmentCopyLabel = "attachment copy";

//! Records into `cmd` a copy of colour attachment `index` of `target` into slice `destinationZ`
//! of `destination` (0 for a 2D image). Attachments have no storage or sampled usage, so this is
//! how compute passes read what a draw rendered (the G-buffer, shadow-map faces) without a round
//! trip through the CPU. The destination must have the attachment's width, height and texel size.
//! Like every command it is timed and separated from its neighbours by full barriers; both must
//! live until Context::run() returns. Throws rtlab::Error on a mismatch.
void copyAttachmentToImage(CommandList& cmd, const RenderTarget& target, std::size_t index, const Image& destination,
                           std::uint32_t destinationZ = 0, std::string_view label = kAttachmentCopyLabel);

} // namespace rtlab::gpu
