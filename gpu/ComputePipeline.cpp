// Compute pipeline creation, dispatch over N items with a 2D workgroup grid
// when N needs more than maxComputeWorkGroupCount[0] groups, and timing with
// timestamp queries where the queue supports them (see ComputePipeline.h).
#include "gpu/ComputePipeline.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <vector>

#include <fmt/core.h>

#include "gpu/VulkanCheck.h"
#include "gpu/VulkanContext.h"
#include "src/util/Error.h"

namespace vdbdag::gpu {

SpecConstants& SpecConstants::setUint(uint32_t id, uint32_t value) {
    if (id == 0) throw Error("specialisation constant 0 is reserved for the workgroup size");
    values_[id] = value;
    return *this;
}
SpecConstants& SpecConstants::setInt(uint32_t id, int32_t value) { return setUint(id, static_cast<uint32_t>(value)); }
SpecConstants& SpecConstants::setFloat(uint32_t id, float value) { return setUint(id, std::bit_cast<uint32_t>(value)); }
SpecConstants& SpecConstants::setBool(uint32_t id, bool value) { return setUint(id, value ? VK_TRUE : VK_FALSE); }

ComputePipeline::ComputePipeline(VulkanContext& context, std::span<const uint32_t> spirv, const SpecConstants& constants,
                                 uint32_t pushConstantBytes, uint32_t workgroupSize, std::string name, bool uniformBuffer)
    : context_(context), name_(std::move(name)), pushConstantBytes_(pushConstantBytes), workgroupSize_(workgroupSize) {
    const DeviceInfo& info = context.deviceInfo();
    if (spirv.size() < 5 || spirv[0] != 0x07230203u) throw Error(fmt::format("{}: not a SPIR-V module", name_));
    const uint32_t maxWorkgroup = std::min(info.maxComputeWorkGroupInvocations, info.maxComputeWorkGroupSizeX);
    if (workgroupSize_ == 0 || workgroupSize_ > maxWorkgroup)
        throw Error(fmt::format("{}: workgroup size {} outside [1, {}] on Vulkan device {}", name_, workgroupSize_, maxWorkgroup, info.name));
    if (pushConstantBytes_ % 4 != 0 || pushConstantBytes_ > info.maxPushConstantsSize)
        throw Error(fmt::format("{}: push constants of {} bytes (must be a multiple of 4, at most {})", name_, pushConstantBytes_,
                                info.maxPushConstantsSize));
    const VkDevice device = context.device();
    try {
        VkShaderModuleCreateInfo moduleInfo{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
        moduleInfo.codeSize = spirv.size() * sizeof(uint32_t);
        moduleInfo.pCode = spirv.data();
        checkVk(vkCreateShaderModule(device, &moduleInfo, nullptr, &module_), "vkCreateShaderModule");

        VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes_};
        VkPipelineLayoutCreateInfo layoutInfo{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        layoutInfo.pushConstantRangeCount = pushConstantBytes_ ? 1 : 0;
        layoutInfo.pPushConstantRanges = &range;
        if (uniformBuffer) {
            setLayout_ = uniformBufferSetLayout(device);
            layoutInfo.setLayoutCount = 1;
            layoutInfo.pSetLayouts = &setLayout_;
        }
        checkVk(vkCreatePipelineLayout(device, &layoutInfo, nullptr, &layout_), "vkCreatePipelineLayout");

        // Constant 0 = workgroup size, then the caller's, in id order.
        std::vector<uint32_t> data{workgroupSize_};
        std::vector<VkSpecializationMapEntry> entries{{0, 0, 4}};
        for (const auto& [id, value] : constants.values()) {
            entries.push_back({id, static_cast<uint32_t>(data.size() * 4), 4});
            data.push_back(value);
        }
        VkSpecializationInfo spec{};
        spec.mapEntryCount = static_cast<uint32_t>(entries.size());
        spec.pMapEntries = entries.data();
        spec.dataSize = data.size() * 4;
        spec.pData = data.data();

        VkComputePipelineCreateInfo pipelineInfo{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
        pipelineInfo.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        pipelineInfo.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
        pipelineInfo.stage.module = module_;
        pipelineInfo.stage.pName = "main";
        pipelineInfo.stage.pSpecializationInfo = &spec;
        pipelineInfo.layout = layout_;
        const VkResult r = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &pipelineInfo, nullptr, &pipeline_);
        if (r != VK_SUCCESS) throw Error(fmt::format("{}: vkCreateComputePipelines failed: {}", name_, vkResultName(r)));

        if (info.timestamps && context.timestampValidBits() > 0) {
            VkQueryPoolCreateInfo queryInfo{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
            queryInfo.queryType = VK_QUERY_TYPE_TIMESTAMP;
            queryInfo.queryCount = 2;
            checkVk(vkCreateQueryPool(device, &queryInfo, nullptr, &timestamps_), "vkCreateQueryPool");
        }
    } catch (...) {
        release();
        throw;
    }
}

ComputePipeline::~ComputePipeline() { release(); }

void ComputePipeline::release() {
    const VkDevice device = context_.device();
    if (timestamps_ != VK_NULL_HANDLE) vkDestroyQueryPool(device, timestamps_, nullptr);
    if (pipeline_ != VK_NULL_HANDLE) vkDestroyPipeline(device, pipeline_, nullptr);
    if (layout_ != VK_NULL_HANDLE) vkDestroyPipelineLayout(device, layout_, nullptr);
    if (setLayout_ != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
    setLayout_ = VK_NULL_HANDLE;
    if (module_ != VK_NULL_HANDLE) vkDestroyShaderModule(device, module_, nullptr);
    timestamps_ = VK_NULL_HANDLE;
    pipeline_ = VK_NULL_HANDLE;
    layout_ = VK_NULL_HANDLE;
    module_ = VK_NULL_HANDLE;
}

VkDescriptorSetLayout ComputePipeline::uniformBufferSetLayout(VkDevice device) {
    VkDescriptorSetLayoutBinding binding{};
    binding.binding = 0;
    binding.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
    binding.descriptorCount = 1;
    binding.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    VkDescriptorSetLayoutCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    info.bindingCount = 1;
    info.pBindings = &binding;
    VkDescriptorSetLayout layout = VK_NULL_HANDLE;
    checkVk(vkCreateDescriptorSetLayout(device, &info, nullptr, &layout), "vkCreateDescriptorSetLayout");
    return layout;
}

void ComputePipeline::record(VkCommandBuffer cmd, uint64_t itemCount, std::span<const uint8_t> pushConstants, DispatchTiming* grid,
                             VkDescriptorSet uniforms) {
    if ((setLayout_ != VK_NULL_HANDLE) != (uniforms != VK_NULL_HANDLE))
        throw Error(fmt::format("{}: {} uniform buffer set given, the pipeline was made {} one", name_, uniforms ? "a" : "no",
                                setLayout_ ? "with" : "without"));
    if (pushConstants.size() != pushConstantBytes_)
        throw Error(fmt::format("{}: {} bytes of push constants given, the pipeline was made for {}", name_, pushConstants.size(),
                                pushConstantBytes_));
    if (itemCount > UINT32_MAX) throw Error(fmt::format("{}: {} items exceed one dispatch's 32-bit item index", name_, itemCount));
    const DeviceInfo& info = context_.deviceInfo();
    const uint64_t groups = (itemCount + workgroupSize_ - 1) / workgroupSize_;
    const uint64_t maxX = info.maxComputeWorkGroupCount[0];
    const uint32_t x = static_cast<uint32_t>(std::min(groups, maxX));
    const uint64_t y = x ? (groups + x - 1) / x : 0;
    if (y > info.maxComputeWorkGroupCount[1])
        throw Error(fmt::format("{}: {} items need {} x {} workgroups, more than Vulkan device {} allows", name_, itemCount, x, y, info.name));
    if (grid) {
        grid->itemCount = itemCount;
        grid->groupsX = x;
        grid->groupsY = static_cast<uint32_t>(y);
    }
    if (groups == 0) return;
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
    if (pushConstantBytes_)
        vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes_, pushConstants.data());
    if (uniforms != VK_NULL_HANDLE) vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &uniforms, 0, nullptr);
    vkCmdDispatch(cmd, x, static_cast<uint32_t>(y), 1);
}

DispatchTiming ComputePipeline::dispatch(uint64_t itemCount, std::span<const uint8_t> pushConstants, VkDescriptorSet uniforms) {
    DispatchTiming timing;
    const auto start = std::chrono::steady_clock::now();
    context_.submitAndWait([&](VkCommandBuffer cmd) {
        if (timestamps_) {
            vkCmdResetQueryPool(cmd, timestamps_, 0, 2);
            vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps_, 0);
        }
        record(cmd, itemCount, pushConstants, &timing, uniforms);
        if (timestamps_) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, timestamps_, 1);
        // Shader writes -> host reads, transfers and later dispatches.
        VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        barrier.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
        barrier.dstAccessMask = VK_ACCESS_HOST_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_SHADER_READ_BIT;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                             VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1,
                             &barrier, 0, nullptr, 0, nullptr);
    });
    timing.hostMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    timing.deviceMs = timing.hostMs;
    if (timestamps_) {
        uint64_t ticks[2] = {0, 0};
        const VkResult r = vkGetQueryPoolResults(context_.device(), timestamps_, 0, 2, sizeof(ticks), ticks, sizeof(uint64_t),
                                                 VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
        if (r == VK_SUCCESS) {
            const uint32_t bits = context_.timestampValidBits();
            const uint64_t mask = bits >= 64 ? ~uint64_t(0) : (uint64_t(1) << bits) - 1;
            const uint64_t elapsed = (ticks[1] - ticks[0]) & mask;
            timing.deviceMs = static_cast<double>(elapsed) * context_.deviceInfo().timestampPeriodNs * 1e-6;
            timing.deviceTimed = true;
        }
    }
    return timing;
}

} // namespace vdbdag::gpu
