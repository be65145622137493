#pragma once
// Compute pipelines: SPIR-V, the descriptor bindings of set 0, a push-constant block and
// specialisation constants.

#include <bit>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace rtlab::gpu {

namespace detail {
struct PipelineState;
}

//! Kind of resource at a binding of descriptor set 0.
enum class BindingType {
    StorageBuffer, //!< layout(set = 0, binding = N) buffer ...
    StorageImage,  //!< layout(binding = N, rgba32f) uniform image2D/3D ...
    SampledImage,  //!< layout(binding = N) uniform sampler2D/3D ... (combined image sampler)
};

//! "storage buffer", "storage image", "sampled image".
const char* getBindingTypeName(BindingType type);

//! One binding of a pipeline's descriptor set 0.
struct BindingSlot {
    std::uint32_t binding = 0;
    BindingType type = BindingType::StorageBuffer;
};

//! A specialisation constant: layout(constant_id = id) const ... in GLSL, including
//! layout(local_size_x_id = id) in. Always 32 bits wide.
struct SpecConstant {
    std::uint32_t id = 0;
    std::uint32_t bits = 0; //!< the value's bit pattern

    static SpecConstant makeUint(std::uint32_t id, std::uint32_t value) { return {id, value}; }
    static SpecConstant makeInt(std::uint32_t id, std::int32_t value)
    {
        return {id, std::bit_cast<std::uint32_t>(value)};
    }
    static SpecConstant makeFloat(std::uint32_t id, float value)
    {
        return {id, std::bit_cast<std::uint32_t>(value)};
    }
    static SpecConstant makeBool(std::uint32_t id, bool value) { return {id, value ? 1u : 0u}; }
};

//! Everything needed to build a compute pipeline.
struct ComputePipelineDesc {
    std::string name;                   //!< shown in errors and as the default label
    std::vector<std::uint32_t> spirv;   //!< e.g. CompiledShader::spirv
    std::vector<BindingSlot> bindings;  //!< descriptor set 0
    std::uint32_t pushConstantSize = 0; //!< bytes, multiple of 4; 0 = none
    std::vector<SpecConstant> specConstants;
    std::string entryPoint = "main";
};

//! A compute pipeline with its descriptor-set and pipeline layouts. Move-only.
class ComputePipeline {
public:
    ComputePipeline();
    ~ComputePipeline();
    ComputePipeline(ComputePipeline&&) noexcept;
    ComputePipeline& operator=(ComputePipeline&&) noexcept;

    bool isValid() const { return mState != nullptr; }
    const std::string& getName() const;
    const std::vector<BindingSlot>& getBindings() const;
    std::uint32_t getPushConstantSize() const;
    detail::PipelineState& getState() const;

private:
    friend class Context;
    explicit ComputePipeline(std::unique_ptr<detail::PipelineState> state);
    std::unique_ptr<detail::PipelineState> mState;
};

} // namespace rtlab::gpu
