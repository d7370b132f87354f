// Uploads a palette channel's sections; see DevicePaletteChannel.h.
#include "gpu/DevicePaletteChannel.h"

#include "gpu/ByteSpan.h"

namespace vdbdag::gpu {

DevicePaletteChannel::DevicePaletteChannel(VulkanContext& context, const attributes::PaletteChannel* channel, const std::string& label,
                                           DeviceArrayOptions options) {
    // The block directory as the shader reads it: 3 uint64 per block.
    std::vector<uint64_t> blocks;
    if (channel) {
        blocks.reserve(channel->blocks.size() * 3);
        for (const attributes::PaletteBlock& b : channel->blocks) {
            blocks.push_back(b.firstEntry);
            blocks.push_back(b.dataOffset);
            blocks.push_back(uint64_t(b.paletteOffset) | (uint64_t(b.indexBits) << 32));
        }
    }
    const std::span<const uint8_t> none;
    arrays_.reserve(5);
    arrays_.emplace_back(context, orZeros(channel ? bytesOf(channel->materials) : none), label + " materials", options);
    arrays_.emplace_back(context, orZeros(channel ? bytesOf(channel->palettes) : none), label + " palettes", options);
    arrays_.emplace_back(context, orZeros(bytesOf(blocks)), label + " block directory", options);
    arrays_.emplace_back(context, orZeros(channel ? bytesOf(channel->indexBits) : none), label + " palette indices", options);
    arrays_.emplace_back(context, orZeros(channel ? bytesOf(channel->direct) : none), label + " direct values", options);
    ref_.materials = arrays_[0].ref();
    ref_.palettes = arrays_[1].ref();
    ref_.blocks = arrays_[2].ref();
    ref_.indexBits = arrays_[3].ref();
    ref_.direct = arrays_[4].ref();
    ref_.entryCount = channel ? channel->entryCount : 0;
    ref_.blockCount = channel ? channel->blocks.size() : 0;
    ref_.valueSize = channel ? channel->valueSize : 0;
}

} // namespace vdbdag::gpu
