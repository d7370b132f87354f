// A palette channel on the GPU (src/attributes/PaletteChannel.h): the
// device arrays of its sections and its sizes (gpu::PaletteChannelGpu,
// std430), and PaletteChannel::lookup with a block hint: the block
// directory by binary search; direct, palette and whole-material-array
// blocks; bit-packed indices (Dado et al. §4.2). Serves every channel the
// tracer reads (values, ONV normal codes): the caller passes the channel
// (a private copy, loaded once per invocation) and its own hint, and decodes
// the bytes at the location returned.
#ifndef VDBDAG_PALETTE_CHANNEL_GLSL
#define VDBDAG_PALETTE_CHANNEL_GLSL

#include "device_array.glsl"

// Same layout as gpu::PaletteChannelGpu (std430, 144 bytes).
struct PaletteChannel {
    DeviceArray materials;  // palette material array, valueSize bytes each
    DeviceArray palettes;   // uint32 material indices
    DeviceArray blocks;     // 3 uint64 per block: firstEntry, dataOffset, paletteOffset | indexBits << 32
    DeviceArray indexBits;  // uint64 bit-packed indices
    DeviceArray direct;     // directly stored values
    uint64_t entryCount;
    uint64_t blockCount;
    uint valueSize;
    uint pad;
};

// PaletteChannel.h readPackedBits.
uint64_t paletteBits(DeviceArray indexBits, uint64_t bitOffset, uint bits) {
    if (bits == 0u) return 0ul;
    const uint64_t word = bitOffset >> 6;
    const uint shift = uint(bitOffset & 63ul);
    uint64_t v = deviceArrayU64(indexBits, word) >> shift;
    if (shift + bits > 64u) v |= deviceArrayU64(indexBits, word + 1ul) << (64u - shift);
    return v & ((uint64_t(1) << bits) - 1ul);
}

// Where entry `index` (< c.entryCount) of channel `c` is stored: its byte
// offset in c.direct when `direct` comes back true, else in c.materials.
// `hint` is the block of the caller's previous lookup, tried first (a walk
// reads nearby entries, so most lookups skip the binary search), and is
// left at the block used.
uint64_t paletteLocate(PaletteChannel c, uint64_t index, inout uint64_t hint, out bool direct) {
    // The last block whose first entry is <= index (upper_bound - 1).
    uint64_t lo = hint;
    uint64_t first = deviceArrayU64(c.blocks, 3ul * lo);
    if (!(first <= index && (lo + 1ul == c.blockCount || index < deviceArrayU64(c.blocks, 3ul * (lo + 1ul))))) {
        lo = 0ul;
        uint64_t hi = c.blockCount;
        while (hi - lo > 1ul) {
            const uint64_t mid = (lo + hi) >> 1;
            if (deviceArrayU64(c.blocks, 3ul * mid) <= index) lo = mid;
            else hi = mid;
        }
        hint = lo;
        first = deviceArrayU64(c.blocks, 3ul * lo);
    }
    const uint64_t dataOffset = deviceArrayU64(c.blocks, 3ul * lo + 1ul);
    const uint64_t packed = deviceArrayU64(c.blocks, 3ul * lo + 2ul);
    const uint paletteOffset = uint(packed & 0xFFFFFFFFul);
    const uint bits = uint(packed >> 32);
    const uint64_t k = index - first;
    direct = bits == 0xFFu;
    if (direct) return dataOffset + k * uint64_t(c.valueSize);
    const uint64_t local = paletteBits(c.indexBits, dataOffset + k * uint64_t(bits), bits);
    const uint64_t m = paletteOffset == 0xFFFFFFFFu ? local : uint64_t(deviceArrayU32(c.palettes, uint64_t(paletteOffset) + local));
    return m * uint64_t(c.valueSize);
}

#endif
