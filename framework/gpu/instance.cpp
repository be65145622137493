// Instance creation (headless, optional validation with a recording messenger) and the choice
// of physical device.

#include "gpu/vulkan_internal.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>

#include "core/error.h"

namespace rtlab::gpu {

// ---- ValidationLog -----------------------------------------------------------------------------

void ValidationLog::addMessage(std::string message)
{
    std::lock_guard lock(mMutex);
    mMessages.push_back(std::move(message));
}

std::vector<std::string> ValidationLog::getMessages() const
{
    std::lock_guard lock(mMutex);
    return mMessages;
}

std::size_t ValidationLog::countMessages() const
{
    std::lock_guard lock(mMutex);
    return mMessages.size();
}

void ValidationLog::clearMessages()
{
    std::lock_guard lock(mMutex);
    mMessages.clear();
}

// ---- DeviceInfo --------------------------------------------------------------------------------

const char* getDeviceTypeName(DeviceType type)
{
    switch (type) {
    case DeviceType::DiscreteGpu:
        return "discrete GPU";
    case DeviceType::IntegratedGpu:
        return "integrated GPU";
    case DeviceType::VirtualGpu:
        return "virtual GPU";
    case DeviceType::Cpu:
        return "CPU";
    case DeviceType::Other:
        break;
    }
    return "other";
}

std::string DeviceInfo::describe() const
{
    std::string s = name + " [" + getDeviceTypeName(type) + ", " + vendorName;
    if (!driverName.empty())
        s += ", " + driverName;
    if (!driverInfo.empty())
        s += " " + driverInfo;
    return s + ", Vulkan " + apiVersion + "]";
}

namespace detail {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

const char* kNoDeviceHelp =
    "rtlab runs its compute work through Vulkan; on a machine without a GPU it uses Mesa's CPU "
    "driver lavapipe. Install it with: apt-get install mesa-vulkan-drivers (the Vulkan loader "
    "is libvulkan1). If a driver is installed, check that VK_DRIVER_FILES / VK_ICD_FILENAMES "
    "do not point somewhere else.";

[[noreturn]] void throwNoDevice(const std::string& what)
{
    throw EnvironmentError("no Vulkan device is available (" + what + "). " + kNoDeviceHelp);
}

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT types,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data,
                                              void* user)
{
    auto* state = static_cast<InstanceState*>(user);
    std::string text =
        severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "[error]" : "[warning]";
    if (types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT)
        text += "[validation]";
    if (types & VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT)
        text += "[performance]";
    if (types & VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT)
        text += "[general]";
    if (data->pMessageIdName != nullptr)
        text += std::string(" ") + data->pMessageIdName;
    text += ": ";
    text += data->pMessage != nullptr ? data->pMessage : "(no message)";
    if (state->echo)
        std::fprintf(stderr, "rtlab vulkan %s\n", text.c_str());
    state->log->addMessage(std::move(text));
    return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT makeMessengerInfo(InstanceState* state)
{
    VkDebugUtilsMessengerCreateInfoEXT info{
        VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = &onDebugMessage;
    info.pUserData = state;
    return info;
}

bool hasExtension(const std::vector<VkExtensionProperties>& list, const char* name)
{
    return std::any_of(list.begin(), list.end(), [&](const VkExtensionProperties& e) {
        return std::strcmp(e.extensionName, name) == 0;
    });
}

std::vector<VkExtensionProperties> listInstanceExtensions(const char* layer)
{
    std::uint32_t count = 0;
    if (vkEnumerateInstanceExtensionProperties(layer, &count, nullptr) != VK_SUCCESS)
        return {};
    std::vector<VkExtensionProperties> list(count);
    if (vkEnumerateInstanceExtensionProperties(layer, &count, list.data()) != VK_SUCCESS)
        return {};
    list.resize(count);
    return list;
}

bool hasValidationLayer()
{
    std::uint32_t count = 0;
    if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS)
        return false;
    std::vector<VkLayerProperties> layers(count);
    if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS)
        return false;
    return std::any_of(layers.begin(), layers.begin() + count, [](const VkLayerProperties& l) {
        return std::strcmp(l.layerName, kValidationLayer) == 0;
    });
}

[[noreturn]] void throwMissingValidation(const std::string& why)
{
    throw EnvironmentError(
        "Vulkan validation was requested (ContextOptions::enableValidation or "
        "RTLAB_VK_VALIDATION=1) but " +
        why + ". Install the validation layers with: apt-get install vulkan-validationlayers");
}

std::string formatVersion(std::uint32_t v)
{
    return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
           "." + std::to_string(VK_API_VERSION_PATCH(v));
}

std::string formatDriverVersion(std::uint32_t vendor, std::uint32_t v)
{
    if (vendor == 0x10DE) { // NVIDIA: 10.8.8.6 bits
        return std::to_string(v >> 22) + "." + std::to_string((v >> 14) & 0xff) + "." +
               std::to_string((v >> 6) & 0xff) + "." + std::to_string(v & 0x3f);
    }
    return formatVersion(v);
}

std::string getVendorName(std::uint32_t vendor)
{
    switch (vendor) {
    case 0x1002:
        return "AMD";
    case 0x10DE:
        return "NVIDIA";
    case 0x8086:
        return "Intel";
    case 0x13B5:
        return "ARM";
    case 0x5143:
        return "Qualcomm";
    case 0x1010:
        return "Imagination";
    case 0x106B:
        return "Apple";
    case 0x10005:
        return "Mesa";
    default:
        break;
    }
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04x", vendor);
    return buf;
}

DeviceType toDeviceType(VkPhysicalDeviceType type)
{
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
        return DeviceType::IntegratedGpu;
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
        return DeviceType::DiscreteGpu;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
        return DeviceType::VirtualGpu;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
        return DeviceType::Cpu;
    default:
        return DeviceType::Other;
    }
}

int scoreDevice(DeviceType type)
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

std::string toLower(std::string s)
{
    for (char& c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

// Fills `info` from the device's properties. The driver strings need Vulkan 1.2 or
// VK_KHR_driver_properties.
void describeDevice(VkPhysicalDevice device, std::uint32_t queueTimestampBits, DeviceInfo& info)
{
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(device, &props);

    std::uint32_t extCount = 0;
    vkEnumerateDeviceExtensionProperties(device, nullptr, &extCount, nullptr);
    std::vector<VkExtensionProperties> exts(extCount);
    vkEnumerateDeviceExtensionProperties(device, nullptr, &extCount, exts.data());
    exts.resize(extCount);

    info.name = props.deviceName;
    info.type = toDeviceType(props.deviceType);
    info.isCpu = info.type == DeviceType::Cpu;
    info.vendorId = props.vendorID;
    info.vendorName = getVendorName(props.vendorID);
    info.deviceId = props.deviceID;
    info.apiVersion = formatVersion(props.apiVersion);
    info.driverVersion = props.driverVersion;
    info.driverVersionString = formatDriverVersion(props.vendorID, props.driverVersion);
    if (props.apiVersion >= VK_API_VERSION_1_2 ||
        hasExtension(exts, VK_KHR_DRIVER_PROPERTIES_EXTENSION_NAME)) {
        VkPhysicalDeviceDriverProperties driver{
            VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
        VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
        props2.pNext = &driver;
        vkGetPhysicalDeviceProperties2(device, &props2);
        info.driverName = driver.driverName;
        info.driverInfo = driver.driverInfo;
    }

    const VkPhysicalDeviceLimits& limits = props.limits;
    info.timestampPeriodNs = limits.timestampPeriod;
    info.timestampValidBits = queueTimestampBits;
    info.timestampsSupported = queueTimestampBits > 0 && limits.timestampPeriod > 0.0f;
    info.subTexelPrecisionBits = limits.subTexelPrecisionBits;
    info.subPixelPrecisionBits = limits.subPixelPrecisionBits;
    info.maxPushConstantsSize = limits.maxPushConstantsSize;
    info.maxComputeWorkGroupInvocations = limits.maxComputeWorkGroupInvocations;
    for (int i = 0; i < 3; ++i) {
        info.maxComputeWorkGroupSize[i] = limits.maxComputeWorkGroupSize[i];
        info.maxComputeWorkGroupCount[i] = limits.maxComputeWorkGroupCount[i];
    }
    info.maxImageDimension2D = limits.maxImageDimension2D;
    info.maxImageDimension3D = limits.maxImageDimension3D;

    VkPhysicalDeviceMemoryProperties memory;
    vkGetPhysicalDeviceMemoryProperties(device, &memory);
    for (std::uint32_t i = 0; i < memory.memoryHeapCount; ++i) {
        if (memory.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            info.deviceLocalBytes =
                std::max<std::uint64_t>(info.deviceLocalBytes, memory.memoryHeaps[i].size);
    }
}

} // namespace

InstanceState::~InstanceState()
{
    if (messenger != VK_NULL_HANDLE) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroy != nullptr)
            destroy(instance, messenger, nullptr);
    }
    if (instance != VK_NULL_HANDLE)
        vkDestroyInstance(instance, nullptr);
}

std::shared_ptr<InstanceState> createInstance(const ContextOptions& options, bool validation)
{
    auto state = std::make_shared<InstanceState>();
    state->log = options.validationLog ? options.validationLog : std::make_shared<ValidationLog>();
    state->echo = options.echoValidationMessages;
    state->validation = validation;

    std::uint32_t loaderVersion = VK_API_VERSION_1_0;
    if (vkEnumerateInstanceVersion(&loaderVersion) != VK_SUCCESS ||
        loaderVersion < VK_API_VERSION_1_1)
        throwNoDevice("the Vulkan loader only supports Vulkan 1.0; rtlab needs 1.1");

    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    VkValidationFeatureEnableEXT enabledFeatures[] = {
        VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    VkDebugUtilsMessengerCreateInfoEXT messengerInfo = makeMessengerInfo(state.get());
    const void* next = nullptr;
    if (validation) {
        if (!hasValidationLayer())
            throwMissingValidation(std::string("the layer ") + kValidationLayer +
                                   " is not installed");
        layers.push_back(kValidationLayer);
        const auto global = listInstanceExtensions(nullptr);
        const auto fromLayer = listInstanceExtensions(kValidationLayer);
        if (!hasExtension(global, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) &&
            !hasExtension(fromLayer, VK_EXT_DEBUG_UTILS_EXTENSION_NAME))
            throwMissingValidation("the instance extension VK_EXT_debug_utils is missing");
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        next = &messengerInfo;
        if (hasExtension(fromLayer, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME)) {
            extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
            features.enabledValidationFeatureCount = 1;
            features.pEnabledValidationFeatures = enabledFeatures;
            features.pNext = &messengerInfo;
            next = &features;
        }
    }

    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = options.applicationName.c_str();
    app.applicationVersion = 1;
    app.pEngineName = "rtlab";
    app.engineVersion = 1;
    app.apiVersion = std::min<std::uint32_t>(loaderVersion, VK_API_VERSION_1_2);

    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pNext = next;
    info.pApplicationInfo = &app;
    info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
    info.ppEnabledLayerNames = layers.data();
    info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();

    const VkResult result = vkCreateInstance(&info, nullptr, &state->instance);
    if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
        throwNoDevice("vkCreateInstance found no Vulkan driver: VK_ERROR_INCOMPATIBLE_DRIVER");
    if (result == VK_ERROR_LAYER_NOT_PRESENT)
        throwMissingValidation(std::string("the layer ") + kValidationLayer + " failed to load");
    if (result == VK_ERROR_EXTENSION_NOT_PRESENT && validation)
        throwMissingValidation("a debug extension is missing");
    checkResult(result, "vkCreateInstance");

    if (validation) {
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(state->instance, "vkCreateDebugUtilsMessengerEXT"));
        if (create == nullptr)
            throwMissingValidation("vkCreateDebugUtilsMessengerEXT is unavailable");
        checkResult(create(state->instance, &messengerInfo, nullptr, &state->messenger),
                    "vkCreateDebugUtilsMessengerEXT");
    }
    return state;
}

std::vector<PhysicalDeviceChoice> findUsableDevices(VkInstance instance)
{
    std::uint32_t count = 0;
    VkResult result = vkEnumeratePhysicalDevices(instance, &count, nullptr);
    if (result == VK_ERROR_INITIALIZATION_FAILED || (result == VK_SUCCESS && count == 0))
        throwNoDevice("vkEnumeratePhysicalDevices reported no devices");
    checkResult(result, "vkEnumeratePhysicalDevices");
    std::vector<VkPhysicalDevice> devices(count);
    result = vkEnumeratePhysicalDevices(instance, &count, devices.data());
    if (result != VK_INCOMPLETE)
        checkResult(result, "vkEnumeratePhysicalDevices");
    devices.resize(count);

    std::vector<PhysicalDeviceChoice> usable;
    std::vector<std::string> rejected;
    for (VkPhysicalDevice device : devices) {
        VkPhysicalDeviceProperties props;
        vkGetPhysicalDeviceProperties(device, &props);
        if (props.apiVersion < VK_API_VERSION_1_1) {
            rejected.push_back(std::string("'") + props.deviceName + "' supports only Vulkan " +
                               formatVersion(props.apiVersion) + " (1.1 needed)");
            continue;
        }
        std::uint32_t familyCount = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, nullptr);
        std::vector<VkQueueFamilyProperties> families(familyCount);
        vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, families.data());
        // The first compute family with timestamps, else the first compute family.
        int chosen = -1;
        for (std::uint32_t i = 0; i < familyCount; ++i) {
            if (!(families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) || families[i].queueCount == 0)
                continue;
            if (chosen < 0 ||
                (families[chosen].timestampValidBits == 0 && families[i].timestampValidBits > 0))
                chosen = static_cast<int>(i);
        }
        if (chosen < 0) {
            rejected.push_back(std::string("'") + props.deviceName + "' has no compute queue");
            continue;
        }
        PhysicalDeviceChoice choice;
        choice.device = device;
        choice.queueFamily = static_cast<std::uint32_t>(chosen);
        describeDevice(device, families[chosen].timestampValidBits, choice.info);
        usable.push_back(std::move(choice));
    }
    if (usable.empty()) {
        std::string why;
        for (const std::string& r : rejected)
            why += (why.empty() ? "" : "; ") + r;
        throwNoDevice("no device is usable: " + why);
    }
    return usable;
}

PhysicalDeviceChoice chooseDevice(const std::vector<PhysicalDeviceChoice>& devices,
                                  const std::string& nameFilter, const char* filterOrigin)
{
    const std::string needle = toLower(nameFilter);
    const PhysicalDeviceChoice* best = nullptr;
    for (const PhysicalDeviceChoice& d : devices) {
        if (!needle.empty() && toLower(d.info.name).find(needle) == std::string::npos)
            continue;
        if (best == nullptr || scoreDevice(d.info.type) > scoreDevice(best->info.type))
            best = &d;
    }
    if (best == nullptr) {
        std::string names;
        for (const PhysicalDeviceChoice& d : devices)
            names += std::string(names.empty() ? "" : ", ") + "'" + d.info.name + "' (" +
                     getDeviceTypeName(d.info.type) + ")";
        throw EnvironmentError(std::string(filterOrigin) + " = '" + nameFilter +
                               "' matches no Vulkan device. Available devices: " + names);
    }
    return *best;
}

} // namespace detail
} // namespace rtlab::gpu
