// Palette channel lookup (Dado et al. §4.2; docs/FORMAT.md §7), one source
// for C++ and GLSL (see shader_lang.h): where entry `index` of a channel is
// stored, through the block directory (found by binary search unless the
// caller's hint is already the block), direct blocks, palette blocks whose
// bit-packed ω-bit indices name a palette's material, and blocks whose
// indices address the material array itself. PaletteChannel::lookup
// (src/attributes/PaletteChannel.cpp) and the tracer's shaders
// (gpu/shaders/palette_channel.glsl) both include it.
//
// The includer defines how a channel is read, before including:
//   VDBDAG_PALETTE_T                  the channel parameter's type
//   VDBDAG_PALETTE_BLOCK_COUNT(c)     blocks in the directory (uint64_t)
//   VDBDAG_PALETTE_BLOCK_FIRST(c, b)  block b's first entry (uint64_t)
//   VDBDAG_PALETTE_BLOCK_DATA(c, b)   its data offset: a byte offset into the
//                                     direct values, or a bit offset into the indices
//   VDBDAG_PALETTE_BLOCK_PALETTE(c, b) its first palette word (uint), or
//                                     kPaletteWholeMaterialArray
//   VDBDAG_PALETTE_BLOCK_BITS(c, b)   its index width ω (uint), or kPaletteDirect
//   VDBDAG_PALETTE_INDEX_WORD(c, w)   64-bit word w of the packed indices
//   VDBDAG_PALETTE_ENTRY(c, i)        palette word i: a material index (uint)
//   VDBDAG_PALETTE_VALUE_SIZE(c)      bytes per value (uint)
// A C++ program includes it once, in one source file.
#ifndef VDBDAG_PALETTE_ACCESS_H
#define VDBDAG_PALETTE_ACCESS_H

#include "shader_lang.h"

VDBDAG_NAMESPACE_BEGIN

VDBDAG_CONST uint kPaletteDirect = 0xFFu;                   // index width of a direct block
VDBDAG_CONST uint kPaletteWholeMaterialArray = 0xFFFFFFFFu;  // palette offset: indices address the materials

// The `bits`-bit field (0..63) at bit `bitOffset` of the packed indices.
VDBDAG_FN uint64_t paletteBits(VDBDAG_PALETTE_T c, uint64_t bitOffset, uint bits) {
    if (bits == 0u) return 0ul;
    const uint64_t word = bitOffset >> 6u;
    const uint shift = uint(bitOffset & 63ul);
    uint64_t v = VDBDAG_PALETTE_INDEX_WORD(c, word) >> shift;
    if (shift + bits > 64u) v |= VDBDAG_PALETTE_INDEX_WORD(c, word + 1ul) << (64u - shift);
    return v & ((uint64_t(1) << bits) - 1ul);
}

// Where entry `index` (< the channel's entry count) is stored: its byte
// offset among the direct values when `direct` comes back true, else among
// the materials. `hint` is the block of the caller's previous lookup, tried
// first (a walk reads nearby entries, so most lookups skip the binary
// search), and is left at the block used.
VDBDAG_FN uint64_t paletteLocate(VDBDAG_PALETTE_T c, uint64_t index, VDBDAG_INOUT(uint64_t) hint, VDBDAG_OUT(bool) direct) {
    const uint64_t count = VDBDAG_PALETTE_BLOCK_COUNT(c);
    uint64_t lo = hint;
    if (!(lo < count && VDBDAG_PALETTE_BLOCK_FIRST(c, lo) <= index && (lo + 1ul == count || index < VDBDAG_PALETTE_BLOCK_FIRST(c, lo + 1ul)))) {
        // The last block whose first entry is <= index (upper_bound - 1).
        lo = 0ul;
        uint64_t hi = count;
        while (hi - lo > 1ul) {
            const uint64_t mid = (lo + hi) >> 1u;
            if (VDBDAG_PALETTE_BLOCK_FIRST(c, mid) <= index) lo = mid;
            else hi = mid;
        }
        hint = lo;
    }
    const uint64_t k = index - VDBDAG_PALETTE_BLOCK_FIRST(c, lo);
    const uint64_t dataOffset = VDBDAG_PALETTE_BLOCK_DATA(c, lo);
    const uint bits = VDBDAG_PALETTE_BLOCK_BITS(c, lo);
    const uint64_t valueSize = uint64_t(VDBDAG_PALETTE_VALUE_SIZE(c));
    direct = bits == kPaletteDirect;
    if (direct) return dataOffset + k * valueSize;
    const uint64_t local = paletteBits(c, dataOffset + k * uint64_t(bits), bits);
    const uint paletteOffset = VDBDAG_PALETTE_BLOCK_PALETTE(c, lo);
    const uint64_t m = paletteOffset == kPaletteWholeMaterialArray ? local : uint64_t(VDBDAG_PALETTE_ENTRY(c, uint64_t(paletteOffset) + local));
    return m * valueSize;
}

VDBDAG_NAMESPACE_END

#endif
