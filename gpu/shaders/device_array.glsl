// Reading a gpu::DeviceArray (gpu/DeviceArray.h) through buffer device
// addresses: a byte array split into chunks of 2^chunkShift bytes, each its
// own buffer, with a table of chunk addresses. Power-of-two chunks mean an
// aligned 2-, 4- or 8-byte element never straddles two chunks. One-chunk
// arrays (anything up to the device's allocation limit, lavapipe: 2 GiB)
// skip the table. Indices are element indices (64-bit: arrays may exceed 4 GiB).
#ifndef VDBDAG_DEVICE_ARRAY_GLSL
#define VDBDAG_DEVICE_ARRAY_GLSL

#extension GL_EXT_buffer_reference : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_explicit_arithmetic_types_int16 : require
#extension GL_EXT_shader_16bit_storage : require

// Same layout as gpu::DeviceArrayRef (std430, 24 bytes).
struct DeviceArray {
    uint64_t firstChunk;
    uint64_t chunkTable;
    uint chunkShift;
    uint chunkCount;
};

layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer DeviceArrayChunkTable { uint64_t address[]; };
layout(buffer_reference, std430, buffer_reference_align = 2) readonly buffer DeviceArrayU16Ptr { uint16_t value; };
layout(buffer_reference, std430, buffer_reference_align = 4) readonly buffer DeviceArrayU32Ptr { uint value; };
layout(buffer_reference, std430, buffer_reference_align = 8) readonly buffer DeviceArrayU64Ptr { uint64_t value; };

// Device address of byte `byteOffset` of the array.
uint64_t deviceArrayAddress(DeviceArray a, uint64_t byteOffset) {
    if (a.chunkCount == 1u) return a.firstChunk + byteOffset;
    const uint chunk = uint(byteOffset >> a.chunkShift);
    const uint64_t within = byteOffset & ((uint64_t(1) << a.chunkShift) - uint64_t(1));
    return DeviceArrayChunkTable(a.chunkTable).address[chunk] + within;
}

uint deviceArrayU16(DeviceArray a, uint64_t index) {
    return uint(DeviceArrayU16Ptr(deviceArrayAddress(a, index * 2ul)).value);
}
uint deviceArrayU32(DeviceArray a, uint64_t index) {
    return DeviceArrayU32Ptr(deviceArrayAddress(a, index * 4ul)).value;
}
uint64_t deviceArrayU64(DeviceArray a, uint64_t index) {
    return DeviceArrayU64Ptr(deviceArrayAddress(a, index * 8ul)).value;
}
// Byte `index`, read through its aligned 32-bit word (no 8-bit storage needed).
uint deviceArrayU8(DeviceArray a, uint64_t index) {
    const uint word = deviceArrayU32(a, index >> 2);
    return (word >> (uint(index & 3ul) * 8u)) & 0xFFu;
}

// Plain output arrays at a DeviceBuffer::address().
layout(buffer_reference, std430, buffer_reference_align = 4) buffer U32Array { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer U64Array { uint64_t v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer F32Array { float v[]; };

#endif
