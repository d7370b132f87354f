// The palette compressor (Dado et al. §4.2, Alg. 1): builds the traceable
// channel of PaletteChannel.h from an attribute array. An encoder's part:
// a reader only looks channels up (the reader library does not link it).
#pragma once
#include <cstdint>
#include <span>

#include "src/attributes/PaletteChannel.h"

namespace vdbdag::attributes {

// Compresses `values` (entries of `valueSize` bytes) with the two-phase
// greedy partition of Dado et al. Alg. 1, in O(n log n). Besides ω = 0..8
// palettes and direct storage, a block may index the material array
// directly (kWholeMaterialArray) when that is cheaper.
PaletteChannel compressPalette(std::span<const uint8_t> values, uint32_t valueSize);

// The paper's Table 1 columns for a channel.
struct ChannelStats {
    uint64_t entries = 0;        // Λ
    uint64_t unique = 0;         // λ (distinct values in the whole channel)
    uint64_t rawBytes = 0;       // Λ * valueSize
    uint64_t materialIndexBytes = 0;  // M + Λ * ceil(log2 λ) bits
    uint64_t paletteBytes = 0;   // the traceable palette layout
    uint64_t directBlocks = 0, paletteBlocks = 0, palettesStored = 0;
};
ChannelStats channelStats(std::span<const uint8_t> values, uint32_t valueSize, const PaletteChannel& channel);

} // namespace vdbdag::attributes
