// A compute pipeline built from embedded SPIR-V, specialisation constants and
// a push-constant block, dispatched over N items in 1D.
//
// Conventions every vdbdag compute shader follows (see gpu/shaders/dispatch.glsl):
//  - `layout(local_size_x_id = 0) in;` : specialisation constant 0 is the
//    workgroup size, set by the pipeline (default 64);
//  - the item index is vdbdagItemIndex(): N items may need more workgroups
//    than maxComputeWorkGroupCount[0] (65535), so large dispatches use a 2D
//    grid of workgroups; the shader returns early when the index >= its item
//    count (which it receives in its own push constants);
//  - no descriptor sets: data is reached through 64-bit buffer device
//    addresses (DeviceBuffer::address(), DeviceArrayRef) in push constants;
//    parameters beyond the 128 push-constant bytes every device guarantees
//    go into a small DeviceBuffer whose address is pushed;
//  - 16-bit loads need storageBuffer16BitAccess, 64-bit ones shaderInt64
//    (both enabled when present; lavapipe has them).
// Specialisation constants (ids >= 1) compile in only what a scene has, e.g.
// `layout(constant_id = 1) const bool HAS_COLOR = false;`.
#pragma once
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <type_traits>

#include <vulkan/vulkan.h>

namespace vdbdag::gpu {

class VulkanContext;

// Values of specialisation constants by constant_id, all 32-bit (bool is a
// VkBool32, float its bit pattern). Id 0 is the workgroup size (reserved).
class SpecConstants {
public:
    SpecConstants& setUint(uint32_t id, uint32_t value);
    SpecConstants& setInt(uint32_t id, int32_t value);
    SpecConstants& setFloat(uint32_t id, float value);
    SpecConstants& setBool(uint32_t id, bool value);
    const std::map<uint32_t, uint32_t>& values() const { return values_; }

private:
    std::map<uint32_t, uint32_t> values_;
};

struct DispatchTiming {
    double hostMs = 0.0;    // submit to fence signalled, measured on the host
    double deviceMs = 0.0;  // between timestamps around the dispatch; = hostMs when !deviceTimed
    bool deviceTimed = false;
    uint64_t itemCount = 0;
    uint32_t groupsX = 0, groupsY = 0;
};

class ComputePipeline {
public:
    // `spirv`: the module (e.g. embeddedShader("trace")), entry point "main".
    // `pushConstantBytes`: size of the shader's push-constant block (0 if none;
    // at most the device's maxPushConstantsSize, >= 128 everywhere).
    // `workgroupSize`: 1..min(maxComputeWorkGroupInvocations, maxComputeWorkGroupSize[0]).
    // `name` appears in error messages.
    // `uniformBuffer`: the shader reads one uniform buffer at set 0, binding
    // 0 (a descriptor set made with uniformBufferSetLayout's definition,
    // passed to dispatch).
    ComputePipeline(VulkanContext& context, std::span<const uint32_t> spirv, const SpecConstants& constants,
                    uint32_t pushConstantBytes, uint32_t workgroupSize = 64, std::string name = "compute shader", bool uniformBuffer = false);
    ~ComputePipeline();
    ComputePipeline(const ComputePipeline&) = delete;
    ComputePipeline& operator=(const ComputePipeline&) = delete;

    // Runs the shader over `itemCount` items with `pushConstants` (exactly
    // pushConstantBytes long) and waits for it. Writes by the shader are
    // visible to the host (mapped buffers, DeviceBuffer::download) afterwards.
    DispatchTiming dispatch(uint64_t itemCount, std::span<const uint8_t> pushConstants, VkDescriptorSet uniforms = VK_NULL_HANDLE);
    template <class T>
    DispatchTiming dispatch(uint64_t itemCount, const T& pushConstants, VkDescriptorSet uniforms = VK_NULL_HANDLE) {
        static_assert(std::is_trivially_copyable_v<T>);
        return dispatch(itemCount, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(&pushConstants), sizeof(T)), uniforms);
    }

    // Records the dispatch (push constants + vkCmdDispatch) into `cmd`, for
    // callers that batch several dispatches into one submission. Add barriers yourself.
    void record(VkCommandBuffer cmd, uint64_t itemCount, std::span<const uint8_t> pushConstants, DispatchTiming* grid = nullptr,
                VkDescriptorSet uniforms = VK_NULL_HANDLE);

    // The layout of a set holding one uniform buffer at binding 0 (the
    // caller destroys it). On lavapipe a uniform-buffer read at an offset
    // all invocations share is one load; a buffer-device-address read is a
    // loop over the subgroup's lanes (~220 instructions per 8 lanes).
    static VkDescriptorSetLayout uniformBufferSetLayout(VkDevice device);

    uint32_t workgroupSize() const { return workgroupSize_; }
    VkPipeline pipeline() const { return pipeline_; }
    VkPipelineLayout layout() const { return layout_; }

private:
    VulkanContext& context_;
    std::string name_;
    uint32_t pushConstantBytes_ = 0;
    uint32_t workgroupSize_ = 0;
    VkShaderModule module_ = VK_NULL_HANDLE;
    VkPipelineLayout layout_ = VK_NULL_HANDLE;
    VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;  // uniformBuffer pipelines
    VkPipeline pipeline_ = VK_NULL_HANDLE;
    VkQueryPool timestamps_ = VK_NULL_HANDLE;

    void release();
};

} // namespace vdbdag::gpu
