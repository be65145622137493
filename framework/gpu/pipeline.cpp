// Compute pipelines: descriptor-set layout, pipeline layout, shader module, specialisation.

#include "gpu/pipeline.h"

#include <algorithm>
#include <set>

#include "core/error.h"
#include "gpu/vulkan_internal.h"

namespace rtlab::gpu {

const char* getBindingTypeName(BindingType type)
{
    switch (type) {
    case BindingType::StorageBuffer:
        return "storage buffer";
    case BindingType::StorageImage:
        return "storage image";
    case BindingType::SampledImage:
        return "sampled image";
    }
    return "?";
}

namespace detail {

PipelineState::~PipelineState()
{
    if (!device)
        return;
    if (pipeline != VK_NULL_HANDLE)
        vkDestroyPipeline(device->device, pipeline, nullptr);
    if (layout != VK_NULL_HANDLE)
        vkDestroyPipelineLayout(device->device, layout, nullptr);
    if (setLayout != VK_NULL_HANDLE)
        vkDestroyDescriptorSetLayout(device->device, setLayout, nullptr);
}

VkDescriptorType toVkDescriptorType(BindingType type)
{
    switch (type) {
    case BindingType::StorageBuffer:
        return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    case BindingType::StorageImage:
        return VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    case BindingType::SampledImage:
        return VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    }
    return VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}

} // namespace detail

ComputePipeline::ComputePipeline() = default;
ComputePipeline::~ComputePipeline() = default;
ComputePipeline::ComputePipeline(ComputePipeline&&) noexcept = default;
ComputePipeline& ComputePipeline::operator=(ComputePipeline&&) noexcept = default;
ComputePipeline::ComputePipeline(std::unique_ptr<detail::PipelineState> state)
    : mState(std::move(state))
{
}

detail::PipelineState& ComputePipeline::getState() const
{
    if (!mState)
        throw Error("use of an empty gpu::ComputePipeline");
    return *mState;
}

const std::string& ComputePipeline::getName() const
{
    return getState().name;
}

const std::vector<BindingSlot>& ComputePipeline::getBindings() const
{
    return getState().bindings;
}

std::uint32_t ComputePipeline::getPushConstantSize() const
{
    return getState().pushConstantSize;
}

ComputePipeline Context::createPipeline(const ComputePipelineDesc& desc)
{
    const std::string name = desc.name.empty() ? std::string("pipeline") : desc.name;
    auto fail = [&](const std::string& why) {
        throw Error("compute pipeline '" + name + "': " + why);
    };
    constexpr std::uint32_t kSpirvMagic = 0x07230203u;
    if (desc.spirv.size() < 5 || desc.spirv[0] != kSpirvMagic)
        fail("the code is not SPIR-V (missing or empty?)");
    if (desc.pushConstantSize % 4 != 0)
        fail("push-constant size " + std::to_string(desc.pushConstantSize) +
             " is not a multiple of 4");
    if (desc.pushConstantSize > mDevice->limits.maxPushConstantsSize)
        fail("push-constant size " + std::to_string(desc.pushConstantSize) +
             " exceeds the device limit of " +
             std::to_string(mDevice->limits.maxPushConstantsSize));
    std::set<std::uint32_t> seen;
    for (const BindingSlot& b : desc.bindings) {
        if (!seen.insert(b.binding).second)
            fail("binding " + std::to_string(b.binding) + " is declared twice");
    }
    std::set<std::uint32_t> seenSpec;
    for (const SpecConstant& c : desc.specConstants) {
        if (!seenSpec.insert(c.id).second)
            fail("specialisation constant " + std::to_string(c.id) + " is given twice");
    }

    auto state = std::make_unique<detail::PipelineState>();
    state->device = mDevice;
    state->name = name;
    state->bindings = desc.bindings;
    std::sort(state->bindings.begin(), state->bindings.end(),
              [](const BindingSlot& a, const BindingSlot& b) { return a.binding < b.binding; });
    state->pushConstantSize = desc.pushConstantSize;
    VkDevice device = mDevice->device;

    std::vector<VkDescriptorSetLayoutBinding> layoutBindings;
    for (const BindingSlot& b : state->bindings) {
        VkDescriptorSetLayoutBinding lb{};
        lb.binding = b.binding;
        lb.descriptorType = detail::toVkDescriptorType(b.type);
        lb.descriptorCount = 1;
        lb.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
        layoutBindings.push_back(lb);
    }
    VkDescriptorSetLayoutCreateInfo setInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    setInfo.bindingCount = static_cast<std::uint32_t>(layoutBindings.size());
    setInfo.pBindings = layoutBindings.data();
    detail::checkResult(vkCreateDescriptorSetLayout(device, &setInfo, nullptr, &state->setLayout),
                        "vkCreateDescriptorSetLayout");

    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, desc.pushConstantSize};
    VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.setLayoutCount = 1;
    layoutInfo.pSetLayouts = &state->setLayout;
    layoutInfo.pushConstantRangeCount = desc.pushConstantSize > 0 ? 1 : 0;
    layoutInfo.pPushConstantRanges = &range;
    detail::checkResult(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &state->layout),
                        "vkCreatePipelineLayout");

    VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    moduleInfo.codeSize = desc.spirv.size() * sizeof(std::uint32_t);
    moduleInfo.pCode = desc.spirv.data();
    VkShaderModule module = VK_NULL_HANDLE;
    detail::checkResult(vkCreateShaderModule(device, &moduleInfo, nullptr, &module),
                        "vkCreateShaderModule");

    std::vector<VkSpecializationMapEntry> entries;
    std::vector<std::uint32_t> values;
    for (const SpecConstant& c : desc.specConstants) {
        entries.push_back({c.id, static_cast<std::uint32_t>(values.size() * 4), 4});
        values.push_back(c.bits);
    }
    VkSpecializationInfo spec{};
    spec.mapEntryCount = static_cast<std::uint32_t>(entries.size());
    spec.pMapEntries = entries.data();
    spec.dataSize = values.size() * sizeof(std::uint32_t);
    spec.pData = values.data();

    VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    info.stage.module = module;
    info.stage.pName = desc.entryPoint.c_str();
    info.stage.pSpecializationInfo = entries.empty() ? nullptr : &spec;
    info.layout = state->layout;
    const VkResult result =
        vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &state->pipeline);
    vkDestroyShaderModule(device, module, nullptr);
    if (result != VK_SUCCESS)
        fail(std::string("vkCreateComputePipelines failed: ") + detail::getResultName(result));
    mDevice->setObjectName(VK_OBJECT_TYPE_PIPELINE,
                           reinterpret_cast<std::uint64_t>(state->pipeline), name);
    return ComputePipeline(std::move(state));
}

} // namespace rtlab::gpu
