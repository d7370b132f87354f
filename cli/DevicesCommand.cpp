// `vdbdag devices [--json] [--device N]`: the Vulkan devices the loader sees,
// with the limits and features the tracer depends on, and which one is
// chosen by default (like `vulkaninfo --summary`); --device N opens device N
// (as `render --device N` would) and marks it selected. No devices, or no
// device N -> one-line error, exit 1.
#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/Commands.h"
#include "cli/JsonReport.h"
#include "gpu/DeviceInfo.h"
#include "src/util/Error.h"

namespace vdbdag::cli {

namespace {

std::string mib(uint64_t bytes) {
    if (bytes >= (1ull << 30) && bytes % (1ull << 30) == 0) return fmt::format("{} GiB", bytes >> 30);
    if (bytes >= (1ull << 20) && bytes % (1ull << 20) == 0) return fmt::format("{} MiB", bytes >> 20);
    return fmt::format("{} bytes", bytes);
}

nlohmann::json toJson(const gpu::DeviceInfo& d, bool isChosen) {
    return {{"index", d.index},
            {"name", d.name},
            {"type", d.type},
            {"api_version", d.apiVersion},
            {"driver_name", d.driverName},
            {"driver_info", d.driverInfo},
            {"vendor_id", d.vendorId},
            {"device_id", d.deviceId},
            {"max_storage_buffer_range", d.maxStorageBufferRange},
            {"max_memory_allocation_size", d.maxMemoryAllocationSize},
            {"max_buffer_size", d.maxBufferSize},
            {"device_local_heap_bytes", d.deviceLocalHeapBytes},
            {"max_compute_work_group_invocations", d.maxComputeWorkGroupInvocations},
            {"max_compute_work_group_count",
             {d.maxComputeWorkGroupCount[0], d.maxComputeWorkGroupCount[1], d.maxComputeWorkGroupCount[2]}},
            {"max_push_constants_size", d.maxPushConstantsSize},
            {"subgroup_size", d.subgroupSize},
            {"buffer_device_address", d.bufferDeviceAddress},
            {"shader_int64", d.shaderInt64},
            {"uniform_buffer_standard_layout", d.uniformBufferStandardLayout},
            {"shader_int16", d.shaderInt16},
            {"storage_buffer_16bit_access", d.storageBuffer16BitAccess},
            {"shader_float64", d.shaderFloat64},
            {"timestamps", d.timestamps},
            {"timestamp_period_ns", d.timestampPeriodNs},
            {"usable", d.usable},
            {"unusable_reason", d.unusableReason},
            {"chosen", isChosen}};
}

std::string yesNo(bool b) { return b ? "yes" : "no"; }

} // namespace

void addDevicesCommand(CLI::App& app, int& exitCode) {
    struct Options { bool json = false; std::optional<uint32_t> device; };
    auto opt = std::make_shared<Options>();
    CLI::App* cmd = app.add_subcommand("devices", "List the Vulkan devices (index for --device N, limits, features, the default choice)");
    cmd->add_flag("--json", opt->json, "print JSON");
    cmd->add_option("--device", opt->device, "open device N and mark it as the selected one");
    cmd->callback([opt, &exitCode] {
        const std::vector<gpu::DeviceInfo> devices = gpu::listDevices();
        std::optional<uint32_t> chosen = gpu::defaultDeviceIndex(devices);
        if (opt->device) {
            gpu::ContextOptions options;
            options.deviceIndex = opt->device;
            chosen = gpu::openDevice(options).index;
        }
        const char* mark = opt->device ? "  (selected)" : "  (default)";
        const bool json = opt->json;
        if (json) {
            nlohmann::json report = nlohmann::json::array();
            for (const gpu::DeviceInfo& d : devices) report.push_back(toJson(d, chosen && *chosen == d.index));
            report = nlohmann::json{{"devices", report}};
            if (chosen) report[opt->device ? "selected" : "default"] = *chosen;
            printJson(report);
        } else {
            for (const gpu::DeviceInfo& d : devices) {
                fmt::print("{}: {} [{}]{}\n", d.index, d.name, d.type, chosen && *chosen == d.index ? mark : "");
                fmt::print("   Vulkan {}, driver {} {}\n", d.apiVersion, d.driverName, d.driverInfo);
                fmt::print("   maxStorageBufferRange {}, maxMemoryAllocationSize {}, device-local heap {}\n", mib(d.maxStorageBufferRange),
                           mib(d.maxMemoryAllocationSize), mib(d.deviceLocalHeapBytes));
                fmt::print("   maxComputeWorkGroupInvocations {}, maxComputeWorkGroupCount {}x{}x{}, subgroup size {}, push constants {} bytes\n",
                           d.maxComputeWorkGroupInvocations, d.maxComputeWorkGroupCount[0], d.maxComputeWorkGroupCount[1],
                           d.maxComputeWorkGroupCount[2], d.subgroupSize, d.maxPushConstantsSize);
                fmt::print("   bufferDeviceAddress {}, int64 {}, std430 uniforms {}, int16 {}, 16-bit storage {}, float64 {}, timestamps {}\n",
                           yesNo(d.bufferDeviceAddress), yesNo(d.shaderInt64), yesNo(d.uniformBufferStandardLayout), yesNo(d.shaderInt16),
                           yesNo(d.storageBuffer16BitAccess),
                           yesNo(d.shaderFloat64), d.timestamps ? fmt::format("yes ({} ns/tick)", d.timestampPeriodNs) : "no");
                if (!d.usable) fmt::print("   not usable: {}\n", d.unusableReason);
            }
        }
        if (!chosen) throw Error("no usable Vulkan device (see the reasons listed above)");
        exitCode = 0;
    });
}

} // namespace vdbdag::cli
