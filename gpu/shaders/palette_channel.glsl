// A palette channel on the GPU (src/attributes/PaletteChannel.h): the
// device arrays of its sections and its sizes (gpu::PaletteChannelGpu,
// std430), and PaletteChannel::lookup with a block hint: the block
// directory by binary search; direct, palette and whole-material-array
// blocks; bit-packed indices (Dado et al. §4.2), from the shared source. Serves every channel the
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

// PaletteChannel::lookup: the one source shared with the CPU
// (include/vdbdag/palette_access.h), reading this struct's device arrays.
#define VDBDAG_GLSL 1
#define VDBDAG_PALETTE_T PaletteChannel
#define VDBDAG_PALETTE_BLOCK_COUNT(c) (c).blockCount
#define VDBDAG_PALETTE_BLOCK_FIRST(c, b) deviceArrayU64((c).blocks, 3ul * (b))
#define VDBDAG_PALETTE_BLOCK_DATA(c, b) deviceArrayU64((c).blocks, 3ul * (b) + 1ul)
#define VDBDAG_PALETTE_BLOCK_PALETTE(c, b) uint(deviceArrayU64((c).blocks, 3ul * (b) + 2ul) & 0xFFFFFFFFul)
#define VDBDAG_PALETTE_BLOCK_BITS(c, b) uint(deviceArrayU64((c).blocks, 3ul * (b) + 2ul) >> 32)
#define VDBDAG_PALETTE_INDEX_WORD(c, w) deviceArrayU64((c).indexBits, w)
#define VDBDAG_PALETTE_ENTRY(c, i) deviceArrayU32((c).palettes, i)
#define VDBDAG_PALETTE_VALUE_SIZE(c) (c).valueSize
#include "vdbdag/palette_access.h"

#endif
