// A storage buffer with a device address, its allocation, mapping and
// staged transfers (see DeviceBuffer.h). Staged copies run in slices of at
// most 64 MiB so a 2 GiB upload never needs a 2 GiB staging buffer.
#include "gpu/DeviceBuffer.h"

#include <algorithm>
#include <cstring>
#include <utility>

#include <fmt/core.h>

#include "gpu/VulkanCheck.h"
#include "gpu/VulkanContext.h"
#include "src/util/Error.h"

namespace vdbdag::gpu {

namespace {
constexpr uint64_t kStagingSliceBytes = 64ull << 20;

// Makes transfer writes visible to later shader reads, transfers and the host.
void transferBarrier(VkCommandBuffer cmd) {
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                            VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                         &barrier, 0, nullptr, 0, nullptr);
}
} // namespace

DeviceBuffer::DeviceBuffer(VulkanContext& context, uint64_t sizeBytes, MemoryKind kind, std::string label, bool zeroFill)
    : context_(&context), size_(std::max<uint64_t>(16, (sizeBytes + 15) & ~uint64_t(15))), label_(std::move(label)) {
    const DeviceInfo& info = context.deviceInfo();
    const uint64_t limit = std::min(info.maxMemoryAllocationSize, info.maxBufferSize);
    if (size_ > limit || sizeBytes > size_)
        throw Error(fmt::format("{}: {} bytes exceed the per-allocation limit of Vulkan device {} ({} bytes); split it (DeviceArray)",
                                label_, sizeBytes, info.name, limit));
    const VkDevice device = context.device();
    try {
        VkBufferCreateInfo bufferInfo{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
        bufferInfo.size = size_;
        bufferInfo.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
                           VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
        bufferInfo.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
        checkVk(vkCreateBuffer(device, &bufferInfo, nullptr, &buffer_), "vkCreateBuffer");

        VkMemoryRequirements req{};
        vkGetBufferMemoryRequirements(device, buffer_, &req);
        uint32_t type = 0;
        if (kind == MemoryKind::HostVisible)
            type = context.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                                          VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT | VK_MEMORY_PROPERTY_HOST_CACHED_BIT);
        else
            type = context.findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        const VkMemoryPropertyFlags flags = context.memoryProperties().memoryTypes[type].propertyFlags;
        const bool map = kind == MemoryKind::HostVisible ||
                         (kind == MemoryKind::DeviceLocal && (flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) &&
                          (flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT));

        VkMemoryAllocateFlagsInfo flagsInfo{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
        flagsInfo.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        VkMemoryAllocateInfo allocInfo{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        allocInfo.pNext = &flagsInfo;
        allocInfo.allocationSize = req.size;
        allocInfo.memoryTypeIndex = type;
        const VkResult r = vkAllocateMemory(device, &allocInfo, nullptr, &memory_);
        if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
            throw Error(fmt::format("{}: out of memory allocating {} bytes on Vulkan device {} ({})", label_, req.size, info.name, vkResultName(r)));
        checkVk(r, "vkAllocateMemory");
        checkVk(vkBindBufferMemory(device, buffer_, memory_, 0), "vkBindBufferMemory");

        VkBufferDeviceAddressInfo addressInfo{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
        addressInfo.buffer = buffer_;
        address_ = vkGetBufferDeviceAddress(device, &addressInfo);
        if (map) checkVk(vkMapMemory(device, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
        if (zeroFill) fill(0);
    } catch (...) {
        release();
        throw;
    }
}

DeviceBuffer::~DeviceBuffer() { release(); }

DeviceBuffer::DeviceBuffer(DeviceBuffer&& other) noexcept { *this = std::move(other); }

DeviceBuffer& DeviceBuffer::operator=(DeviceBuffer&& other) noexcept {
    if (this != &other) {
        release();
        context_ = std::exchange(other.context_, nullptr);
        buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
        memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
        address_ = std::exchange(other.address_, 0);
        size_ = std::exchange(other.size_, 0);
        mapped_ = std::exchange(other.mapped_, nullptr);
        label_ = std::move(other.label_);
    }
    return *this;
}

void DeviceBuffer::release() {
    if (!context_) return;
    const VkDevice device = context_->device();
    if (mapped_) vkUnmapMemory(device, memory_);
    if (buffer_ != VK_NULL_HANDLE) vkDestroyBuffer(device, buffer_, nullptr);
    if (memory_ != VK_NULL_HANDLE) vkFreeMemory(device, memory_, nullptr);
    mapped_ = nullptr;
    buffer_ = VK_NULL_HANDLE;
    memory_ = VK_NULL_HANDLE;
}

void DeviceBuffer::checkRange(uint64_t offset, uint64_t count, const char* what) const {
    if (offset > size_ || count > size_ - offset)
        throw Error(fmt::format("{}: {} of {} bytes at offset {} is outside the buffer of {} bytes", label_, what, count, offset, size_));
}

void DeviceBuffer::upload(std::span<const uint8_t> bytes, uint64_t offset) {
    checkRange(offset, bytes.size(), "upload");
    if (bytes.empty()) return;
    if (mapped_) {
        std::memcpy(static_cast<uint8_t*>(mapped_) + offset, bytes.data(), bytes.size());
        return;
    }
    DeviceBuffer staging(*context_, std::min<uint64_t>(bytes.size(), kStagingSliceBytes), MemoryKind::HostVisible, label_ + " staging", false);
    for (uint64_t done = 0; done < bytes.size();) {
        const uint64_t n = std::min<uint64_t>(bytes.size() - done, staging.size());
        std::memcpy(staging.mappedData(), bytes.data() + done, n);
        context_->submitAndWait([&](VkCommandBuffer cmd) {
            const VkBufferCopy region{0, offset + done, n};
            vkCmdCopyBuffer(cmd, staging.buffer(), buffer_, 1, &region);
            transferBarrier(cmd);
        });
        done += n;
    }
}

void DeviceBuffer::download(std::span<uint8_t> out, uint64_t offset) const {
    checkRange(offset, out.size(), "download");
    if (out.empty()) return;
    if (mapped_) {
        std::memcpy(out.data(), static_cast<const uint8_t*>(mapped_) + offset, out.size());
        return;
    }
    DeviceBuffer staging(*context_, std::min<uint64_t>(out.size(), kStagingSliceBytes), MemoryKind::HostVisible, label_ + " staging", false);
    for (uint64_t done = 0; done < out.size();) {
        const uint64_t n = std::min<uint64_t>(out.size() - done, staging.size());
        context_->submitAndWait([&](VkCommandBuffer cmd) {
            const VkBufferCopy region{offset + done, 0, n};
            vkCmdCopyBuffer(cmd, buffer_, staging.buffer(), 1, &region);
            transferBarrier(cmd);
        });
        std::memcpy(out.data() + done, staging.mappedData(), n);
        done += n;
    }
}

void DeviceBuffer::fill(uint32_t value) {
    if (mapped_) {
        auto* words = static_cast<uint32_t*>(mapped_);
        std::fill(words, words + size_ / 4, value);
        return;
    }
    context_->submitAndWait([&](VkCommandBuffer cmd) {
        vkCmdFillBuffer(cmd, buffer_, 0, VK_WHOLE_SIZE, value);
        transferBarrier(cmd);
    });
}

} // namespace vdbdag::gpu
