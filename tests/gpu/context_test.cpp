// Context creation: device description and choice, the no-device and missing-layer errors,
// and the validation log.

#include <algorithm>
#include <cctype>
#include <string>

#include "core/error.h"
#include "gpu/context.h"
#include "gpu/shader_compiler.h"
#include "gpu_test_support.h"

namespace rtlab::gpu::test {
namespace {

std::string toUpper(std::string s)
{
    for (char& c : s)
        c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return s;
}

int rankDeviceType(DeviceType type)
{
    switch (type) {
    case DeviceType::DiscreteGpu:
        return 4;
    case DeviceType::IntegratedGpu:
        return 3;
    case DeviceType::VirtualGpu:
        return 2;
    case DeviceType::Cpu:
        return 1;
    case DeviceType::Other:
        break;
    }
    return 0;
}

// Environment that must not leak into the device-choice tests from the calling shell.
struct CleanDeviceEnv {
    ScopedEnv device{"RTLAB_VK_DEVICE", std::nullopt};
    ScopedEnv validation{"RTLAB_VK_VALIDATION", std::nullopt};
};

TEST_F(GpuTest, DescribesTheChosenDevice)
{
    const DeviceInfo& info = getContext().getDeviceInfo();
    EXPECT_FALSE(info.name.empty());
    EXPECT_FALSE(info.vendorName.empty());
    EXPECT_FALSE(info.driverName.empty());
    EXPECT_FALSE(info.driverVersionString.empty());
    EXPECT_GT(info.timestampPeriodNs, 0.0);
    EXPECT_TRUE(info.timestampsSupported);
    EXPECT_GT(info.timestampValidBits, 0u);
    EXPECT_LE(info.timestampValidBits, 64u);
    EXPECT_GE(info.subTexelPrecisionBits, 4u); // the Vulkan minimum
    EXPECT_GE(info.maxPushConstantsSize, 128u);
    EXPECT_GE(info.maxComputeWorkGroupInvocations, 128u);
    EXPECT_EQ(info.isCpu, info.type == DeviceType::Cpu);
    EXPECT_NE(info.describe().find(info.name), std::string::npos);
    if (info.name.find("llvmpipe") != std::string::npos) {
        // Mesa's lavapipe: a CPU device from the Mesa vendor id with the llvmpipe driver.
        EXPECT_TRUE(info.isCpu);
        EXPECT_EQ(info.vendorName, "Mesa");
        EXPECT_EQ(info.driverName, "llvmpipe");
        EXPECT_NE(info.driverInfo.find("Mesa"), std::string::npos);
    }
    EXPECT_TRUE(getContext().isValidationEnabled());
}

TEST(GpuContext, PicksTheMostCapableDeviceTypeByDefault)
{
    CleanDeviceEnv env;
    const std::vector<DeviceInfo> devices = Context::enumerateDevices();
    ASSERT_FALSE(devices.empty());
    int bestRank = 0;
    for (const DeviceInfo& d : devices)
        bestRank = std::max(bestRank, rankDeviceType(d.type));
    Context context;
    EXPECT_EQ(rankDeviceType(context.getDeviceInfo().type), bestRank)
        << "chose " << context.getDeviceInfo().describe();
    EXPECT_FALSE(context.isValidationEnabled());
}

TEST(GpuContext, DeviceNameOptionSelectsByCaseInsensitiveSubstring)
{
    CleanDeviceEnv env;
    for (const DeviceInfo& d : Context::enumerateDevices()) {
        ContextOptions options;
        options.deviceName = toUpper(d.name.substr(1, std::min<std::size_t>(d.name.size() - 1, 6)));
        Context context(options);
        EXPECT_NE(toUpper(context.getDeviceInfo().name).find(options.deviceName),
                  std::string::npos);
    }
}

TEST(GpuContext, DeviceNameComesFromEnvironmentWhenOptionIsEmpty)
{
    CleanDeviceEnv env;
    const std::vector<DeviceInfo> devices = Context::enumerateDevices();
    ASSERT_FALSE(devices.empty());
    const std::string wanted = devices.back().name;
    ScopedEnv device("RTLAB_VK_DEVICE", wanted);
    Context context;
    EXPECT_EQ(context.getDeviceInfo().name, wanted);

    ScopedEnv wrong("RTLAB_VK_DEVICE", "no-such-device-in-env");
    ContextOptions options;
    options.deviceName = wanted; // the option wins over the environment
    Context fromOption(options);
    EXPECT_EQ(fromOption.getDeviceInfo().name, wanted);
}

TEST(GpuContext, UnknownDeviceNameListsAvailableDevices)
{
    CleanDeviceEnv env;
    ContextOptions options;
    options.deviceName = "no-such-device-xyz";
    try {
        Context context(options);
        FAIL() << "expected rtlab::EnvironmentError";
    } catch (const EnvironmentError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("no-such-device-xyz"), std::string::npos) << what;
        EXPECT_NE(what.find("ContextOptions::deviceName"), std::string::npos) << what;
        EXPECT_NE(what.find("Available devices"), std::string::npos) << what;
        for (const DeviceInfo& d : Context::enumerateDevices())
            EXPECT_NE(what.find("'" + d.name + "'"), std::string::npos) << what;
    }

    ScopedEnv device("RTLAB_VK_DEVICE", "also-not-a-device");
    try {
        Context context;
        FAIL() << "expected rtlab::EnvironmentError";
    } catch (const EnvironmentError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("RTLAB_VK_DEVICE = 'also-not-a-device'"), std::string::npos) << what;
    }
}

// The loader reads VK_DRIVER_FILES (and the older VK_ICD_FILENAMES) whenever an instance is
// created, so pointing both at a missing manifest hides every driver from this process.
TEST(GpuContext, NoVulkanDriverGivesOneClearEnvironmentError)
{
    CleanDeviceEnv env;
    {
        ScopedEnv drivers("VK_DRIVER_FILES", "/nonexistent/rtlab-no-such-driver.json");
        ScopedEnv icds("VK_ICD_FILENAMES", "/nonexistent/rtlab-no-such-driver.json");
        ScopedEnv addDrivers("VK_ADD_DRIVER_FILES", std::nullopt);
        for (int attempt = 0; attempt < 2; ++attempt) {
            try {
                if (attempt == 0)
                    Context context;
                else
                    Context::enumerateDevices();
                FAIL() << "expected rtlab::EnvironmentError";
            } catch (const EnvironmentError& e) {
                const std::string what = e.what();
                EXPECT_NE(what.find("no Vulkan device is available"), std::string::npos) << what;
                EXPECT_NE(what.find("apt-get install mesa-vulkan-drivers"), std::string::npos)
                    << what;
            }
        }
    }
    // With the variables restored the same process finds a device again, so the error above
    // came from the hidden drivers and nothing else.
    Context context;
    EXPECT_FALSE(context.getDeviceInfo().name.empty());
}

TEST(GpuContext, MissingValidationLayerNamesTheDebianPackage)
{
    CleanDeviceEnv env;
    TempDir emptyLayerDir("no-layers");
    ScopedEnv layerPath("VK_LAYER_PATH", emptyLayerDir.getPath().string());
    ScopedEnv addLayerPath("VK_ADD_LAYER_PATH", std::nullopt);
    ScopedEnv instanceLayers("VK_INSTANCE_LAYERS", std::nullopt);
    ContextOptions options;
    options.enableValidation = true;
    try {
        Context context(options);
        FAIL() << "expected rtlab::EnvironmentError";
    } catch (const EnvironmentError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("VK_LAYER_KHRONOS_validation"), std::string::npos) << what;
        EXPECT_NE(what.find("apt-get install vulkan-validationlayers"), std::string::npos) << what;
    }
    {
        ScopedEnv validation("RTLAB_VK_VALIDATION", "1");
        EXPECT_THROW(Context context, EnvironmentError);
    }
    Context withoutValidation; // the device itself is still usable
    EXPECT_FALSE(withoutValidation.isValidationEnabled());
}

TEST(GpuContext, ValidationEnvironmentVariableTurnsValidationOn)
{
    CleanDeviceEnv env;
    {
        ScopedEnv validation("RTLAB_VK_VALIDATION", "1");
        Context context;
        EXPECT_TRUE(context.isValidationEnabled());
        EXPECT_EQ(context.getValidationLog()->countMessages(), 0u)
            << joinMessages(context.getValidationLog()->getMessages());
    }
    {
        ScopedEnv validation("RTLAB_VK_VALIDATION", "0");
        Context context;
        EXPECT_FALSE(context.isValidationEnabled());
    }
}

// The fixture's guarantee (no validation message goes unnoticed) is only worth something if
// messages really reach the log: provoke one through the public API. The smoke shader
// declares 8 bytes of push constants; a pipeline layout with only 4 is inconsistent with the
// shader (VUID-VkComputePipelineCreateInfo-layout-00703 in this layer version).
TEST_F(GpuTest, ValidationMessagesReachTheLog)
{
    ASSERT_EQ(getValidationLog()->countMessages(), 0u);
    ShaderCompilerOptions compilerOptions;
    compilerOptions.useCache = false;
    const CompiledShader shader =
        ShaderCompiler(compilerOptions).compileFile(getBuiltinShaderDir() / "smoke.comp");
    ComputePipelineDesc desc;
    desc.name = "too-small-push-range";
    desc.spirv = shader.spirv;
    desc.bindings = {{0, BindingType::StorageBuffer}, {1, BindingType::StorageBuffer}};
    desc.pushConstantSize = 4;
    desc.specConstants = {SpecConstant::makeUint(0, 64)};
    try {
        ComputePipeline pipeline = getContext().createPipeline(desc);
    } catch (const Error&) {
        // A driver may also reject the pipeline; the validation message is what matters here.
    }
    const std::vector<std::string> messages = getValidationLog()->getMessages();
    ASSERT_FALSE(messages.empty());
    EXPECT_NE(joinMessages(messages).find("[error][validation]"), std::string::npos)
        << joinMessages(messages);
    EXPECT_NE(joinMessages(messages).find("VUID-VkComputePipelineCreateInfo-layout"),
              std::string::npos)
        << joinMessages(messages);
    EXPECT_NE(joinMessages(messages).find("Push constant"), std::string::npos)
        << joinMessages(messages);
    getValidationLog()->clearMessages(); // provoked on purpose
}

TEST(GpuContext, ResourcesKeepTheDeviceAliveAfterTheContextIsGone)
{
    CleanDeviceEnv env;
    ContextOptions options;
    options.enableValidation = true;
    options.echoValidationMessages = false;
    options.validationLog = std::make_shared<ValidationLog>();
    {
        Buffer buffer;
        {
            Context context(options);
            buffer = context.createBuffer({256, "outlives-context"});
        }
        const std::vector<std::uint32_t> values(64, 7u);
        buffer.uploadSpan<std::uint32_t>(values);
        EXPECT_EQ(buffer.downloadVector<std::uint32_t>(), values);
    }
    // Everything is destroyed now; leaks or wrong destruction order would have been reported.
    EXPECT_EQ(options.validationLog->countMessages(), 0u)
        << joinMessages(options.validationLog->getMessages());
}

} // namespace
} // namespace rtlab::gpu::test
