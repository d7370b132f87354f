// Splits a byte array over power-of-two chunks, one buffer each, and builds
// the chunk address table (see DeviceArray.h).
#include "gpu/DeviceArray.h"

#include <algorithm>
#include <bit>

#include <fmt/core.h>

#include "gpu/VulkanContext.h"
#include "src/util/Error.h"

namespace vdbdag::gpu {

uint32_t DeviceArray::maxChunkShift(const VulkanContext& context) {
    const DeviceInfo& info = context.deviceInfo();
    const uint64_t limit = std::min(info.maxMemoryAllocationSize, info.maxBufferSize);
    if (limit < 16) throw Error(fmt::format("Vulkan device {} reports a per-allocation limit of {} bytes", info.name, limit));
    return static_cast<uint32_t>(std::bit_width(limit) - 1);  // floor(log2(limit))
}

DeviceArray::DeviceArray(VulkanContext& context, std::span<const uint8_t> bytes, std::string label, DeviceArrayOptions options)
    : size_(bytes.size()) {
    const uint32_t maxShift = maxChunkShift(context);
    const uint32_t shift = options.chunkShift ? options.chunkShift : maxShift;
    if (shift < 4 || shift > maxShift)
        throw Error(fmt::format("{}: chunk shift {} outside [4, {}] for Vulkan device {}", label, shift, maxShift, context.deviceInfo().name));
    const uint64_t chunkBytes = uint64_t(1) << shift;
    const uint64_t count = std::max<uint64_t>(1, (size_ + chunkBytes - 1) >> shift);
    chunks_.reserve(count);
    std::vector<uint64_t> addresses;
    for (uint64_t c = 0; c < count; ++c) {
        const uint64_t begin = c << shift;
        const uint64_t n = std::min(chunkBytes, size_ - std::min(size_, begin));
        const std::string chunkLabel = count == 1 ? label : fmt::format("{} (chunk {} of {})", label, c, count);
        // Zero-fill only what the data does not cover (the last chunk's padding).
        chunks_.emplace_back(context, n, options.kind, chunkLabel, n % 16 != 0 || n == 0);
        chunks_.back().upload(bytes.subspan(begin, n));
        addresses.push_back(chunks_.back().address());
    }
    ref_.firstChunk = addresses[0];
    ref_.chunkShift = shift;
    ref_.chunkCount = static_cast<uint32_t>(count);
    if (count > 1) {
        table_.emplace_back(context, addresses.size() * 8, options.kind, label + " chunk table", false);
        table_.back().upload({reinterpret_cast<const uint8_t*>(addresses.data()), addresses.size() * 8});
        ref_.chunkTable = table_.back().address();
    } else {
        ref_.chunkTable = addresses[0];  // unused by the shader helpers when chunkCount == 1
    }
}

} // namespace vdbdag::gpu
