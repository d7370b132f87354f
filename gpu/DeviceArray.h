// An arbitrary byte array on the device (the compact DAG's 16-bit inner words,
// 64-bit leaves, palette sections; up to many GiB) that one shader can read
// whole, whatever the device's per-binding limit (lavapipe: 128 MiB) is.
//
// Mechanism: buffer device addresses instead of descriptor bindings, so the
// binding limit does not apply. Data larger than one allocation (lavapipe:
// 2 GiB) is split into chunks of 2^chunkShift bytes, each its own buffer; a
// small table holds the chunks' addresses. Chunks are powers of two, so an
// aligned 2-, 4- or 8-byte element never straddles two chunks. Shaders take a
// DeviceArrayRef (24 bytes, e.g. in push constants) and read with the helpers
// of gpu/shaders/device_array.glsl (deviceArrayU16/U32/U64/U8); a one-chunk
// array (the usual case) costs no table lookup.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "gpu/DeviceBuffer.h"

namespace vdbdag::gpu {

// Same layout as GLSL `struct DeviceArray` in device_array.glsl (std430).
struct alignas(8) DeviceArrayRef {
    uint64_t firstChunk = 0;  // address of chunk 0
    uint64_t chunkTable = 0;  // address of chunkCount uint64 chunk addresses
    uint32_t chunkShift = 0;  // chunk c holds bytes [c << chunkShift, (c + 1) << chunkShift)
    uint32_t chunkCount = 0;
};
static_assert(sizeof(DeviceArrayRef) == 24, "must match the GLSL struct DeviceArray");

struct DeviceArrayOptions {
    MemoryKind kind = MemoryKind::DeviceLocal;
    // log2 of the chunk size; 0 = the largest power of two the device allows
    // in one allocation and buffer. Smaller values are for tests (>= 4).
    uint32_t chunkShift = 0;
};

class DeviceArray {
public:
    // Uploads `bytes`; the last chunk is zero-padded to a multiple of 16 bytes.
    // Throws vdbdag::Error naming `label` when memory runs out.
    DeviceArray(VulkanContext& context, std::span<const uint8_t> bytes, std::string label, DeviceArrayOptions options = {});

    DeviceArrayRef ref() const { return ref_; }
    uint64_t sizeBytes() const { return size_; }
    uint32_t chunkCount() const { return static_cast<uint32_t>(chunks_.size()); }
    uint32_t chunkShift() const { return ref_.chunkShift; }
    const DeviceBuffer& chunk(uint32_t i) const { return chunks_.at(i); }

    // The largest chunk shift `context`'s device allows.
    static uint32_t maxChunkShift(const VulkanContext& context);

private:
    std::vector<DeviceBuffer> chunks_;
    std::vector<DeviceBuffer> table_;  // empty or one buffer of chunk addresses
    DeviceArrayRef ref_;
    uint64_t size_ = 0;
};

} // namespace vdbdag::gpu
