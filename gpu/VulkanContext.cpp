// Vulkan instance, device listing and selection, logical device and one-shot
// submissions (see VulkanContext.h and DeviceInfo.h).
#include "gpu/VulkanContext.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <fmt/core.h>

#include "gpu/VulkanCheck.h"
#include "src/util/Error.h"

namespace vdbdag::gpu {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

Error noDeviceError(const char* detail) {
    std::string env;
    for (const char* name : {"VK_ICD_FILENAMES", "VK_DRIVER_FILES"})
        if (const char* v = std::getenv(name)) env += fmt::format(" ({}={})", name, v);
    return Error(fmt::format("no Vulkan device found{}: install mesa-vulkan-drivers (lavapipe, a CPU device) or your GPU's "
                             "Vulkan driver, and check VK_ICD_FILENAMES / VK_DRIVER_FILES{}",
                             detail, env));
}

VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT type,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    const bool error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    if (error && user) static_cast<std::atomic<uint64_t>*>(user)->fetch_add(1);
    const char* source = (type & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT)    ? "vulkan validation"
                         : (type & VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT) ? "vulkan performance"
                                                                                   : "vulkan";  // e.g. the loader
    std::fprintf(stderr, "%s %s: %s\n", source, error ? "error" : "warning", data->pMessage);
    return VK_FALSE;
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(std::atomic<uint64_t>* errorCounter) {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = onDebugMessage;
    info.pUserData = errorCounter;
    return info;
}

bool hasInstanceExtension(const char* name) {
    uint32_t count = 0;
    if (vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr) != VK_SUCCESS) return false;
    std::vector<VkExtensionProperties> props(count);
    vkEnumerateInstanceExtensionProperties(nullptr, &count, props.data());
    return std::any_of(props.begin(), props.end(), [&](const VkExtensionProperties& p) { return std::strcmp(p.extensionName, name) == 0; });
}

bool hasInstanceLayer(const char* name) {
    uint32_t count = 0;
    if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
    std::vector<VkLayerProperties> props(count);
    vkEnumerateInstanceLayerProperties(&count, props.data());
    return std::any_of(props.begin(), props.end(), [&](const VkLayerProperties& p) { return std::strcmp(p.layerName, name) == 0; });
}

// Creates a Vulkan 1.2 instance (with the validation layer and a messenger
// when asked). Maps "no driver" to the one-line no-device error.
VkInstance createInstance(bool validation, std::atomic<uint64_t>* errorCounter, VkDebugUtilsMessengerEXT* messenger) {
    uint32_t loaderVersion = VK_API_VERSION_1_0;
    if (vkEnumerateInstanceVersion(&loaderVersion) != VK_SUCCESS || loaderVersion < VK_API_VERSION_1_2)
        throw Error(fmt::format("the Vulkan loader supports version {}.{}, vdbdag needs 1.2: update libvulkan1",
                                VK_API_VERSION_MAJOR(loaderVersion), VK_API_VERSION_MINOR(loaderVersion)));
    std::vector<const char*> extensions, layers;
    VkInstanceCreateInfo create{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    // Portability drivers (MoltenVK) are only listed when asked for.
    if (hasInstanceExtension(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME)) {
        extensions.push_back(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
        create.flags |= VK_INSTANCE_CREATE_ENUMERATE_PORTABILITY_BIT_KHR;
    }
    VkDebugUtilsMessengerCreateInfoEXT debugInfo = messengerInfo(errorCounter);
    if (validation) {
        if (!hasInstanceLayer(kValidationLayer))
            throw Error("VDBDAG_VULKAN_VALIDATION is set but the Khronos validation layer is missing: install vulkan-validationlayers");
        layers.push_back(kValidationLayer);
        extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
        create.pNext = &debugInfo;  // also reports problems of instance creation itself
    }
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "vdbdag";
    app.applicationVersion = VK_MAKE_API_VERSION(0, 0, 1, 0);
    app.pEngineName = "vdbdag";
    app.apiVersion = VK_API_VERSION_1_2;
    create.pApplicationInfo = &app;
    create.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    create.ppEnabledExtensionNames = extensions.data();
    create.enabledLayerCount = static_cast<uint32_t>(layers.size());
    create.ppEnabledLayerNames = layers.data();
    VkInstance instance = VK_NULL_HANDLE;
    const VkResult r = vkCreateInstance(&create, nullptr, &instance);
    if (r == VK_ERROR_INCOMPATIBLE_DRIVER) throw noDeviceError(" (no Vulkan driver loaded)");
    checkVk(r, "vkCreateInstance (Vulkan 1.2)");
    if (validation) {
        auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
        if (createMessenger) createMessenger(instance, &debugInfo, nullptr, messenger);
    }
    return instance;
}

void destroyInstance(VkInstance instance, VkDebugUtilsMessengerEXT messenger) {
    if (instance == VK_NULL_HANDLE) return;
    if (messenger != VK_NULL_HANDLE) {
        auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
        if (destroyMessenger) destroyMessenger(instance, messenger, nullptr);
    }
    vkDestroyInstance(instance, nullptr);
}

std::vector<VkPhysicalDevice> enumeratePhysicalDevices(VkInstance instance) {
    uint32_t count = 0;
    checkVk(vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices");
    std::vector<VkPhysicalDevice> devices(count);
    checkVk(vkEnumeratePhysicalDevices(instance, &count, devices.data()), "vkEnumeratePhysicalDevices");
    devices.resize(count);
    if (devices.empty()) throw noDeviceError("");
    return devices;
}

std::string typeName(VkPhysicalDeviceType type) {
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
    }
}

// The first queue family that can run compute work, or -1.
int computeQueueFamily(VkPhysicalDevice device, uint32_t* timestampBits) {
    uint32_t count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
    std::vector<VkQueueFamilyProperties> families(count);
    vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
    for (uint32_t i = 0; i < count; ++i) {
        if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
            if (timestampBits) *timestampBits = families[i].timestampValidBits;
            return static_cast<int>(i);
        }
    }
    return -1;
}

DeviceInfo describe(VkPhysicalDevice device, uint32_t index) {
    DeviceInfo info;
    info.index = index;
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(device, &props);
    info.name = props.deviceName;
    info.type = typeName(props.deviceType);
    info.apiVersion = fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(props.apiVersion), VK_API_VERSION_MINOR(props.apiVersion),
                                  VK_API_VERSION_PATCH(props.apiVersion));
    info.vendorId = props.vendorID;
    info.deviceId = props.deviceID;
    const VkPhysicalDeviceLimits& limits = props.limits;
    info.maxStorageBufferRange = limits.maxStorageBufferRange;
    info.maxComputeWorkGroupInvocations = limits.maxComputeWorkGroupInvocations;
    info.maxComputeWorkGroupSizeX = limits.maxComputeWorkGroupSize[0];
    for (int i = 0; i < 3; ++i) info.maxComputeWorkGroupCount[i] = limits.maxComputeWorkGroupCount[i];
    info.maxPushConstantsSize = limits.maxPushConstantsSize;
    info.timestampPeriodNs = limits.timestampPeriod;

    VkPhysicalDeviceMemoryProperties memory{};
    vkGetPhysicalDeviceMemoryProperties(device, &memory);
    for (uint32_t h = 0; h < memory.memoryHeapCount; ++h)
        if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            info.deviceLocalHeapBytes = std::max<uint64_t>(info.deviceLocalHeapBytes, memory.memoryHeaps[h].size);

    uint32_t timestampBits = 0;
    const int family = computeQueueFamily(device, &timestampBits);
    info.timestamps = family >= 0 && timestampBits > 0 && limits.timestampPeriod > 0.0f;

    if (props.apiVersion < VK_API_VERSION_1_2) {
        info.unusableReason = fmt::format("supports Vulkan {} only, vdbdag needs 1.2", info.apiVersion);
        return info;
    }
    // Vulkan 1.1/1.2(/1.3) properties and features.
    VkPhysicalDeviceMaintenance4Properties maintenance4{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_PROPERTIES};
    VkPhysicalDeviceVulkan12Properties p12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES};
    VkPhysicalDeviceVulkan11Properties p11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES};
    p11.pNext = &p12;
    if (props.apiVersion >= VK_API_VERSION_1_3) p12.pNext = &maintenance4;
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props2.pNext = &p11;
    vkGetPhysicalDeviceProperties2(device, &props2);
    info.subgroupSize = p11.subgroupSize;
    info.maxMemoryAllocationSize = p11.maxMemoryAllocationSize;
    info.maxBufferSize = props.apiVersion >= VK_API_VERSION_1_3 ? maintenance4.maxBufferSize : p11.maxMemoryAllocationSize;
    info.driverName = p12.driverName;
    info.driverInfo = p12.driverInfo;

    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceVulkan11Features f11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
    f11.pNext = &f12;
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    features.pNext = &f11;
    vkGetPhysicalDeviceFeatures2(device, &features);
    info.bufferDeviceAddress = f12.bufferDeviceAddress;
    info.shaderInt64 = features.features.shaderInt64;
    info.uniformBufferStandardLayout = f12.uniformBufferStandardLayout;
    info.shaderInt16 = features.features.shaderInt16;
    info.shaderFloat64 = features.features.shaderFloat64;
    info.storageBuffer16BitAccess = f11.storageBuffer16BitAccess;

    if (family < 0) info.unusableReason = "has no compute queue";
    else if (!info.bufferDeviceAddress) info.unusableReason = "lacks the bufferDeviceAddress feature";
    else if (!info.shaderInt64) info.unusableReason = "lacks the shaderInt64 feature";
    else if (!info.uniformBufferStandardLayout) info.unusableReason = "lacks the uniformBufferStandardLayout feature";
    info.usable = info.unusableReason.empty();
    return info;
}

int typeRank(const std::string& type) {
    if (type == "discrete GPU") return 0;
    if (type == "integrated GPU") return 1;
    if (type == "virtual GPU") return 2;
    if (type == "CPU") return 3;
    return 4;
}

std::string deviceSummary(const std::vector<DeviceInfo>& devices) {
    std::string s;
    for (const DeviceInfo& d : devices) s += fmt::format("{}{}: {}", s.empty() ? "" : ", ", d.index, d.name);
    return s;
}

} // namespace

bool ContextOptions::validationRequestedByEnvironment() {
    const char* v = std::getenv("VDBDAG_VULKAN_VALIDATION");
    return v && *v && std::strcmp(v, "0") != 0;
}

std::vector<DeviceInfo> listDevices(const ContextOptions& options) {
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    VkInstance instance = createInstance(options.validation, nullptr, &messenger);
    std::vector<DeviceInfo> infos;
    try {
        const std::vector<VkPhysicalDevice> devices = enumeratePhysicalDevices(instance);
        for (uint32_t i = 0; i < devices.size(); ++i) infos.push_back(describe(devices[i], i));
    } catch (...) {
        destroyInstance(instance, messenger);
        throw;
    }
    destroyInstance(instance, messenger);
    return infos;
}

DeviceInfo openDevice(const ContextOptions& options) {
    const VulkanContext context(options);
    return context.deviceInfo();
}

std::optional<uint32_t> defaultDeviceIndex(const std::vector<DeviceInfo>& devices) {
    std::optional<uint32_t> best;
    for (const DeviceInfo& d : devices)
        if (d.usable && (!best || typeRank(d.type) < typeRank(devices[*best].type))) best = d.index;
    return best;
}

VulkanContext::VulkanContext(const ContextOptions& options) {
    try {
        instance_ = createInstance(options.validation, &validationErrors_, &messenger_);
        const std::vector<VkPhysicalDevice> physical = enumeratePhysicalDevices(instance_);
        for (uint32_t i = 0; i < physical.size(); ++i) devices_.push_back(describe(physical[i], i));

        uint32_t chosen = 0;
        if (options.deviceIndex) {
            chosen = *options.deviceIndex;
            if (chosen >= devices_.size())
                throw Error(fmt::format("Vulkan device {} does not exist: there {} {} device{} ({}); see `vdbdag devices`", chosen,
                                        devices_.size() == 1 ? "is" : "are", devices_.size(), devices_.size() == 1 ? "" : "s",
                                        deviceSummary(devices_)));
            if (!devices_[chosen].usable)
                throw Error(fmt::format("Vulkan device {} ({}) {}", chosen, devices_[chosen].name, devices_[chosen].unusableReason));
        } else {
            const auto best = defaultDeviceIndex(devices_);
            if (!best) {
                std::string reasons;
                for (const DeviceInfo& d : devices_) reasons += fmt::format("{}{} {}", reasons.empty() ? "" : "; ", d.name, d.unusableReason);
                throw Error(fmt::format("no usable Vulkan device: {}", reasons));
            }
            chosen = *best;
        }
        info_ = devices_[chosen];
        physicalDevice_ = physical[chosen];
        vkGetPhysicalDeviceMemoryProperties(physicalDevice_, &memoryProperties_);
        queueFamily_ = static_cast<uint32_t>(computeQueueFamily(physicalDevice_, &timestampValidBits_));

        // Enable what vdbdag's shaders use, where present.
        VkPhysicalDeviceVulkan12Features have12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
        VkPhysicalDeviceVulkan11Features have11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
        have11.pNext = &have12;
        VkPhysicalDeviceFeatures2 have{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
        have.pNext = &have11;
        vkGetPhysicalDeviceFeatures2(physicalDevice_, &have);

        VkPhysicalDeviceVulkan12Features want12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
        want12.bufferDeviceAddress = VK_TRUE;
        want12.shaderInt8 = have12.shaderInt8;
        want12.storageBuffer8BitAccess = have12.storageBuffer8BitAccess;
        want12.scalarBlockLayout = have12.scalarBlockLayout;
        want12.uniformBufferStandardLayout = have12.uniformBufferStandardLayout;
        want12.hostQueryReset = have12.hostQueryReset;
        VkPhysicalDeviceVulkan11Features want11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
        want11.pNext = &want12;
        want11.storageBuffer16BitAccess = have11.storageBuffer16BitAccess;
        VkPhysicalDeviceFeatures2 want{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
        want.pNext = &want11;
        want.features.shaderInt64 = VK_TRUE;
        want.features.shaderInt16 = have.features.shaderInt16;
        want.features.shaderFloat64 = have.features.shaderFloat64;

        const float priority = 1.0f;
        VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
        queueInfo.queueFamilyIndex = queueFamily_;
        queueInfo.queueCount = 1;
        queueInfo.pQueuePriorities = &priority;
        VkDeviceCreateInfo deviceInfo{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
        deviceInfo.pNext = &want;
        deviceInfo.queueCreateInfoCount = 1;
        deviceInfo.pQueueCreateInfos = &queueInfo;
        checkVk(vkCreateDevice(physicalDevice_, &deviceInfo, nullptr, &device_), "vkCreateDevice");
        vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

        VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
        poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT | VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
        poolInfo.queueFamilyIndex = queueFamily_;
        checkVk(vkCreateCommandPool(device_, &poolInfo, nullptr, &commandPool_), "vkCreateCommandPool");
        VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        checkVk(vkCreateFence(device_, &fenceInfo, nullptr, &fence_), "vkCreateFence");
    } catch (...) {
        destroy();
        throw;
    }
}

VulkanContext::~VulkanContext() { destroy(); }

void VulkanContext::destroy() {
    if (device_ != VK_NULL_HANDLE) {
        vkDeviceWaitIdle(device_);
        sharedObjects_.clear();
        if (fence_ != VK_NULL_HANDLE) vkDestroyFence(device_, fence_, nullptr);
        if (commandPool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_, commandPool_, nullptr);
        vkDestroyDevice(device_, nullptr);
    }
    fence_ = VK_NULL_HANDLE;
    commandPool_ = VK_NULL_HANDLE;
    device_ = VK_NULL_HANDLE;
    destroyInstance(instance_, messenger_);
    instance_ = VK_NULL_HANDLE;
    messenger_ = VK_NULL_HANDLE;
}

uint32_t VulkanContext::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const {
    int fallback = -1;
    for (uint32_t i = 0; i < memoryProperties_.memoryTypeCount; ++i) {
        if (!(typeBits & (1u << i))) continue;
        const VkMemoryPropertyFlags flags = memoryProperties_.memoryTypes[i].propertyFlags;
        if ((flags & required) != required) continue;
        if ((flags & preferred) == preferred) return i;
        if (fallback < 0) fallback = static_cast<int>(i);
    }
    if (fallback < 0) throw Error(fmt::format("Vulkan device {} has no memory type with property flags 0x{:x}", info_.name, required));
    return static_cast<uint32_t>(fallback);
}

void VulkanContext::submitAndWait(const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBufferAllocateInfo allocInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    allocInfo.commandPool = commandPool_;
    allocInfo.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocInfo.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    checkVk(vkAllocateCommandBuffers(device_, &allocInfo, &cmd), "vkAllocateCommandBuffers");
    struct Free {
        VkDevice d; VkCommandPool p; VkCommandBuffer c;
        ~Free() { vkFreeCommandBuffers(d, p, 1, &c); }
    } freeOnExit{device_, commandPool_, cmd};
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    checkVk(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
    record(cmd);
    checkVk(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    checkVk(vkResetFences(device_, 1, &fence_), "vkResetFences");
    checkVk(vkQueueSubmit(queue_, 1, &submit, fence_), "vkQueueSubmit");
    // No timeout: a long trace on a CPU device legitimately takes seconds.
    checkVk(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

} // namespace vdbdag::gpu
