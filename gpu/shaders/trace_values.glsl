// Attribute values on the GPU: PaletteChannel::lookup (block directory by
// binary search; direct, palette and whole-material-array blocks; bit-packed
// indices; Dado et al. §4.2) and RenderGrid's decode to up to three doubles
// (src/trace/RenderGrid.cpp, valueAsDoubles). Needs `P` (TraceParams) and the
// VALUE_TYPE specialisation constant (src/volume/GridRecord.h ValueType
// numbering; kNoValues when the grid stores none).
#ifndef VDBDAG_TRACE_VALUES_GLSL
#define VDBDAG_TRACE_VALUES_GLSL

const uint kValueFloat = 0u, kValueDouble = 1u, kValueInt32 = 2u, kValueInt64 = 3u, kValueBool = 4u, kValueMask = 5u,
           kValueVec3S = 6u, kValueVec3D = 7u, kValueVec3I = 8u, kNoValues = 255u;

// Private copies of the channel's references and sizes (loadValueParams(),
// once per invocation: a load through `P` is a memory access each time).
DeviceArray gMaterials, gPalettes, gBlocks, gIndexBits, gDirect;
uint64_t gEntryCount, gBlockCount;
uint gValueSize;

void loadValueParams() {
    if (VALUE_TYPE == kNoValues) return;
    gMaterials = P.materials;
    gPalettes = P.palettes;
    gBlocks = P.blocks;
    gIndexBits = P.indexBits;
    gDirect = P.direct;
    gEntryCount = P.entryCount;
    gBlockCount = P.blockCount;
    gValueSize = P.valueSize;
}

// PaletteChannel.cpp getBits.
uint64_t paletteBits(uint64_t bitOffset, uint bits) {
    if (bits == 0u) return 0ul;
    const uint64_t word = bitOffset >> 6;
    const uint shift = uint(bitOffset & 63ul);
    uint64_t v = deviceArrayU64(gIndexBits, word) >> shift;
    if (shift + bits > 64u) v |= deviceArrayU64(gIndexBits, word + 1ul) << (64u - shift);
    return v & ((uint64_t(1) << bits) - 1ul);
}

double floatAt(DeviceArray a, uint64_t byteOffset) { return double(uintBitsToFloat(deviceArrayU32(a, byteOffset >> 2))); }
double doubleAt(DeviceArray a, uint64_t byteOffset) {
    return packDouble2x32(uvec2(deviceArrayU32(a, byteOffset >> 2), deviceArrayU32(a, (byteOffset >> 2) + 1ul)));
}
double int32At(DeviceArray a, uint64_t byteOffset) { return double(int(deviceArrayU32(a, byteOffset >> 2))); }
double int64At(DeviceArray a, uint64_t byteOffset) {
    const uint64_t lo = uint64_t(deviceArrayU32(a, byteOffset >> 2)), hi = uint64_t(deviceArrayU32(a, (byteOffset >> 2) + 1ul));
    return double(int64_t(lo | (hi << 32)));
}

dvec3 decodeValueAt(DeviceArray a, uint64_t byteOffset) {
    dvec3 value = dvec3(0.0lf);
    if (VALUE_TYPE == kValueFloat) value.x = floatAt(a, byteOffset);
    else if (VALUE_TYPE == kValueDouble) value.x = doubleAt(a, byteOffset);
    else if (VALUE_TYPE == kValueInt32) value.x = int32At(a, byteOffset);
    else if (VALUE_TYPE == kValueInt64) value.x = int64At(a, byteOffset);
    else if (VALUE_TYPE == kValueBool) value.x = deviceArrayU8(a, byteOffset) != 0u ? 1.0lf : 0.0lf;
    else if (VALUE_TYPE == kValueVec3S) value = dvec3(floatAt(a, byteOffset), floatAt(a, byteOffset + 4ul), floatAt(a, byteOffset + 8ul));
    else if (VALUE_TYPE == kValueVec3D) value = dvec3(doubleAt(a, byteOffset), doubleAt(a, byteOffset + 8ul), doubleAt(a, byteOffset + 16ul));
    else if (VALUE_TYPE == kValueVec3I) value = dvec3(int32At(a, byteOffset), int32At(a, byteOffset + 4ul), int32At(a, byteOffset + 8ul));
    return value;
}

uint64_t gBlockHint = 0ul;  // the palette block of the last lookup

// valueAsDoubles(grid, attribute): zeros without values or past the last entry.
dvec3 valueAsDoubles(uint64_t index) {
    if (VALUE_TYPE == kNoValues || VALUE_TYPE == kValueMask || index >= gEntryCount) return dvec3(0.0lf);
    // The last block whose first entry is <= index (upper_bound - 1).
    const DeviceArray blocks = gBlocks;
    const uint64_t blockCount = gBlockCount;
    // The block of the previous lookup first (PaletteChannel::lookup's hint):
    // a walk reads nearby entries, so most lookups skip the binary search.
    uint64_t lo = gBlockHint;
    uint64_t first = deviceArrayU64(blocks, 3ul * lo);
    if (!(first <= index && (lo + 1ul == blockCount || index < deviceArrayU64(blocks, 3ul * (lo + 1ul))))) {
        lo = 0ul;
        uint64_t hi = blockCount;
        while (hi - lo > 1ul) {
            const uint64_t mid = (lo + hi) >> 1;
            if (deviceArrayU64(blocks, 3ul * mid) <= index) lo = mid;
            else hi = mid;
        }
        gBlockHint = lo;
        first = deviceArrayU64(blocks, 3ul * lo);
    }
    const uint64_t dataOffset = deviceArrayU64(blocks, 3ul * lo + 1ul);
    const uint64_t packed = deviceArrayU64(blocks, 3ul * lo + 2ul);
    const uint paletteOffset = uint(packed & 0xFFFFFFFFul);
    const uint bits = uint(packed >> 32);
    const uint64_t k = index - first;
    if (bits == 0xFFu) return decodeValueAt(gDirect, dataOffset + k * uint64_t(gValueSize));
    const uint64_t local = paletteBits(dataOffset + k * uint64_t(bits), bits);
    const uint64_t m = paletteOffset == 0xFFFFFFFFu ? local : uint64_t(deviceArrayU32(gPalettes, uint64_t(paletteOffset) + local));
    return decodeValueAt(gMaterials, m * uint64_t(gValueSize));
}

#endif
