#version 460
// Backend self-test (tests/unit/test_vulkan_backend.cpp): for item i, reads
// the 64-bit element index64[i] and the 16-bit element index16[i] of a
// DeviceArray (possibly larger than one binding or split over chunks) and
// writes them to out64[i] / out16[i]. Specialisation constants 1 and 2 switch
// the two reads off, to check that specialisation reaches the shader.
#include "dispatch.glsl"
#include "device_array.glsl"

layout(constant_id = 1) const bool READ_U64 = true;
layout(constant_id = 2) const bool READ_U16 = true;

layout(push_constant, std430) uniform Push {
    DeviceArray source;
    uint64_t indices;  // U64Array: {index64, index16} per item
    uint64_t out64;    // U64Array
    uint64_t out16;    // U32Array
    uint itemCount;
} pc;

void main() {
    const uint i = vdbdagItemIndex();
    if (i >= pc.itemCount) return;
    U64Array indices = U64Array(pc.indices);
    if (READ_U64) U64Array(pc.out64).v[i] = deviceArrayU64(pc.source, indices.v[2 * i]);
    if (READ_U16) U32Array(pc.out16).v[i] = deviceArrayU16(pc.source, indices.v[2 * i + 1]);
}
