// One-line errors for failed Vulkan calls (see VulkanCheck.h).
#include "gpu/VulkanCheck.h"

#include <fmt/core.h>

#include "src/util/Error.h"

namespace vdbdag::gpu {

const char* vkResultName(VkResult result) {
    switch (result) {
#define VDBDAG_VK_CASE(x) case x: return #x;
        VDBDAG_VK_CASE(VK_SUCCESS)
        VDBDAG_VK_CASE(VK_NOT_READY)
        VDBDAG_VK_CASE(VK_TIMEOUT)
        VDBDAG_VK_CASE(VK_INCOMPLETE)
        VDBDAG_VK_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
        VDBDAG_VK_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        VDBDAG_VK_CASE(VK_ERROR_INITIALIZATION_FAILED)
        VDBDAG_VK_CASE(VK_ERROR_DEVICE_LOST)
        VDBDAG_VK_CASE(VK_ERROR_MEMORY_MAP_FAILED)
        VDBDAG_VK_CASE(VK_ERROR_LAYER_NOT_PRESENT)
        VDBDAG_VK_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
        VDBDAG_VK_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
        VDBDAG_VK_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
        VDBDAG_VK_CASE(VK_ERROR_TOO_MANY_OBJECTS)
        VDBDAG_VK_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
        VDBDAG_VK_CASE(VK_ERROR_FRAGMENTED_POOL)
        VDBDAG_VK_CASE(VK_ERROR_UNKNOWN)
        VDBDAG_VK_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
        VDBDAG_VK_CASE(VK_ERROR_INVALID_EXTERNAL_HANDLE)
        VDBDAG_VK_CASE(VK_ERROR_FRAGMENTATION)
        VDBDAG_VK_CASE(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
#undef VDBDAG_VK_CASE
    default: return "unknown VkResult";
    }
}

void checkVk(VkResult result, const char* what) {
    if (result != VK_SUCCESS) throw Error(fmt::format("{} failed: {} ({})", what, vkResultName(result), static_cast<int>(result)));
}

} // namespace vdbdag::gpu
