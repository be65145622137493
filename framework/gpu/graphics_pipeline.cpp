// Graphics pipelines, render passes and the device checks that drawing needs.

#include "gpu/graphics.h"

#include <algorithm>

#include "core/error.h"
#include "gpu/context.h"
#include "gpu/graphics_internal.h"

namespace rtlab::gpu {

std::uint32_t getVertexFormatSize(VertexFormat format)
{
    switch (format) {
    case VertexFormat::Float:
    case VertexFormat::Uint:
        return 4;
    case VertexFormat::Float2:
        return 8;
    case VertexFormat::Float3:
        return 12;
    case VertexFormat::Float4:
        return 16;
    }
    return 0;
}

namespace detail {

namespace {

VkFormat toVkVertexFormat(VertexFormat format)
{
    switch (format) {
    case VertexFormat::Float:
        return VK_FORMAT_R32_SFLOAT;
    case VertexFormat::Float2:
        return VK_FORMAT_R32G32_SFLOAT;
    case VertexFormat::Float3:
        return VK_FORMAT_R32G32B32_SFLOAT;
    case VertexFormat::Float4:
        return VK_FORMAT_R32G32B32A32_SFLOAT;
    case VertexFormat::Uint:
        return VK_FORMAT_R32_UINT;
    }
    return VK_FORMAT_UNDEFINED;
}

VkCullModeFlags toVkCullMode(CullMode mode)
{
    switch (mode) {
    case CullMode::None:
        return VK_CULL_MODE_NONE;
    case CullMode::Back:
        return VK_CULL_MODE_BACK_BIT;
    case CullMode::Front:
        return VK_CULL_MODE_FRONT_BIT;
    }
    return VK_CULL_MODE_NONE;
}

VkFormatFeatureFlags getOptimalFeatures(const DeviceState& device, VkFormat format)
{
    VkFormatProperties props;
    vkGetPhysicalDeviceFormatProperties(device.physicalDevice, format, &props);
    return props.optimalTilingFeatures;
}

// Destroys a shader module on scope exit.
class ShaderModule {
public:
    ShaderModule(VkDevice device, const std::vector<std::uint32_t>& spirv, const std::string& what)
        : mDevice(device)
    {
        if (spirv.empty())
            throw Error(what + ": no SPIR-V given");
        VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        info.codeSize = spirv.size() * sizeof(std::uint32_t);
        info.pCode = spirv.data();
        checkResult(vkCreateShaderModule(device, &info, nullptr, &mModule),
                    (what + ": vkCreateShaderModule").c_str());
    }
    ~ShaderModule() { vkDestroyShaderModule(mDevice, mModule, nullptr); }
    ShaderModule(const ShaderModule&) = delete;
    ShaderModule& operator=(const ShaderModule&) = delete;
    VkShaderModule get() const { return mModule; }

private:
    VkDevice mDevice;
    VkShaderModule mModule = VK_NULL_HANDLE;
};

void checkVertexInput(const GraphicsPipelineDesc& desc, const std::string& what)
{
    const auto bindingCount = desc.vertexBindings.size();
    for (std::size_t i = 0; i < bindingCount; ++i) {
        const auto n = std::count_if(
            desc.vertexBindings.begin(), desc.vertexBindings.end(),
            [&](const VertexBinding& b) { return b.binding == static_cast<std::uint32_t>(i); });
        if (n != 1)
            throw Error(what + ": vertex bindings must be numbered 0.." +
                        std::to_string(bindingCount - 1) + ", each once");
    }
    for (const VertexAttribute& a : desc.vertexAttributes) {
        const std::string where =
            what + ": vertex attribute at location " + std::to_string(a.location);
        if (a.binding >= bindingCount)
            throw Error(where + " uses binding " + std::to_string(a.binding) +
                        ", which is not declared");
        const auto same =
            std::count_if(desc.vertexAttributes.begin(), desc.vertexAttributes.end(),
                          [&](const VertexAttribute& b) { return b.location == a.location; });
        if (same > 1)
            throw Error(where + " is declared more than once");
        const VertexBinding& binding =
            *std::find_if(desc.vertexBindings.begin(), desc.vertexBindings.end(),
                          [&](const VertexBinding& b) { return b.binding == a.binding; });
        if (a.offset + getVertexFormatSize(a.format) > binding.stride)
            throw Error(where + " does not fit in the stride of " + std::to_string(binding.stride) +
                        " bytes");
    }
}

} // namespace

void requireGraphicsQueue(const DeviceState& device, const std::string& what)
{
    std::uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device.physicalDevice, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(device.physicalDevice, &count, families.data());
    if (device.queueFamily >= count ||
        !(families[device.queueFamily].queueFlags & VK_QUEUE_GRAPHICS_BIT))
        throw Error(what + ": the queue family in use on '" + device.info.name +
                    "' cannot draw (no graphics support)");
}

void requireColorAttachmentFormat(const DeviceState& device, Format format, const std::string& what)
{
    if (!(getOptimalFeatures(device, toVkFormat(format)) & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BIT))
        throw Error(what + ": this device cannot render to format " +
                    std::string(getFormatName(format)));
}

void requireDepthAttachmentFormat(const DeviceState& device, const std::string& what)
{
    const VkFormatFeatureFlags needed =
        VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_FORMAT_FEATURE_TRANSFER_SRC_BIT;
    if ((getOptimalFeatures(device, VK_FORMAT_D32_SFLOAT) & needed) != needed)
        throw Error(what + ": this device has no D32_SFLOAT depth attachments");
}

VkRenderPass createRenderPass(DeviceState& device, const std::vector<Format>& colorFormats,
                              bool depth, bool clear)
{
    std::vector<VkAttachmentDescription> attachments;
    std::vector<VkAttachmentReference> colorRefs;
    const VkAttachmentLoadOp load =
        clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    const VkImageLayout initial = clear ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_GENERAL;
    for (Format format : colorFormats) {
        VkAttachmentDescription a{};
        a.format = toVkFormat(format);
        a.samples = VK_SAMPLE_COUNT_1_BIT;
        a.loadOp = load;
        a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        a.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        a.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        a.initialLayout = initial;
        a.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
        colorRefs.push_back({static_cast<std::uint32_t>(attachments.size()),
                             VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL});
        attachments.push_back(a);
    }
    VkAttachmentReference depthRef{static_cast<std::uint32_t>(attachments.size()),
                                   VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    if (depth) {
        VkAttachmentDescription a{};
        a.format = VK_FORMAT_D32_SFLOAT;
        a.samples = VK_SAMPLE_COUNT_1_BIT;
        a.loadOp = load;
        a.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        a.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        a.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        a.initialLayout = initial;
        a.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
        attachments.push_back(a);
    }

    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = static_cast<std::uint32_t>(colorRefs.size());
    subpass.pColorAttachments = colorRefs.data();
    subpass.pDepthStencilAttachment = depth ? &depthRef : nullptr;

    // Everything before the pass happens before its attachment accesses, and those before
    // everything after it (the layout transitions are ordered by these dependencies too).
    constexpr VkPipelineStageFlags kAttachmentStages =
        VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
        VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    constexpr VkAccessFlags kAttachmentWrites =
        VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    constexpr VkAccessFlags kAttachmentAccesses = kAttachmentWrites |
                                                  VK_ACCESS_COLOR_ATTACHMENT_READ_BIT |
                                                  VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT;
    VkSubpassDependency dependencies[2]{};
    dependencies[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    dependencies[0].dstSubpass = 0;
    dependencies[0].srcStageMask = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    dependencies[0].dstStageMask = kAttachmentStages;
    dependencies[0].srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
    dependencies[0].dstAccessMask = kAttachmentAccesses;
    dependencies[1].srcSubpass = 0;
    dependencies[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    dependencies[1].srcStageMask = kAttachmentStages;
    dependencies[1].dstStageMask = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    dependencies[1].srcAccessMask = kAttachmentWrites;
    dependencies[1].dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;

    VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    info.attachmentCount = static_cast<std::uint32_t>(attachments.size());
    info.pAttachments = attachments.data();
    info.subpassCount = 1;
    info.pSubpasses = &subpass;
    info.dependencyCount = 2;
    info.pDependencies = dependencies;
    VkRenderPass pass = VK_NULL_HANDLE;
    checkResult(vkCreateRenderPass(device.device, &info, nullptr, &pass), "vkCreateRenderPass");
    return pass;
}

GraphicsPipelineState::~GraphicsPipelineState()
{
    if (!device)
        return;
    if (pipeline != VK_NULL_HANDLE)
        vkDestroyPipeline(device->device, pipeline, nullptr);
    if (layout != VK_NULL_HANDLE)
        vkDestroyPipelineLayout(device->device, layout, nullptr);
    if (renderPass != VK_NULL_HANDLE)
        vkDestroyRenderPass(device->device, renderPass, nullptr);
}

} // namespace detail

// ---- GraphicsPipeline --------------------------------------------------------------------------

GraphicsPipeline::GraphicsPipeline() = default;
GraphicsPipeline::~GraphicsPipeline() = default;
GraphicsPipeline::GraphicsPipeline(GraphicsPipeline&&) noexcept = default;
GraphicsPipeline& GraphicsPipeline::operator=(GraphicsPipeline&&) noexcept = default;
GraphicsPipeline::GraphicsPipeline(std::unique_ptr<detail::GraphicsPipelineState> state)
    : mState(std::move(state))
{
}

detail::GraphicsPipelineState& GraphicsPipeline::getState() const
{
    if (!mState)
        throw Error("use of an empty gpu::GraphicsPipeline");
    return *mState;
}

const std::string& GraphicsPipeline::getName() const
{
    return getState().name;
}

std::uint32_t GraphicsPipeline::getPushConstantSize() const
{
    return getState().pushConstantSize;
}

GraphicsPipeline Context::createGraphicsPipeline(const GraphicsPipelineDesc& desc)
{
    const std::string name = desc.name.empty() ? std::string("graphics pipeline") : desc.name;
    const std::string what = "graphics pipeline '" + name + "'";
    detail::DeviceState& device = *mDevice;
    detail::requireGraphicsQueue(device, what);
    if (desc.colorFormats.empty() && !desc.depthTest)
        throw Error(what + " writes no attachment");
    if (desc.colorFormats.size() > device.limits.maxColorAttachments)
        throw Error(what + ": " + std::to_string(desc.colorFormats.size()) +
                    " colour attachments exceed the device limit of " +
                    std::to_string(device.limits.maxColorAttachments));
    for (Format format : desc.colorFormats)
        detail::requireColorAttachmentFormat(device, format, what);
    if (desc.depthTest)
        detail::requireDepthAttachmentFormat(device, what);
    if (desc.pushConstantSize % 4 != 0 ||
        desc.pushConstantSize > device.limits.maxPushConstantsSize)
        throw Error(what + ": push-constant size " + std::to_string(desc.pushConstantSize) +
                    " is not a multiple of 4 or exceeds the device limit of " +
                    std::to_string(device.limits.maxPushConstantsSize) + " bytes");
    detail::checkVertexInput(desc, what);

    auto state = std::make_unique<detail::GraphicsPipelineState>();
    state->device = mDevice;
    state->name = name;
    state->colorFormats = desc.colorFormats;
    state->vertexBindings = desc.vertexBindings;
    state->depthTest = desc.depthTest;
    state->pushConstantSize = desc.pushConstantSize;
    state->renderPass = detail::createRenderPass(device, desc.colorFormats, desc.depthTest, true);

    VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                              desc.pushConstantSize};
    VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    layoutInfo.pushConstantRangeCount = desc.pushConstantSize > 0 ? 1 : 0;
    layoutInfo.pPushConstantRanges = &range;
    detail::checkResult(vkCreatePipelineLayout(device.device, &layoutInfo, nullptr, &state->layout),
                        "vkCreatePipelineLayout");

    const detail::ShaderModule vertex(device.device, desc.vertexSpirv, what + " (vertex)");
    const detail::ShaderModule fragment(device.device, desc.fragmentSpirv, what + " (fragment)");
    VkPipelineShaderStageCreateInfo stages[2]{};
    stages[0].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vertex.get();
    stages[0].pName = "main";
    stages[1].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = fragment.get();
    stages[1].pName = "main";

    std::vector<VkVertexInputBindingDescription> bindings;
    for (const VertexBinding& b : desc.vertexBindings)
        bindings.push_back({b.binding, b.stride, VK_VERTEX_INPUT_RATE_VERTEX});
    std::vector<VkVertexInputAttributeDescription> attributes;
    for (const VertexAttribute& a : desc.vertexAttributes)
        attributes.push_back({a.location, a.binding, detail::toVkVertexFormat(a.format), a.offset});
    VkPipelineVertexInputStateCreateInfo vertexInput{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vertexInput.vertexBindingDescriptionCount = static_cast<std::uint32_t>(bindings.size());
    vertexInput.pVertexBindingDescriptions = bindings.data();
    vertexInput.vertexAttributeDescriptionCount = static_cast<std::uint32_t>(attributes.size());
    vertexInput.pVertexAttributeDescriptions = attributes.data();

    VkPipelineInputAssemblyStateCreateInfo assembly{
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;

    VkPipelineViewportStateCreateInfo viewport{
        VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1; // set when drawing
    viewport.scissorCount = 1;

    VkPipelineRasterizationStateCreateInfo raster{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = detail::toVkCullMode(desc.cullMode);
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;

    VkPipelineMultisampleStateCreateInfo multisample{
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;

    VkPipelineDepthStencilStateCreateInfo depth{
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = desc.depthTest ? VK_TRUE : VK_FALSE;
    depth.depthWriteEnable = desc.depthTest ? VK_TRUE : VK_FALSE;
    depth.depthCompareOp = VK_COMPARE_OP_LESS;

    std::vector<VkPipelineColorBlendAttachmentState> blends(desc.colorFormats.size());
    for (VkPipelineColorBlendAttachmentState& b : blends)
        b.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                           VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo blend{
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    blend.attachmentCount = static_cast<std::uint32_t>(blends.size());
    blend.pAttachments = blends.data();

    const VkDynamicState dynamicStates[] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamicStates;

    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &vertexInput;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = desc.depthTest ? &depth : nullptr;
    info.pColorBlendState = &blend;
    info.pDynamicState = &dynamic;
    info.layout = state->layout;
    info.renderPass = state->renderPass;
    info.subpass = 0;
    detail::checkResult(vkCreateGraphicsPipelines(device.device, VK_NULL_HANDLE, 1, &info, nullptr,
                                                  &state->pipeline),
                        ("creating " + what).c_str());
    mDevice->setObjectName(VK_OBJECT_TYPE_PIPELINE,
                           reinterpret_cast<std::uint64_t>(state->pipeline), name);
    return GraphicsPipeline(std::move(state));
}

} // namespace rtlab::gpu
