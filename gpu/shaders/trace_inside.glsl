// The level set's inside bits on the GPU (src/trace/InsideBits.h): one bit
// per attribute entry, value <= 0. The zero-crossing visitor tests a bit
// instead of decoding a palette entry, and the walk crosses 4^3 leaves with
// no inside voxel as empty space (DagWalk.h keepLeaf), as the CPU does.
// Needs `P` (TraceParams) and LEVEL_SET; P.inside is empty (firstChunk 0)
// when the grid has no inside bits.
#ifndef VDBDAG_TRACE_INSIDE_GLSL
#define VDBDAG_TRACE_INSIDE_GLSL

DeviceArray gInside;           // private copy, loadInsideParams()
uint64_t gInsideEntries = 0ul; // 0: no inside bits
bool gHasInside = false;

void loadInsideParams() {
    if (!LEVEL_SET) return;
    gInside = P.inside;
    gHasInside = P.inside.firstChunk != 0ul;
    gInsideEntries = gHasInside ? P.values.entryCount : 0ul;
}

// InsideBits::inside.
bool insideAt(uint64_t entry) {
    if (entry >= gInsideEntries) return false;
    return ((deviceArrayU64(gInside, entry >> 6) >> uint(entry & 63ul)) & 1ul) != 0ul;
}

// The inside bits of the `count` (<= 64) entries from `first` (bit k: entry
// first + k), 0 past the entries; InsideBits::anyInside is whether any is
// set. The walk keeps a leaf's word in a register, so the zero-crossing test
// of its voxels reads no memory.
uint64_t insideWord(uint64_t first, uint count) {
    if (count == 0u || first >= gInsideEntries) return 0ul;
    const uint64_t word = first >> 6;
    const uint shift = uint(first & 63ul);
    uint64_t bits = deviceArrayU64(gInside, word) >> shift;
    if (shift + count > 64u && ((word + 1ul) << 6) < gInsideEntries) bits |= deviceArrayU64(gInside, word + 1ul) << (64u - shift);
    return count == 64u ? bits : bits & ((uint64_t(1) << count) - 1ul);
}

#endif
