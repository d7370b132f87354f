// What vdbdag knows about one Vulkan physical device, and how a device is
// chosen. This header is Vulkan-free so the CLI can list devices without
// Vulkan headers (DESIGN.md folder rules: Vulkan lives only in gpu/).
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace vdbdag::gpu {

struct DeviceInfo {
    uint32_t index = 0;             // position in the loader's enumeration: what --device N means
    std::string name;               // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string type;               // "discrete GPU", "integrated GPU", "virtual GPU", "CPU", "other"
    std::string apiVersion;         // e.g. "1.3.230"
    std::string driverName;         // e.g. "llvmpipe" (empty before Vulkan 1.2)
    std::string driverInfo;         // e.g. "Mesa 22.3.6 (LLVM 15.0.6)"
    uint32_t vendorId = 0, deviceId = 0;
    // Limits that decide how data is laid out and how work is dispatched.
    uint64_t maxStorageBufferRange = 0;       // bytes one storage-buffer binding may see (lavapipe: 128 MiB)
    uint64_t maxMemoryAllocationSize = 0;     // bytes per allocation (lavapipe: 2 GiB)
    uint64_t maxBufferSize = 0;               // bytes per VkBuffer (Vulkan 1.3; else = maxMemoryAllocationSize)
    uint64_t deviceLocalHeapBytes = 0;        // size of the largest device-local heap
    uint32_t maxComputeWorkGroupInvocations = 0;
    uint32_t maxComputeWorkGroupSizeX = 0;
    uint32_t maxComputeWorkGroupCount[3] = {0, 0, 0};
    uint32_t maxPushConstantsSize = 0;
    uint32_t subgroupSize = 0;
    // Features vdbdag uses.
    bool bufferDeviceAddress = false;  // required: all data is reached through 64-bit addresses
    bool shaderInt64 = false;          // required: addresses and leaf masks are 64-bit
    bool uniformBufferStandardLayout = false;  // required: the tracer's parameters are a std430 uniform block
    bool shaderInt16 = false;
    bool storageBuffer16BitAccess = false;
    bool shaderFloat64 = false;
    bool timestamps = false;           // compute-queue timestamp queries
    double timestampPeriodNs = 0.0;
    // A device is usable when it speaks Vulkan 1.2, has a compute queue and
    // the required features; otherwise `unusableReason` says why.
    bool usable = false;
    std::string unusableReason;
};

// How to create a VulkanContext.
struct ContextOptions {
    // Explicit device (`--device N`); empty = the default choice: a discrete,
    // then integrated, then virtual GPU, else a CPU device such as lavapipe.
    std::optional<uint32_t> deviceIndex;
    // Khronos validation layer, messages to stderr. Default: on when the
    // environment variable VDBDAG_VULKAN_VALIDATION is set to a value other than "0".
    bool validation = validationRequestedByEnvironment();

    static bool validationRequestedByEnvironment();
};

// Lists every physical device (usable or not). Throws vdbdag::Error
// ("no Vulkan device found: ...") when there is no loader, no driver or no device.
std::vector<DeviceInfo> listDevices(const ContextOptions& options = {});

// Opens the device `options` choose (a full VulkanContext, then closes it)
// and returns its description: checks that `--device N` exists and works.
// Throws the same one-line vdbdag::Error as VulkanContext.
DeviceInfo openDevice(const ContextOptions& options);

// The index the default choice picks among `devices` (usable ones only), or
// empty when none is usable.
std::optional<uint32_t> defaultDeviceIndex(const std::vector<DeviceInfo>& devices);

} // namespace vdbdag::gpu
