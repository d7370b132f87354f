// The Vulkan 1.2 compute context: instance (no window, no surface), the chosen
// physical device, a logical device with one compute queue, and a command
// pool for one-shot submissions. Everything else in gpu/ (DeviceBuffer,
// DeviceArray, ComputePipeline) is created from a context and must be
// destroyed before it.
//
// Device choice: ContextOptions::deviceIndex when given (`--device N`), else
// a discrete, integrated or virtual GPU, else a CPU device (lavapipe). Every
// shader reaches its data through buffer device addresses (Vulkan 1.2 core
// feature bufferDeviceAddress, GLSL GL_EXT_buffer_reference), so a device
// without it is listed but not usable; lavapipe has it. The features vdbdag
// uses are enabled when present: shaderInt64 (required), shaderInt16,
// shaderFloat64, storageBuffer16BitAccess, 8-bit storage, scalar layout.
//
// Validation (ContextOptions::validation, VDBDAG_VULKAN_VALIDATION=1): the
// Khronos validation layer with its warnings and errors printed to stderr as
// "vulkan validation: ..." lines and counted (validationErrorCount()).
#pragma once
#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "gpu/DeviceInfo.h"

namespace vdbdag::gpu {

class VulkanContext {
public:
    // Throws vdbdag::Error with a one-line message when there is no usable
    // device, the index does not exist, or the device lacks a required feature.
    explicit VulkanContext(const ContextOptions& options = {});
    ~VulkanContext();
    VulkanContext(const VulkanContext&) = delete;
    VulkanContext& operator=(const VulkanContext&) = delete;

    const DeviceInfo& deviceInfo() const { return info_; }
    const std::vector<DeviceInfo>& allDevices() const { return devices_; }

    VkInstance instance() const { return instance_; }
    VkPhysicalDevice physicalDevice() const { return physicalDevice_; }
    VkDevice device() const { return device_; }
    VkQueue queue() const { return queue_; }
    uint32_t queueFamily() const { return queueFamily_; }
    const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return memoryProperties_; }
    uint32_t timestampValidBits() const { return timestampValidBits_; }

    // Index of a memory type allowed by `typeBits` with all `required` flags,
    // preferring one that also has `preferred`; throws when none exists.
    uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred = 0) const;

    // Records commands with `record` into a fresh primary command buffer,
    // submits it to the queue and waits for it to finish.
    void submitAndWait(const std::function<void(VkCommandBuffer)>& record);

    // Objects that live as long as the device, shared by everything created
    // from this context (e.g. compiled pipelines reused by several tracers:
    // lavapipe compiles a large shader in about a second). Released before
    // the device is destroyed.
    std::map<std::string, std::shared_ptr<void>>& sharedObjects() { return sharedObjects_; }

    // Validation-layer messages of severity error seen so far (0 without validation).
    uint64_t validationErrorCount() const { return validationErrors_.load(); }
    bool validationEnabled() const { return messenger_ != VK_NULL_HANDLE; }

private:
    std::vector<DeviceInfo> devices_;
    DeviceInfo info_;
    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    uint32_t queueFamily_ = 0;
    uint32_t timestampValidBits_ = 0;
    VkCommandPool commandPool_ = VK_NULL_HANDLE;
    VkFence fence_ = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memoryProperties_{};
    std::atomic<uint64_t> validationErrors_{0};
    std::map<std::string, std::shared_ptr<void>> sharedObjects_;

    void destroy();
};

} // namespace vdbdag::gpu
