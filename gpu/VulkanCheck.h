// Turns failed Vulkan calls into one-line vdbdag::Error messages
// ("vkAllocateMemory failed: VK_ERROR_OUT_OF_DEVICE_MEMORY").
#pragma once
#include <vulkan/vulkan.h>

namespace vdbdag::gpu {

// The enum's name, e.g. "VK_ERROR_DEVICE_LOST".
const char* vkResultName(VkResult result);

// Throws vdbdag::Error("<what> failed: <result name>") unless result == VK_SUCCESS.
void checkVk(VkResult result, const char* what);

} // namespace vdbdag::gpu
