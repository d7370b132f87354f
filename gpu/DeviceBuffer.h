// One VkBuffer with its own memory allocation, usable as a storage buffer and
// reachable from shaders through its 64-bit device address (buffer device
// address, Vulkan 1.2 core). Large inputs that exceed one allocation go
// through DeviceArray, which splits them over several DeviceBuffers.
#pragma once
#include <cstdint>
#include <span>
#include <string>

#include <vulkan/vulkan.h>

namespace vdbdag::gpu {

class VulkanContext;

enum class MemoryKind {
    // Host-visible, coherent and mapped: the host writes inputs and reads
    // results directly (prefers device-local host-visible memory, e.g. on
    // lavapipe or a resizable-BAR GPU). Use it for results read back.
    HostVisible,
    // Device-local: the fastest for shaders. Mapped directly when the
    // device-local memory is host-visible too (lavapipe, integrated GPUs);
    // otherwise upload() and download() go through a staging buffer.
    DeviceLocal,
    // Device-local and never mapped: always staged (what a discrete GPU does;
    // lets tests exercise the staging path on lavapipe).
    DeviceLocalStaged,
};

class DeviceBuffer {
public:
    // Allocates `sizeBytes` (rounded up to 16, at least 16) bytes, zero-filled
    // unless `zeroFill` is false (for buffers about to be overwritten whole).
    // Throws vdbdag::Error naming `label` when the size exceeds the device's
    // per-allocation or per-buffer limit or memory runs out.
    DeviceBuffer(VulkanContext& context, uint64_t sizeBytes, MemoryKind kind, std::string label = "buffer", bool zeroFill = true);
    ~DeviceBuffer();
    DeviceBuffer(DeviceBuffer&& other) noexcept;
    DeviceBuffer& operator=(DeviceBuffer&& other) noexcept;
    DeviceBuffer(const DeviceBuffer&) = delete;
    DeviceBuffer& operator=(const DeviceBuffer&) = delete;

    VkBuffer buffer() const { return buffer_; }
    uint64_t address() const { return address_; }  // what shaders dereference (GL_EXT_buffer_reference)
    uint64_t size() const { return size_; }          // the rounded-up size
    bool isMapped() const { return mapped_ != nullptr; }
    void* mappedData() const { return mapped_; }     // null unless isMapped()
    const std::string& label() const { return label_; }

    // Copies `bytes` to [offset, offset + bytes.size()); staged when not mapped.
    void upload(std::span<const uint8_t> bytes, uint64_t offset = 0);
    // Copies [offset, offset + out.size()) back to `out`; staged when not mapped.
    // Call after the work writing the buffer has finished (dispatches wait).
    void download(std::span<uint8_t> out, uint64_t offset = 0) const;
    // Sets every 32-bit word to `value` (vkCmdFillBuffer).
    void fill(uint32_t value);

private:
    VulkanContext* context_ = nullptr;
    VkBuffer buffer_ = VK_NULL_HANDLE;
    VkDeviceMemory memory_ = VK_NULL_HANDLE;
    uint64_t address_ = 0;
    uint64_t size_ = 0;
    void* mapped_ = nullptr;
    std::string label_;

    void release();
    void checkRange(uint64_t offset, uint64_t count, const char* what) const;
};

} // namespace vdbdag::gpu
