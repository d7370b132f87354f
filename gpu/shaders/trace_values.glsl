// Attribute values on the GPU: the value channel's entries, found by
// paletteLocate (palette_channel.glsl, PaletteChannel::lookup) and decoded
// as RenderGrid does to up to three doubles (src/trace/RenderGrid.cpp,
// valueAsDoubles). Needs `P` (TraceParams) and the VALUE_TYPE
// specialisation constant (src/volume/GridRecord.h ValueType numbering;
// kNoValues when the grid stores none).
#ifndef VDBDAG_TRACE_VALUES_GLSL
#define VDBDAG_TRACE_VALUES_GLSL

const uint kValueFloat = 0u, kValueDouble = 1u, kValueInt32 = 2u, kValueInt64 = 3u, kValueBool = 4u, kValueMask = 5u,
           kValueVec3S = 6u, kValueVec3D = 7u, kValueVec3I = 8u, kNoValues = 255u;

// The value channel (palette_channel.glsl), a private copy made once per
// invocation by loadValueParams(): a load through `P` is a memory access
// each time.
PaletteChannel gValues;

void loadValueParams() {
    if (VALUE_TYPE == kNoValues) return;
    gValues = P.values;
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

uint64_t gBlockHint = 0ul;  // the value channel's palette block of the last lookup

// valueAsDoubles(grid, attribute): zeros without values or past the last entry.
dvec3 valueAsDoubles(uint64_t index) {
    if (VALUE_TYPE == kNoValues || VALUE_TYPE == kValueMask || index >= gValues.entryCount) return dvec3(0.0lf);
    bool direct;
    const uint64_t byteOffset = paletteLocate(gValues, index, gBlockHint, direct);
    if (direct) return decodeValueAt(gValues.direct, byteOffset);
    return decodeValueAt(gValues.materials, byteOffset);
}

#endif
